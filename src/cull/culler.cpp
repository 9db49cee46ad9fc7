// The algorithm registry and option parsing.
#include "occull/culler.hpp"

#include "cullers.hpp"
#include "occull/error.hpp"
#include "occull/input_limits.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fmt/format.h>

namespace occull {
namespace {

using Factory = std::unique_ptr<Culler> (*)(const SceneIndex&, const Options&, const CullerContext&);

struct Entry {
  AlgorithmInfo info;
  Factory make;
};

const std::vector<Entry>& registry() {
  static const std::vector<Entry> entries = {
      {{"none", "render every object (reference cost of no culling)", true, {}, false, SceneKind::any},
       &detail::make_none},
      {{"vfc", "hierarchical view-frustum culling over the BVH, front to back", true, {}},
       &detail::make_vfc},
      {{"stopwait", "hierarchical stop-and-wait: query every node in the frustum front to back, wait for each",
        true,
        {{"threshold", "0", "a node is visible when more samples (pixels) pass", true},
         {"virtual_leaf", "0", "subtrees with at most this many triangles count as leaves (0: off)"}}},
       &detail::make_stopwait},
      {{"perobject", "per-object async queries after an occluder pre-pass; visible objects re-tested every N frames (seed 002)",
        false,
        {{"interval", "5", "MAX_FRAMES_WO_OCCLUSION_TESTING: frames a visible object goes untested"},
         {"render_pending", "on", "draw an object while its query is pending"},
         {"prepass", "on", "draw occluders (class always) first and never test them"},
         {"threshold", "0", "an object is visible when more samples (pixels) pass", true}}},
       &detail::make_perobject},
      {{"chc", "coherent hierarchical culling (Bittner & Wimmer 2004; seed 000 Listing 8.4.1)", true,
        {{"threshold", "0", "a node is visible when more samples (pixels) pass", true},
         {"skip", "0", "n_av: a visible leaf is assumed visible for n_av frames, queried in frame n_av+1"},
         {"flush_every", "8", "hand queries to the device this many at a time, and poll only those handed over (1: each at once)"},
         {"virtual_leaf", "0", "subtrees with at most this many triangles count as leaves (0: off)"}}},
       &detail::make_chc},
      {{"chcpp", "CHC++: batched i/v-queues, render queue, multiqueries, jittered re-queries, tight bounds (seed 000)",
        true,
        {{"batch", "50", "b: previously invisible nodes per query batch (1: no batching)"},
         {"vqueue", "on", "defer queries of visible leaves to fill idle time (off: query each at once)"},
         {"multiquery", "on", "group previously invisible nodes into multiqueries by p_keep"},
         {"jitter", "on", "first re-query of a newly visible leaf after a random 0 < r < n_av frames"},
         {"n_av", "6", "frames between queries of a visible leaf"},
         {"tight", "on", "query with the descendants' boxes (tighter bounding volumes)"},
         {"d_max", "3", "tight bounds: levels below the node"},
         {"s_max", "1.4", "tight bounds: most total surface area, relative to the node's"},
         {"virtual_leaf", "1500", "subtrees with at most this many triangles count as leaves (0: off)"},
         {"leaf_objects", "0", "... and with at most this many objects (0: any number; 8 cost more queries than it saved on track/lap)"},
         {"threshold", "0", "a node is visible when more samples (pixels) pass", true},
         {"pkeep_samples", "20", "tests at persistence i before the measured p_keep(i) replaces the formula"},
         {"seed", "1", "random seed of the jitter"},
         {"flush", "on", "flush the device after each query batch so its results come back sooner"},
         {"render_batch", "20000", "also hand the render queue over (and flush) once it holds this many triangles; 0: only before query batches"},
         {"enter_p_min", "0.1", "query nodes entering the view (not occluded last frame) only in BVH regions where at least this share of them was found occluded; elsewhere draw them and learn from their first re-query (0: always query, as CHC++)"},
         {"backoff", "2", "a visible leaf found visible again k times in a row waits n_av * 2^min(k-1, backoff) frames for its next query (0: always n_av)"},
         {"gate_depth", "5", "BVH depth of the regions that learn that share each on their own"}}},
       &detail::make_chcpp},
      {{"nohc", "near optimal hierarchical culling: occlusion probability + calibrated hardware cost model (seed 001)",
        true,
        {{"profile", "(calibrated)", "hardware profile JSON; occull bench calibrates and caches one per renderer"},
         {"threshold", "0", "a node is visible when more samples (pixels) pass", true},
         {"fragments_per_pixel", "2", "overdraw assumed when estimating shaded fragments"},
         {"visible_factor", "0.5", "p_occl = factor * p_cov^2 for nodes visible in the last frame"},
         {"levels", "0", "levels the benefit is spread over (0: log2(N_h + 1))"},
         {"max_parallel", "0", "N_q: queries in flight before the oldest counts as finished (0: from the profile)"},
         {"exact_area", "on", "c_bb from the exact projected box area (off: the paper's approximation)"},
         {"learn", "on", "correct the occlusion probabilities by the share of queries that found nodes occluded, per previous state (off: the paper's model alone)"},
         {"flush_every", "8", "hand queries to the device this many at a time, and poll only those handed over (1: each at once)"},
         {"virtual_leaf", "0", "subtrees with at most this many triangles count as leaves (0: off)"}}},
       &detail::make_nohc},
      {{"grid",
        "uniform grid in occlusion order, cell queries read a frame later, occluder pre-pass, per-frame query cap "
        "(Seletsky, seed 003); may pop",
        false,
        {{"cell", "0", "cell edge, scene units (0: twice the median object size, at most 256 cells along the scene)"},
         {"traversal", "frustum", "frustum: rasterize the frustum slice by slice; box: every cell of its bounding box"},
         {"cap", "4000", "queries per frame; cells visible by their last answer are queried past it"},
         {"vis_duration", "20", "frames a visible answer holds"},
         {"vis_growth", "4", "... longer by this per consecutive frame that hit the cap"},
         {"invis_duration", "1", "frames an occluded answer holds (1: query again next frame)"},
         {"invis_growth", "1", "... longer by this per consecutive frame that hit the cap"},
         {"prepass", "75", "occluders of class sometimes drawn in the pre-pass per frame (class always: all)"},
         {"unknown", "visible", "a cell the frustum did not meet last frame: visible (draw it while its query runs) or hidden (the thesis: it pops in a frame late)"},
         {"tight", "on", "query the box of what a cell holds instead of the whole cell"},
         {"latency", "0", "frames before a hidden cell's answer is used: 0 waits for it after the colour pass and draws the cells found visible in the same frame; 1 uses it next frame (the thesis: they pop in a frame late)"},
         {"conditional", "wait", "pre-pass of a cell queried this frame under conditional rendering on its query: wait (the device waits for the result), no_wait (draws while it is unknown) or off"},
         {"threshold", "0", "a cell is visible when more samples (pixels) pass", true},
         {"seed", "1", "random seed of the answers' extra duration when capped"},
         {"split", "reveal", "split screen (bench --views): how the views share the cap; reveal: an even split of what the queries of drawn cells leave, capped at each view's recent peak demand, and what a view does not need lent in proportion to demand x share of its re-queries of hidden cells that found them visible (measured: less popping than even); even: cap / views each"},
         {"split_floor", "1", "with split=reveal: share of an even split of what the queries of drawn cells leave each view is sure of (below 1, more goes by reveal rate)"}}},
       &detail::make_grid},
      {{"auto",
        "adaptive: runs the cheapest of chcpp, vfc and nohc for this view, learnt from the measured frame times, "
        "with hysteresis",
        true,
        {{"candidates", "chcpp+vfc+nohc", "cullers to choose among, joined by +, tried in this order (nohc only with a profile, which occull bench passes)"},
         {"trial", "2", "frames a candidate runs when tried (its cost: their median, per unit of frame content)"},
         {"period", "50", "frames between tries of a challenger (doubled after each lost try, up to 16x)"},
         {"margin", "0.15", "a challenger must be this much cheaper to take over (frame times of one culler vary more than 5 % between frames)"}}},
       &detail::make_auto},
      {{"tilevfc", "tiled worlds: view-frustum culling over the BVH of every tile instance in the frustum, nearest tile first (seed 004's baseline)",
        true,
        {{"evict", "60", "frames a tile instance may go unused before its BVH instance is freed"}},
        false, SceneKind::tiled},
       &detail::make_tilevfc},
      {{"pertile", "tiled worlds: every tile instance in the frustum culled by its own CHC++ context, nearest first, no tile queries (seed 004)",
        true,
        {{"evict", "60", "frames a tile instance may go unused before its BVH instance and CHC++ context are freed"}},
        false, SceneKind::tiled},
       &detail::make_pertile},
      {{"tiles", "tiled worlds: visibility propagated tile to tile by queries of the common box, front to back, "
                 "with temporal prediction; each visible tile culled by its own CHC++ (seed 004, Algorithms 1-4)",
        true,
        {{"local", "chcpp", "culling inside a visible tile: chcpp (its own CHC++ context) or none (draw the whole tile)"},
         {"evict", "60", "frames a tile instance may go unused before its BVH instance and CHC++ context are freed"},
         {"neighbors", "8", "neighbours a visible tile queries: 4 (edges) or 8 (edges and corners)"},
         {"requery", "1", "a tile found visible is queried again every N frames and drawn without a query in between (1: every frame, as the paper; N > 1 as CHC++ re-queries visible nodes)"},
         {"box", "common", "box a tile query draws: common (the union of every tile's box) or tile (the queried tile's own box: not conservative, seed 004's Figure 7, kept to show why)", true}},
        false, SceneKind::tiled},
       &detail::make_tiles},
      {{"oracle",
        "renders exactly the ground-truth visible set, no queries: the lower bound (occull bench only)",
        true, {}, true, SceneKind::any},
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

std::string Options::get_choice(const std::string& key, std::string_view fallback,
                                std::initializer_list<std::string_view> choices) const {
  const auto it = values_.find(key);
  if (it == values_.end()) return std::string(fallback);
  std::string valid;
  for (std::string_view c : choices) {
    if (c == it->second) return it->second;
    valid += fmt::format("{}{}", valid.empty() ? "" : ", ", c);
  }
  throw InputError(fmt::format("option {}: '{}' is not one of {}", key, it->second, valid));
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

bool runs_on(const AlgorithmInfo& info, bool tiled) noexcept {
  return info.scenes == SceneKind::any || (info.scenes == SceneKind::tiled) == tiled;
}

std::vector<std::string> default_algorithms(bool tiled) {
  std::vector<std::string> names;
  for (const Entry& e : registry()) {
    if (!runs_on(e.info, tiled)) continue;
    names.push_back(e.info.name);
    if (e.info.name == "tiles") names.push_back("tiles:local=none");
  }
  return names;
}

std::string_view vfc_baseline(bool tiled) noexcept { return tiled ? "tilevfc" : "vfc"; }

const AlgorithmInfo& find_algorithm(std::string_view name) {
  for (const AlgorithmInfo& a : algorithms())
    if (a.name == name) return a;
  throw InputError(
      fmt::format("unknown algorithm '{}'; valid algorithms: {}", name, algorithm_names()));
}

AlgorithmSpec parse_algorithm_spec(std::string_view spec, const Options& base) {
  if (spec.size() > limits::spec_chars)
    throw InputError(fmt::format("algorithm spec '{}...': {} characters is past the limit of {} "
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
      throw InputError(fmt::format("algorithm '{}': '{}' is not key=value", spec, item));
    out.options.set(info.name + "." + std::string(item));
  }
  check_options(out.options);
  return out;
}

bool is_conservative(const AlgorithmSpec& spec) {
  const AlgorithmInfo& info = find_algorithm(spec.name);
  if (!info.conservative) return false;
  for (const OptionInfo& o : info.options) {
    if (!o.approximate_unless_default) continue;
    const auto it = spec.options.values().find(spec.name + "." + o.key);
    if (it != spec.options.values().end() && it->second != o.default_value) return false;
  }
  return true;
}

FrameStats Culler::render_frame(const View& view, Backend& backend) {
  recorder_.inner = &backend;
  recorder_.drawn.clear();
  drawn_sorted_ = false;
  FrameStats stats = cull(view, recorder_);
  recorder_.inner = nullptr;  // no backend kept between frames
  return stats;
}

std::span<const ObjectId> Culler::drawn_objects() const {
  if (!drawn_sorted_) {
    std::vector<ObjectId>& d = recorder_.drawn;
    std::sort(d.begin(), d.end());
    d.erase(std::unique(d.begin(), d.end()), d.end());
    drawn_sorted_ = true;
  }
  return recorder_.drawn;
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

std::unique_ptr<Culler> make_culler(std::string_view spec_text, const SceneIndex& index, const Options& base,
                                    const CullerContext& context) {
  const AlgorithmSpec spec = parse_algorithm_spec(spec_text, base);
  const Options& options = spec.options;
  const Entry* entry = find(spec.name);
  const std::string prefix = entry->info.name + ".";
  for (const auto& [key, value] : options.values())
    if (key.rfind(prefix, 0) == 0) check_option(*entry, key, key.substr(prefix.size()));
  if (!entry->make)
    throw InputError(fmt::format("{} needs each frame's ground truth: it runs only in the harness "
                                 "(occull bench)",
                                 entry->info.name));
  const bool tiled = index.world != nullptr;
  if (!runs_on(entry->info, tiled)) {
    std::string fits;
    for (const Entry& e : registry())
      if (runs_on(e.info, tiled)) fits += (fits.empty() ? "" : ", ") + e.info.name;
    throw InputError(fmt::format("{} does not run on {}; algorithms that do: {}", entry->info.name,
                                 tiled ? "a tiled world (it has no global BVH)" : "a scene that is not a tiled world",
                                 fits));
  }
  return entry->make(index, options, context);
}

}  // namespace occull
