// The algorithm registry and option parsing.
#include "occull/culler.hpp"

#include "cullers.hpp"
#include "occull/error.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <fmt/format.h>

namespace occull {
namespace {

using Factory = std::unique_ptr<Culler> (*)(const SceneIndex&, const Options&);

struct Entry {
  AlgorithmInfo info;
  Factory make;
};

const std::vector<Entry>& registry() {
  static const std::vector<Entry> entries = {
      {{"none", "render every object (reference cost of no culling)", true, {}},
       &detail::make_none},
      {{"vfc", "hierarchical view-frustum culling over the BVH, front to back", true, {}},
       &detail::make_vfc},
      {{"oracle",
        "renders exactly the ground-truth visible set, no queries: the lower bound (occull bench only)",
        true, {}, true},
       nullptr},
  };
  return entries;
}

const Entry* find(std::string_view name) {
  for (const Entry& e : registry())
    if (e.info.name == name) return &e;
  return nullptr;
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

void Options::set(std::string_view assignment) {
  const auto eq = assignment.find('=');
  const auto dot = assignment.find('.');
  if (eq == std::string_view::npos || dot == std::string_view::npos || dot > eq || dot == 0 ||
      dot + 1 == eq)
    throw InputError(fmt::format("option '{}' is not of the form algorithm.key=value "
                                 "(e.g. chcpp.batch=50)",
                                 assignment));
  set(std::string(assignment.substr(0, eq)), std::string(assignment.substr(eq + 1)));
}

int Options::get_int(const std::string& key, int fallback, int lo, int hi) const {
  const auto it = values_.find(key);
  if (it == values_.end()) return fallback;
  int v = 0;
  const std::string& s = it->second;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size())
    throw InputError(fmt::format("option {}: '{}' is not a whole number", key, s));
  if (v < lo || v > hi)
    throw InputError(fmt::format("option {}: {} is outside [{}, {}]", key, v, lo, hi));
  return v;
}

double Options::get_double(const std::string& key, double fallback, double lo, double hi) const {
  const auto it = values_.find(key);
  if (it == values_.end()) return fallback;
  const std::string& s = it->second;
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v))
    throw InputError(fmt::format("option {}: '{}' is not a number", key, s));
  if (v < lo || v > hi)
    throw InputError(fmt::format("option {}: {} is outside [{}, {}]", key, v, lo, hi));
  return v;
}

bool Options::get_bool(const std::string& key, bool fallback) const {
  const auto it = values_.find(key);
  if (it == values_.end()) return fallback;
  const std::string v = lower(it->second);
  if (v == "on" || v == "true" || v == "yes" || v == "1") return true;
  if (v == "off" || v == "false" || v == "no" || v == "0") return false;
  throw InputError(fmt::format("option {}: '{}' is not on/off", key, it->second));
}

std::span<const AlgorithmInfo> algorithms() {
  static const std::vector<AlgorithmInfo> infos = [] {
    std::vector<AlgorithmInfo> v;
    for (const Entry& e : registry()) v.push_back(e.info);
    return v;
  }();
  return infos;
}

std::string algorithm_names() {
  std::string out;
  for (const Entry& e : registry()) out += (out.empty() ? "" : ", ") + e.info.name;
  return out;
}

namespace {

// Throws unless `sub` is an option of `entry`.
void check_option(const Entry& entry, const std::string& key, const std::string& sub) {
  std::string valid;
  for (const OptionInfo& o : entry.info.options) {
    if (o.key == sub) return;
    valid += (valid.empty() ? "" : ", ") + o.key;
  }
  throw InputError(fmt::format("unknown option '{}' of {}; valid options: {}", key, entry.info.name,
                               valid.empty() ? "(none)" : valid));
}

}  // namespace

void check_options(const Options& options) {
  for (const auto& [key, value] : options.values()) {
    const auto dot = key.find('.');
    const std::string algo = key.substr(0, dot);
    const Entry* entry = find(algo);
    if (!entry)
      throw InputError(fmt::format("option '{}' names unknown algorithm '{}'; valid algorithms: {}",
                                   key, algo, algorithm_names()));
    check_option(*entry, key, key.substr(dot + 1));
  }
}

const AlgorithmInfo& find_algorithm(std::string_view name) {
  for (const AlgorithmInfo& a : algorithms())
    if (a.name == name) return a;
  throw InputError(
      fmt::format("unknown algorithm '{}'; valid algorithms: {}", name, algorithm_names()));
}

std::unique_ptr<Culler> make_culler(std::string_view name, const SceneIndex& index,
                                    const Options& options) {
  (void)find_algorithm(name);
  const Entry* entry = find(name);
  const std::string prefix = entry->info.name + ".";
  for (const auto& [key, value] : options.values())
    if (key.rfind(prefix, 0) == 0) check_option(*entry, key, key.substr(prefix.size()));
  if (!entry->make)
    throw InputError(fmt::format("{} needs each frame's ground truth: it runs only in the harness "
                                 "(occull bench)",
                                 entry->info.name));
  return entry->make(index, options);
}

}  // namespace occull
