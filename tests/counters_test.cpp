// The counter table (include/occull/counters.hpp) and everything made from
// it: the per-frame copy, split-screen sums, summaries, JSON, CSV and docs.
#include "occull/counters.hpp"
#include "occull/report.hpp"
#include "occull/scenes.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstddef>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace occull {
namespace {

// Where each counter's FrameStats member lies and how big it is.
struct Extent {
  std::size_t offset, size;
  std::string_view name;
};

std::vector<Extent> member_extents() {
  const FrameStats f;
  std::vector<Extent> out;
  for (const Counter& c : frame_counters())
    std::visit(
        [&](auto member) {
          const auto* at = reinterpret_cast<const std::byte*>(&(f.*member));
          out.push_back({std::size_t(at - reinterpret_cast<const std::byte*>(&f)), sizeof(f.*member), c.name});
        },
        c.frame);
  std::sort(out.begin(), out.end(), [](const Extent& a, const Extent& b) { return a.offset < b.offset; });
  return out;
}

// A frame whose counter k holds k + 1 (each value tells its column apart).
FrameStats numbered_frame() {
  FrameStats f;
  double k = 1.0;
  for (const Counter& c : frame_counters()) {
    std::visit([&](auto member) { f.*member = static_cast<std::remove_reference_t<decltype(f.*member)>>(k); },
               c.frame);
    k += 1.0;
  }
  return f;
}

TEST(Counters, EveryFrameStatsMemberHasARow) {
  // The members the table names tile FrameStats with nothing between them
  // but alignment padding: a member added without its row leaves a hole.
  const std::vector<Extent> extents = member_extents();
  std::size_t end = 0;
  for (const Extent& e : extents) {
    EXPECT_GE(e.offset, end) << e.name << " overlaps the member before it: named twice?";
    EXPECT_LT(e.offset - std::min(e.offset, end), e.size) << "a FrameStats member before " << e.name << " has no row";
    end = e.offset + e.size;
  }
  EXPECT_LT(sizeof(FrameStats) - end, alignof(FrameStats)) << "a FrameStats member at the end has no row";
}

// What a culler reports in visit_counters, by name.
std::vector<std::pair<std::string_view, double>> reported(const Culler& culler) {
  std::vector<std::pair<std::string_view, double>> out;
  culler.visit_counters([&](std::string_view name, double value) { out.emplace_back(name, value); });
  return out;
}

TEST(Counters, EveryCounterAnAlgorithmReportsHasARowAndReachesTheFrame) {
  // Every algorithm an engine can make, two frames each (the second with
  // answers to read), on a box scene or a tiled world; `hiz` needs a device.
  const Scene boxes = test::box_scene(test::scattered_boxes(60));
  const Bvh bvh = Bvh::build(boxes);
  SceneBundle world = make_scene("tiles_city:far=150");
  const Bvh no_bvh = Bvh::build(std::span<const Aabb>{}, std::span<const std::uint32_t>{});
  const View box_view = make_view({{0, 2, 40}, 0, 0}, {60.0f, 0.1f, 500.0f}, 64, 64);
  const View world_view = make_view({{1, 1.7f, -20}, 0, 0}, {60.0f, 0.1f, 150.0f}, 64, 64);
  world.world->follow(world.scene, world_view.eye);
  std::set<std::string_view> names;
  for (const AlgorithmInfo& info : algorithms()) {
    if (info.lab_only || info.device) continue;
    const bool tiled = info.scenes == SceneKind::tiled;
    const SceneIndex index = tiled ? SceneIndex{world.scene, no_bvh, world.world.get()} : SceneIndex{boxes, bvh};
    auto culler = make_culler(info.name, index, {}, with_profile(test::hardware_profile()));
    test::ScriptedBackend backend;
    for (int frame = 0; frame < 2; ++frame) {
      const FrameResult result = culler->render_frame(tiled ? world_view : box_view, backend);
      FrameStats stats;
      ASSERT_NO_THROW(copy_culler_counters(result, *culler, stats)) << info.name;
      EXPECT_EQ(stats.nodes_visited, result.nodes_visited) << info.name;
      for (const auto& [name, value] : reported(*culler)) {
        names.insert(name);
        const Counter* row = find_counter(name);
        ASSERT_NE(row, nullptr) << info.name << " reports " << name;
        EXPECT_EQ(counter_value(*row, stats), value) << info.name << ": " << name;
      }
    }
    culler->release(backend);
  }
  // The algorithms' counters, each reported by some algorithm.
  for (const char* name : {"query_batches", "multiqueries", "failed_multiqueries", "raster_ms", "boxes_tested",
                           "buffer_texels", "occluders_resting", "capped", "over_cap", "result_age", "revealed", "auto_choice",
                           "auto_tries", "auto_switches", "tiles_rendered", "tile_queries", "tile_cache"})
    EXPECT_EQ(names.count(name), 1u) << name << " is reported by no algorithm";
}

TEST(Counters, ACounterTheTableDoesNotDeclareIsABug) {
  struct Undeclared final : Culler {
    FrameResult cull(const View&, Backend&) override { return {}; }
    void visit_counters(const CounterVisitor& visit) const override { visit(name, 1.0); }
    std::string_view name;
  };
  Undeclared culler;
  FrameStats stats;
  for (std::string_view name : {"overcap", "queries"}) {  // unknown; and one the backend fills
    culler.name = name;
    try {
      copy_culler_counters({}, culler, stats);
      ADD_FAILURE() << name << " accepted";
    } catch (const std::logic_error& e) {
      EXPECT_NE(std::string(e.what()).find(std::string(name)), std::string::npos) << e.what();
    }
  }
}

TEST(Counters, EverySummarisedCounterHasAUniqueKeyThatNamesItsReduction) {
  std::vector<std::string_view> keys;
  for (const Counter& c : frame_counters()) {
    EXPECT_EQ(c.frames == Combine::none, c.key.empty()) << c.name;
    EXPECT_EQ(c.key.empty(), std::holds_alternative<std::monostate>(c.summary)) << c.name;
    EXPECT_FALSE(c.help.empty()) << c.name;
    EXPECT_FALSE(c.unit.empty()) << c.name;
    // A key says how the run's frames reduce: "_per_frame" and "_share" are means.
    if (c.key.ends_with("_per_frame") || c.key.ends_with("_share"))
      EXPECT_EQ(c.frames, Combine::mean) << c.key << " is named a mean";
    if (!c.key.empty()) keys.push_back(c.key);
  }
  std::sort(keys.begin(), keys.end());
  EXPECT_EQ(std::adjacent_find(keys.begin(), keys.end()), keys.end());
}

TEST(Counters, BackendCountersAreCopiedFromTheirSource) {
  BackendStats d;
  d.queries = 11;
  d.stalled_results = 7;
  d.wait_ms = 2.5;
  d.conditional_skipped = 3;
  FrameStats f;
  f.nodes_visited = 99;  // the culler's: left alone
  copy_backend_counters(d, f);
  EXPECT_EQ(f.queries, 11u);
  EXPECT_EQ(f.stalled, 7u);
  EXPECT_EQ(f.wait_ms, 2.5);
  EXPECT_EQ(f.conditional_skipped, 3u);
  EXPECT_EQ(f.nodes_visited, 99u);
}

TEST(Counters, SplitScreenViewsCombineAsDeclared) {
  FrameStats a, b, sum;
  a.queries = 3, b.queries = 4;
  a.capped = 0, b.capped = 1;
  a.result_age = 1.0, b.result_age = 2.0;
  a.missed_objects = 1, b.missed_objects = 2;
  add_view(sum, a);
  add_view(sum, b);
  finish_views(sum, 2);
  EXPECT_EQ(sum.queries, 7u);          // sum
  EXPECT_EQ(sum.capped, 1u);           // max
  EXPECT_EQ(sum.result_age, 1.5);      // mean
  EXPECT_EQ(sum.missed_objects, 3u);   // sum
}

BenchResult two_repeats() {
  BenchResult r;
  r.verified = true;
  r.frames = 2;
  r.repeat = 2;
  for (int rep = 0; rep < 2; ++rep) {
    AlgorithmRun run{"chc", rep, true, {}, 0};
    run.frames = {numbered_frame(), numbered_frame()};
    r.runs.push_back(run);
  }
  r.summaries = summarize_runs(r.runs);
  return r;
}

TEST(Counters, CsvHasOneColumnPerCounterInTheTablesOrder) {
  std::ostringstream out;
  write_csv(two_repeats(), out);
  std::istringstream lines(out.str());
  std::string header, row;
  std::getline(lines, header);
  std::getline(lines, row);
  std::string expected = "algorithm,repeat,frame";
  for (const Counter& c : frame_counters()) expected += "," + std::string(c.name);
  EXPECT_EQ(header, expected);
  // Counter k's column holds k + 1.
  std::istringstream cells(row);
  std::string cell;
  for (int skip = 0; skip < 3; ++skip) std::getline(cells, cell, ',');
  int k = 1;
  for (const Counter& c : frame_counters()) {
    ASSERT_TRUE(std::getline(cells, cell, ',')) << c.name;
    EXPECT_DOUBLE_EQ(std::stod(cell), k++) << c.name;
  }
}

TEST(Counters, JsonHoldsEachSummaryUnderItsKeyReducedAsDeclared) {
  BenchResult r = two_repeats();
  std::ostringstream out;
  write_json(r, out);
  const auto algo = nlohmann::json::parse(out.str())["algorithms"].at(0);
  double k = 1.0;
  for (const Counter& c : frame_counters()) {
    const double value = k;
    k += 1.0;
    if (c.key.empty()) continue;
    ASSERT_TRUE(algo.contains(std::string(c.key))) << c.key;
    const auto& got = algo[std::string(c.key)];
    if (c.modelled) {
      EXPECT_TRUE(got.is_null()) << c.key << " without --model";
      continue;
    }
    // Two equal frames in each of two equal repeats.
    const double expected = c.frames == Combine::sum ? 2.0 * value : value;
    EXPECT_DOUBLE_EQ(got.get<double>(), expected) << c.key;
  }
  r.modelled = true;
  std::ostringstream modelled;
  write_json(r, modelled);
  EXPECT_FALSE(nlohmann::json::parse(modelled.str())["algorithms"].at(0)["model_ms_per_frame"].is_null());
}

TEST(Counters, RepeatsReduceByMedianOrTheWorst) {
  BenchResult r;
  for (int rep = 0; rep < 3; ++rep) {
    FrameStats f;
    f.queries = std::uint64_t(10 * (rep + 1));         // 10, 20, 30: median 20
    f.missed_objects = std::uint32_t(rep == 1 ? 5 : 0);  // worst repeat: 5
    r.runs.push_back({"chc", rep, true, {f}, 0});
  }
  const AlgorithmSummary a = summarize_runs(r.runs).at(0);
  EXPECT_EQ(a.queries_per_frame, 20.0);
  EXPECT_EQ(a.missed_objects, 5u);
}

TEST(Counters, FrameTimesSummariseToTheirMeanMedianP95MinAndMax) {
  BenchResult r;
  for (int rep = 0; rep < 3; ++rep) {
    std::vector<FrameStats> frames;
    for (double ms : {4.0, 1.0, 3.0, 2.0, 10.0 * (rep + 1)}) {
      FrameStats f;
      f.frame_ms = ms;
      frames.push_back(f);
    }
    r.runs.push_back({"chc", rep, true, std::move(frames), 0});
  }
  const Summary s = summarize_runs(r.runs).at(0).frame_ms;  // each figure: the median of the repeats'
  EXPECT_DOUBLE_EQ(s.mean, 6.0);    // the repeats: 4, 6 and 8
  EXPECT_DOUBLE_EQ(s.median, 3.0);
  EXPECT_DOUBLE_EQ(s.p95, 20.0);    // nearest rank of 5: the largest
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 20.0);
}

// The docs name every JSON key and, in the table's order, every CSV column.
TEST(Counters, DocsAgreeWithTheTable) {
  std::ifstream in(std::string(OCCULL_SOURCE_DIR) + "/docs/lab.md");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::replace(text.begin(), text.end(), '\n', ' ');  // a sentence may wrap
  const auto json_block = text.substr(text.find("## JSON output"));
  for (const Counter& c : frame_counters())
    if (!c.key.empty())
      EXPECT_NE(json_block.find("\"" + std::string(c.key) + "\""), std::string::npos) << c.key << " undocumented";
  std::string columns = "algorithm, repeat, frame";
  for (const Counter& c : frame_counters()) columns += ", " + std::string(c.name);
  EXPECT_NE(text.find("frames.csv columns: " + columns + "."), std::string::npos)
      << "docs/lab.md should say: frames.csv columns: " << columns << ".";
}

}  // namespace
}  // namespace occull
