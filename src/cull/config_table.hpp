// Internal: an algorithm's options written once. Each algorithm keeps a
// typed config struct whose member initialisers are its defaults, and one
// table of its fields (key, member, range, help). The table is the parser
// (Options -> config), the registry entry (AlgorithmInfo::options, with each
// default read from a default-constructed config) and the test of whether a
// run's options make it approximate. Nothing else names an option's key,
// range or default.
#pragma once

#include "occull/culler.hpp"
#include "occull/error.hpp"
#include "core/format.hpp"

#include <functional>
#include <type_traits>
#include <typeinfo>
#include <string>
#include <utility>
#include <vector>

namespace occull::detail {

template <class Config>
class ConfigTable {
 public:
  // `at` names the field: a member pointer (&Config::batch) or, for members
  // of nested structs, a generic lambda [](auto& c) -> auto& { ... } (it is
  // called on const configs too).

  /// A whole number in [lo, hi].
  template <class At>
  ConfigTable&& integer(std::string key, At at, int lo, int hi, std::string help) && {
    number(std::move(key), at, lo, hi, std::move(help));
    return std::move(*this);
  }
  /// A finite number in [lo, hi].
  template <class At>
  ConfigTable&& real(std::string key, At at, double lo, double hi, std::string help) && {
    number(std::move(key), at, lo, hi, std::move(help));
    return std::move(*this);
  }
  /// on/off (also true/false, yes/no, 1/0).
  template <class At>
  ConfigTable&& flag(std::string key, At at, std::string help) && {
    add(std::move(key), std::move(help), "on|off",
        [at](Config& c, const Options& o, const std::string& k) {
          bool& m = std::invoke(at, c);
          m = o.get_bool(k, m);
        },
        [at](const Config& c) -> std::string { return std::invoke(at, c) ? "on" : "off"; });
    return std::move(*this);
  }
  /// One of the named values.
  template <class At>
  ConfigTable&& choice(std::string key, At at,
                       std::vector<std::pair<std::string, std::remove_cvref_t<std::invoke_result_t<At, Config&>>>> names,
                       std::string help) && {
    std::string values;
    for (const auto& n : names) values += (values.empty() ? "" : "|") + n.first;
    add(std::move(key), std::move(help), std::move(values),
        [at, names](Config& c, const Options& o, const std::string& k) {
          const auto it = o.values().find(k);
          if (it == o.values().end()) return;
          std::string valid;
          for (const auto& [name, value] : names) {
            if (name == it->second) {
              std::invoke(at, c) = value;
              return;
            }
            valid += (valid.empty() ? "" : ", ") + name;
          }
          throw InputError(detail::format("option {}: '{}' is not one of {}", k, it->second, valid));
        },
        [at, names](const Config& c) -> std::string {
          for (const auto& [name, value] : names)
            if (value == std::invoke(at, c)) return name;
          return "?";
        },
        [at, names](const Config& c, const std::string& k) {
          std::string valid;
          for (const auto& [name, value] : names) {
            if (value == std::invoke(at, c)) return;
            valid += (valid.empty() ? "" : ", ") + name;
          }
          throw InputError(detail::format("option {}: the config's value is not one of {}", k, valid));
        });
    return std::move(*this);
  }
  /// Free text; `when_empty` is how the help shows an empty default.
  template <class At>
  ConfigTable&& text(std::string key, At at, std::string help, std::string when_empty = "") && {
    add(std::move(key), std::move(help), "",
        [at](Config& c, const Options& o, const std::string& k) {
          const auto it = o.values().find(k);
          if (it != o.values().end()) std::invoke(at, c) = it->second;
        },
        [at, when_empty](const Config& c) -> std::string {
          const std::string& v = std::invoke(at, c);
          return v.empty() ? when_empty : v;
        });
    return std::move(*this);
  }
  /// Marks the field added last: any value but its default may cull visible
  /// objects (OptionInfo::approximate_unless_default).
  ConfigTable&& approximate_unless_default() && {
    fields_.back().info.approximate_unless_default = true;
    return std::move(*this);
  }

  /// The config `options` ("algo.key" -> value) give `algo`: defaults where
  /// a key is absent. Throws InputError naming a value that does not parse
  /// or lies outside its range. Keys of other algorithms are ignored.
  [[nodiscard]] Config parse(const Options& options, std::string_view algo) const {
    Config c;
    for (const Field& f : fields_) f.read(c, options, detail::format("{}.{}", algo, f.info.key));
    return c;
  }
  /// Checks a config made in code (make_culler(ChcppConfig{...})) as
  /// parse() checks options: throws InputError naming the first field
  /// outside its range, as its option ("option chcpp.batch: ...").
  void check(const Config& c, std::string_view algo) const {
    for (const Field& f : fields_)
      if (f.check) f.check(c, detail::format("{}.{}", algo, f.info.key));
  }
  /// The registry's description of every field, defaults from Config{}.
  [[nodiscard]] std::vector<OptionInfo> describe() const {
    const Config defaults{};
    std::vector<OptionInfo> out;
    for (const Field& f : fields_) {
      OptionInfo info = f.info;
      info.default_value = f.show(defaults);
      out.push_back(std::move(info));
    }
    return out;
  }
  /// Whether `options` set a field marked approximate_unless_default to a
  /// value other than its default (compared parsed, so "00" is 0).
  [[nodiscard]] bool approximate(const Options& options, std::string_view algo) const {
    const Config c = parse(options, algo);
    const Config defaults{};
    for (const Field& f : fields_)
      if (f.info.approximate_unless_default && f.show(c) != f.show(defaults)) return true;
    return false;
  }

 private:
  // A number field read by Options::get_int (Bound int) or get_double.
  template <class At, class Bound>
  void number(std::string key, At at, Bound lo, Bound hi, std::string help) {
    add(std::move(key), std::move(help), detail::format("[{}, {}]", lo, hi),
        [at, lo, hi](Config& c, const Options& o, const std::string& k) {
          auto& m = std::invoke(at, c);
          using T = std::remove_reference_t<decltype(m)>;
          if constexpr (std::is_same_v<Bound, int>)
            m = static_cast<T>(o.get_int(k, int(m), lo, hi));
          else
            m = static_cast<T>(o.get_double(k, double(m), lo, hi));
        },
        [at](const Config& c) { return detail::format("{}", std::invoke(at, c)); },
        [at, lo, hi](const Config& c, const std::string& k) {
          const double v = double(std::invoke(at, c));
          if (!(v >= double(lo) && v <= double(hi)))  // NaN too
            throw InputError(detail::format("option {}: {} is outside [{}, {}]", k, std::invoke(at, c), lo, hi));
        });
  }
  struct Field {
    OptionInfo info;
    std::function<void(Config&, const Options&, const std::string&)> read;
    std::function<std::string(const Config&)> show;
    /// Throws InputError when a config's value is outside the field's range
    /// (null: every value is valid, as for a flag or text).
    std::function<void(const Config&, const std::string&)> check;
  };
  template <class Read, class Show>
  void add(std::string key, std::string help, std::string values, Read read, Show show,
           std::function<void(const Config&, const std::string&)> check = nullptr) {
    OptionInfo info;
    info.key = std::move(key);
    info.values = std::move(values);
    info.help = std::move(help);
    fields_.push_back(Field{std::move(info), std::move(read), std::move(show), std::move(check)});
  }
  std::vector<Field> fields_;
};

/// How the registry makes an algorithm from options (null: lab only).
using Factory = std::function<std::unique_ptr<Culler>(const SceneIndex&, const Options&, const CullerContext&)>;

/// How the registry makes the cullers of several views together (null: one
/// culler per view, each by the Factory).
using SplitFactory =
    std::function<std::unique_ptr<SplitScreen>(const SceneIndex&, int views, const Options&, const CullerContext&)>;

/// How the registry makes an algorithm from its typed config (a `const
/// Config*` of the registration's config_type), checked by its table.
using ConfigFactory = std::function<std::unique_ptr<Culler>(const SceneIndex&, const void*, const CullerContext&)>;

/// An algorithm as the registry holds it.
struct Registration {
  AlgorithmInfo info;
  Factory make;
  ConfigFactory make_config;
  const std::type_info* config_type = nullptr;  ///< what make_config takes
  SplitFactory make_views;  ///< set with info.shares_views
  /// Variants `occull bench` runs by default besides the plain name.
  std::vector<std::string> bench_variants;
  /// Whether options make a run approximate (null: never).
  std::function<bool(const Options&)> approximate;
};

/// The registration of an algorithm with a config table: its options are
/// the table's fields, and `make(index, config, options, context)` gets the
/// parsed config (and the whole options, for algorithms that make others).
/// `table` must outlive the registry (a function-local static).
template <class Config, class Make>
Registration registered(AlgorithmInfo info, const ConfigTable<Config>& table, Make make) {
  info.options = table.describe();
  const std::string name = info.name;
  Registration r{std::move(info), {}, {}, {}, {}, {}, {}};
  r.make = [&table, name, make](const SceneIndex& index, const Options& o, const CullerContext& context) {
    return make(index, table.parse(o, name), o, context);
  };
  r.make_config = [&table, name, make](const SceneIndex& index, const void* config, const CullerContext& context) {
    const Config& c = *static_cast<const Config*>(config);
    table.check(c, name);
    return make(index, c, Options{}, context);
  };
  r.config_type = &typeid(Config);
  r.approximate = [&table, name](const Options& o) { return table.approximate(o, name); };
  return r;
}

}  // namespace occull::detail
