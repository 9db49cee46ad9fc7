// The algorithm registry and option parsing.
#include "occull/culler.hpp"

#include "cullers.hpp"
#include "occull/error.hpp"
#include "occull/input_limits.hpp"
#include "core/format.hpp"

#include <algorithm>
#include <cassert>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <typeinfo>

namespace occull {
namespace {

using detail::Registration;

const std::vector<Registration>& registry() {
  static const std::vector<Registration> entries = [] {
    std::vector<Registration> r = {
        detail::none_registration(),    detail::vfc_registration(),     detail::stopwait_registration(),
        detail::perobject_registration(), detail::chc_registration(),   detail::chcpp_registration(),
        detail::nohc_registration(),    detail::grid_registration(),    detail::hiz_registration(),
        detail::soc_registration(),     detail::auto_registration(),
        detail::tilevfc_registration(), detail::pertile_registration(), detail::tiles_registration(),
    };
    // The oracle is made by the lab (it needs each frame's ground truth).
    r.push_back({{"oracle", "renders exactly the ground-truth visible set, no queries: the lower bound (occull bench only)",
                  true,
                  {{"set", "pixels", "pixels|boxes",
                    "pixels: the objects with a visible pixel; boxes: the objects whose boxes reach in front of the "
                    "full scene's depth at a pixel centre, the bound of every culler that tests an object by its box"}},
                  true, SceneKind::any},
                 {},
                 {},
                 {},
                 {}});
    return r;
  }();
  return entries;
}

const Registration* find(std::string_view name) {
  for (const Registration& e : registry())
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
    throw InputError(detail::format("option '{}' is not of the form algorithm.key=value "
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
    throw InputError(detail::format("option {}: '{}' is not a whole number", key, s));
  if (v < lo || v > hi)
    throw InputError(detail::format("option {}: {} is outside [{}, {}]", key, v, lo, hi));
  return v;
}

double Options::get_double(const std::string& key, double fallback, double lo, double hi) const {
  const auto it = values_.find(key);
  if (it == values_.end()) return fallback;
  const std::string& s = it->second;
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v))
    throw InputError(detail::format("option {}: '{}' is not a number", key, s));
  if (v < lo || v > hi)
    throw InputError(detail::format("option {}: {} is outside [{}, {}]", key, v, lo, hi));
  return v;
}

bool Options::get_bool(const std::string& key, bool fallback) const {
  const auto it = values_.find(key);
  if (it == values_.end()) return fallback;
  const std::string v = lower(it->second);
  if (v == "on" || v == "true" || v == "yes" || v == "1") return true;
  if (v == "off" || v == "false" || v == "no" || v == "0") return false;
  throw InputError(detail::format("option {}: '{}' is not on/off", key, it->second));
}

std::span<const AlgorithmInfo> algorithms() {
  static const std::vector<AlgorithmInfo> infos = [] {
    std::vector<AlgorithmInfo> v;
    for (const Registration& e : registry()) v.push_back(e.info);
    return v;
  }();
  return infos;
}

std::string algorithm_names() {
  std::string out;
  for (const Registration& e : registry()) out += (out.empty() ? "" : ", ") + e.info.name;
  return out;
}

namespace {

// Throws unless `sub` is an option of `entry`.
void check_option(const Registration& entry, const std::string& key, const std::string& sub) {
  std::string valid;
  for (const OptionInfo& o : entry.info.options) {
    if (o.key == sub) return;
    valid += (valid.empty() ? "" : ", ") + o.key;
  }
  throw InputError(detail::format("unknown option '{}' of {}; valid options: {}", key, entry.info.name,
                               valid.empty() ? "(none)" : valid));
}

}  // namespace

void check_options(const Options& options) {
  for (const auto& [key, value] : options.values()) {
    const auto dot = key.find('.');
    const std::string algo = key.substr(0, dot);
    const Registration* entry = find(algo);
    if (!entry)
      throw InputError(detail::format("option '{}' names unknown algorithm '{}'; valid algorithms: {}",
                                   key, algo, algorithm_names()));
    check_option(*entry, key, key.substr(dot + 1));
  }
}

bool runs_on(const AlgorithmInfo& info, bool tiled) noexcept {
  return info.scenes == SceneKind::any || (info.scenes == SceneKind::tiled) == tiled;
}

std::vector<std::string> default_algorithms(bool tiled) {
  std::vector<std::string> names;
  for (const Registration& e : registry()) {
    if (!runs_on(e.info, tiled)) continue;
    names.push_back(e.info.name);
    names.insert(names.end(), e.bench_variants.begin(), e.bench_variants.end());
  }
  return names;
}

std::string_view vfc_baseline(bool tiled) noexcept { return tiled ? "tilevfc" : "vfc"; }

const AlgorithmInfo& find_algorithm(std::string_view name) {
  for (const AlgorithmInfo& a : algorithms())
    if (a.name == name) return a;
  throw InputError(
      detail::format("unknown algorithm '{}'; valid algorithms: {}", name, algorithm_names()));
}

AlgorithmSpec parse_algorithm_spec(std::string_view spec, const Options& base) {
  if (spec.size() > limits::spec_chars)
    throw InputError(detail::format("algorithm spec '{}...': {} characters is past the limit of {} "
                                 "(occull::limits::spec_chars)",
                                 spec.substr(0, 32), spec.size(), limits::spec_chars));
  const auto colon = spec.find(':');
  AlgorithmSpec out{std::string(spec.substr(0, colon)), base};
  const AlgorithmInfo& info = find_algorithm(out.name);
  std::string_view rest = colon == std::string_view::npos ? std::string_view{} : spec.substr(colon + 1);
  while (!rest.empty()) {
    const auto next = rest.find(':');
    const std::string_view item = rest.substr(0, next);
    rest = next == std::string_view::npos ? std::string_view{} : rest.substr(next + 1);
    if (item.find('=') == std::string_view::npos)
      throw InputError(detail::format("algorithm '{}': '{}' is not key=value", spec, item));
    out.options.set(info.name + "." + std::string(item));
  }
  check_options(out.options);
  return out;
}

bool is_conservative(const AlgorithmSpec& spec) {
  const Registration* entry = find(spec.name);
  if (!entry) (void)find_algorithm(spec.name);  // throws, listing the valid names
  return entry->info.conservative && !(entry->approximate && entry->approximate(spec.options));
}

namespace detail {

// Forwards every call to the frame's backend and keeps the ids drawn and
// the queries issued.
class DrawRecorder final : public Backend {
 public:
  Backend* inner = nullptr;
  std::vector<ObjectId> drawn;
  bool sorted = true;  // drawn_objects() sorts the list once asked
  std::uint64_t objects = 0;
  std::uint64_t queries = 0;

  void render(std::span<const ObjectId> ids) override {
    keep(ids);
    inner->render(ids);
  }
  QueryId issue_query(std::span<const Aabb> boxes) override {
    ++queries;
    return inner->issue_query(boxes);
  }
  bool result_available(QueryId q) override { return inner->result_available(q); }
  std::uint64_t result(QueryId q) override { return inner->result(q); }
  [[nodiscard]] bool conditional_rendering() const override { return inner->conditional_rendering(); }
  void render_conditional(std::span<const ObjectId> ids, QueryId q, ConditionalWait wait) override {
    keep(ids);
    inner->render_conditional(ids, q, wait);
  }
  void flush() override { inner->flush(); }
  [[nodiscard]] DeviceCulling* device_culling() override { return inner->device_culling(); }
  [[nodiscard]] ResultReads result_reads() const override { return inner->result_reads(); }
  [[nodiscard]] BackendStats stats() const override { return inner->stats(); }

 private:
  void keep(std::span<const ObjectId> ids) {
    drawn.insert(drawn.end(), ids.begin(), ids.end());
    objects += ids.size();
  }
};

}  // namespace detail

Culler::Culler() : recorder_(std::make_unique<detail::DrawRecorder>()) {}
Culler::~Culler() = default;

FrameResult Culler::render_frame(const View& view, Backend& backend) {
  detail::DrawRecorder& r = *recorder_;
  r.inner = &backend;
  r.drawn.clear();
  r.sorted = false;
  r.objects = r.queries = 0;
  const double backend_ms = backend.stats().backend_ms;
  const auto start = std::chrono::steady_clock::now();
  FrameResult result = cull(view, r);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  result.cpu_ms = std::max(0.0, ms - (backend.stats().backend_ms - backend_ms));
  result.objects_drawn = r.objects;
  result.queries = r.queries;
  r.inner = nullptr;  // no backend kept between frames
  return result;
}

std::span<const ObjectId> Culler::drawn_objects() const {
  detail::DrawRecorder& r = *recorder_;
  if (!r.sorted) {
    std::sort(r.drawn.begin(), r.drawn.end());
    r.drawn.erase(std::unique(r.drawn.begin(), r.drawn.end()), r.drawn.end());
    r.sorted = true;
  }
  return r.drawn;
}

CullerContext with_profile(HardwareProfile profile) {
  CullerContext context;
  context.hardware_profile = [profile = std::move(profile)](const std::string& file) -> std::optional<HardwareProfile> {
    if (!file.empty())
      throw InputError(detail::format("nohc.profile={}: this program reads no profile files (its culler context "
                                      "holds one profile in memory)",
                                      file));
    return profile;
  };
  return context;
}

std::optional<double> Culler::counter(std::string_view name) const {
  std::optional<double> found;
  visit_counters([&](std::string_view n, double value) {
    if (n == name) found = value;
  });
  return found;
}

std::vector<ObjectId> objects_not_drawn(const Scene& scene, const View& view, std::span<const ObjectId> drawn) {
  std::vector<ObjectId> out;
  std::size_t k = 0;
  for (ObjectId id = 0; id < scene.objects().size(); ++id) {
    while (k < drawn.size() && drawn[k] < id) ++k;
    if (k < drawn.size() && drawn[k] == id) continue;
    if (scene.alive(id) && view.frustum.classify(scene.object(id).bounds) != Containment::outside) out.push_back(id);
  }
  return out;
}

namespace {

// The registration of algorithm `name`, checked to run on `index`'s kind of
// scene and outside the lab. Throws InputError otherwise.
const Registration& makeable(std::string_view name, const SceneIndex& index) {
  const Registration* entry = find(name);
  if (!entry) (void)find_algorithm(name);  // throws, listing the valid names
  if (!entry->make)
    throw InputError(detail::format("{} needs each frame's ground truth: it runs only in the lab "
                                 "(occull bench)",
                                 entry->info.name));
  const bool tiled = index.world != nullptr;
  if (!runs_on(entry->info, tiled)) {
    std::string fits;
    for (const Registration& e : registry())
      if (runs_on(e.info, tiled)) fits += (fits.empty() ? "" : ", ") + e.info.name;
    throw InputError(detail::format("{} does not run on {}; algorithms that do: {}", entry->info.name,
                                 tiled ? "a tiled world (it has no global BVH)" : "a scene that is not a tiled world",
                                 fits));
  }
  return *entry;
}

// A culler from its typed config, through the registration of Config::algorithm.
template <class Config>
std::unique_ptr<Culler> make_configured(const Config& config, const SceneIndex& index, const CullerContext& context) {
  const Registration& entry = makeable(Config::algorithm, index);
  assert(entry.config_type != nullptr && *entry.config_type == typeid(Config));
  return entry.make_config(index, &config, context);
}

// Independent cullers, one per view.
class IndependentViews final : public SplitScreen {
 public:
  explicit IndependentViews(std::vector<std::unique_ptr<Culler>> views) : views_(std::move(views)) {}
  [[nodiscard]] int size() const noexcept override { return int(views_.size()); }
  [[nodiscard]] Culler& view(int k) override { return *views_.at(std::size_t(k)); }

 private:
  std::vector<std::unique_ptr<Culler>> views_;
};

}  // namespace

std::unique_ptr<Culler> make_culler(std::string_view spec_text, const SceneIndex& index, const Options& base,
                                    const CullerContext& context) {
  const AlgorithmSpec spec = parse_algorithm_spec(spec_text, base);
  return makeable(spec.name, index).make(index, spec.options, context);
}

std::unique_ptr<SplitScreen> make_split_screen(std::string_view spec_text, const SceneIndex& index, int views,
                                               const Options& base, const CullerContext& context) {
  if (views < 1 || views > 16) throw InputError(detail::format("{} views: must be in [1, 16]", views));
  const AlgorithmSpec spec = parse_algorithm_spec(spec_text, base);
  const Registration& entry = makeable(spec.name, index);
  if (entry.make_views) return entry.make_views(index, views, spec.options, context);
  std::vector<std::unique_ptr<Culler>> cullers;
  for (int k = 0; k < views; ++k) cullers.push_back(entry.make(index, spec.options, context));
  return std::make_unique<IndependentViews>(std::move(cullers));
}

namespace detail {

std::unique_ptr<SplitScreen> independent_views(std::string_view algorithm, int views,
                                               const std::function<std::unique_ptr<Culler>()>& make) {
  if (views < 1 || views > 16) throw InputError(detail::format("{} views: must be in [1, 16]", views));
  if (find_algorithm(algorithm).shares_views)
    throw std::logic_error(detail::format("{}'s views share state: make_split_screen needs an overload for its config",
                                          algorithm));
  std::vector<std::unique_ptr<Culler>> cullers;
  for (int k = 0; k < views; ++k) cullers.push_back(make());
  return std::make_unique<IndependentViews>(std::move(cullers));
}

}  // namespace detail

std::unique_ptr<Culler> make_culler(const NoneConfig& config, const SceneIndex& index, const CullerContext& context) {
  return make_configured(config, index, context);
}
std::unique_ptr<Culler> make_culler(const VfcConfig& config, const SceneIndex& index, const CullerContext& context) {
  return make_configured(config, index, context);
}
std::unique_ptr<Culler> make_culler(const StopWaitConfig& config, const SceneIndex& index, const CullerContext& context) {
  return make_configured(config, index, context);
}
std::unique_ptr<Culler> make_culler(const ChcConfig& config, const SceneIndex& index, const CullerContext& context) {
  return make_configured(config, index, context);
}
std::unique_ptr<Culler> make_culler(const ChcppConfig& config, const SceneIndex& index, const CullerContext& context) {
  return make_configured(config, index, context);
}
std::unique_ptr<Culler> make_culler(const NohcConfig& config, const SceneIndex& index, const CullerContext& context) {
  return make_configured(config, index, context);
}
std::unique_ptr<Culler> make_culler(const SocConfig& config, const SceneIndex& index, const CullerContext& context) {
  return make_configured(config, index, context);
}
std::unique_ptr<Culler> make_culler(const HizConfig& config, const SceneIndex& index, const CullerContext& context) {
  return make_configured(config, index, context);
}
std::unique_ptr<Culler> make_culler(const PerObjectConfig& config, const SceneIndex& index, const CullerContext& context) {
  return make_configured(config, index, context);
}
std::unique_ptr<Culler> make_culler(const GridConfig& config, const SceneIndex& index, const CullerContext& context) {
  return make_configured(config, index, context);
}
std::unique_ptr<Culler> make_culler(const AutoConfig& config, const SceneIndex& index, const CullerContext& context) {
  return make_configured(config, index, context);
}
std::unique_ptr<Culler> make_culler(const TileVfcConfig& config, const SceneIndex& index, const CullerContext& context) {
  return make_configured(config, index, context);
}
std::unique_ptr<Culler> make_culler(const PerTileConfig& config, const SceneIndex& index, const CullerContext& context) {
  return make_configured(config, index, context);
}
std::unique_ptr<Culler> make_culler(const TilesConfig& config, const SceneIndex& index, const CullerContext& context) {
  return make_configured(config, index, context);
}

}  // namespace occull
