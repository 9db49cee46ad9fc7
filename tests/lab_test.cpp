// Ground truth, verification, the oracle and the report writers.
#include "occull/lab.hpp"
#include "gl_test_util.hpp"
#include "occull/error.hpp"
#include "occull/report.hpp"
#include "lab/watchdog.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <tinyxml2.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <map>
#include <mutex>
#include <condition_variable>
#include <optional>
#include <sstream>

using namespace occull;

namespace {

constexpr const char* kSmallCity = "city:blocks=3,traffic=6";

gl::RendererOptions small_target() { return test::small_target(160, 90); }

// Renders what an inner culler renders, minus one object.
class DroppingCuller final : public Culler {
 public:
  DroppingCuller(std::unique_ptr<Culler> inner, ObjectId dropped)
      : inner_(std::move(inner)), dropped_(dropped) {}
  FrameResult cull(const View& view, Backend& backend) override {
    Filter filter(backend, dropped_);
    return inner_->render_frame(view, filter);
  }

 private:
  struct Filter final : Backend {
    Filter(Backend& b, ObjectId d) : inner(b), dropped(d) {}
    void render(std::span<const ObjectId> objects) override {
      std::vector<ObjectId> kept;
      for (ObjectId id : objects)
        if (id != dropped) kept.push_back(id);
      inner.render(kept);
    }
    QueryId issue_query(std::span<const Aabb> boxes) override { return inner.issue_query(boxes); }
    bool result_available(QueryId q) override { return inner.result_available(q); }
    std::uint64_t result(QueryId q) override { return inner.result(q); }
    BackendStats stats() const override { return inner.stats(); }
    Backend& inner;
    ObjectId dropped;
  };
  std::unique_ptr<Culler> inner_;
  ObjectId dropped_;
};

// An object visible in every frame of the truth, if any.
std::optional<ObjectId> always_visible(const std::vector<FrameTruth>& truth) {
  std::map<ObjectId, std::size_t> frames;
  for (const FrameTruth& t : truth)
    for (const auto& o : t.visible) ++frames[o.id];
  for (const auto& [id, n] : frames)
    if (n == truth.size()) return id;
  return std::nullopt;
}

// The names in docs/lab.md's "JSON output" block (every "quoted" word).
std::set<std::string> readme_json_names() {
  std::ifstream in(std::string(OCCULL_SOURCE_DIR) + "/docs/lab.md");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto heading = text.find("## JSON output");
  const auto open = text.find("```", heading);
  const auto close = text.find("```", open + 3);
  std::set<std::string> names;
  if (heading == std::string::npos || open == std::string::npos || close == std::string::npos) return names;
  for (std::size_t i = text.find('"', open); i < close; i = text.find('"', i + 1)) {
    const std::size_t end = text.find('"', i + 1);
    names.insert(text.substr(i + 1, end - i - 1));
    i = end;
  }
  return names;
}

// Every object key of a JSON document, recursively (array elements too).
void collect_keys(const nlohmann::json& j, std::set<std::string>& keys) {
  if (j.is_object()) {
    for (const auto& [k, v] : j.items()) {
      keys.insert(k);
      collect_keys(v, keys);
    }
  } else if (j.is_array()) {
    for (const auto& v : j) collect_keys(v, keys);
  }
}

class LabTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    session_ = std::make_unique<Session>(kSmallCity, small_target());
    path_ = &session_->bundle().path("turn");
    truth_ = session_->ground_truth(*path_, kFrames);
  }
  static void TearDownTestSuite() { session_.reset(); }
  static constexpr int kFrames = 12;
  static std::unique_ptr<Session> session_;
  static const CameraPath* path_;
  static std::vector<FrameTruth> truth_;
};
std::unique_ptr<Session> LabTest::session_;
const CameraPath* LabTest::path_ = nullptr;
std::vector<FrameTruth> LabTest::truth_;

}  // namespace

TEST(CheckFrame, CountsMissedWrongPixelsAndExtraObjects) {
  const std::vector<gl::Renderer::ObjectPixels> truth{{1, 100}, {4, 7}, {5, 30}};
  const std::vector<ObjectId> rendered{1, 2, 2, 5, 6};
  FrameStats s;
  const auto missed = check_frame(truth, rendered, 8, s);
  EXPECT_EQ(missed, std::vector<ObjectId>{4});
  EXPECT_EQ(s.truth_objects, 3u);
  EXPECT_EQ(s.missed_objects, 1u);
  EXPECT_EQ(s.wrong_pixels, 7u);
  EXPECT_EQ(s.extra_objects, 2u);  // 2 and 6; duplicates count once
}

TEST(CheckFrame, AnObjectSeenOnlyThroughDepthErrorsLeftOutIsNotMissed) {
  const std::vector<gl::Renderer::ObjectPixels> truth{{1, 100}, {4, 7}, {5, 30}};
  const std::vector<ObjectId> rendered{1};
  const std::vector<ObjectId> depth_error_only{4};
  FrameStats s;
  EXPECT_EQ(check_frame(truth, rendered, 8, s, depth_error_only), std::vector<ObjectId>{5});
  EXPECT_EQ(s.missed_objects, 1u);
  EXPECT_EQ(s.wrong_pixels, 30u);
  EXPECT_EQ(s.depth_error_objects, 1u);
  // Drawn, it is simply drawn.
  EXPECT_TRUE(check_frame(truth, std::vector<ObjectId>{1, 4, 5}, 8, s, depth_error_only).empty());
  EXPECT_EQ(s.depth_error_objects, 0u);
}

namespace {

// An 8 x 8 image filled by object 0, a 2 m cube 9 to 11 m ahead of the eye,
// every pixel at the depth of a point `distance` metres ahead.
struct DepthErrorImage {
  Scene scene = test::box_scene({{{-1, -1, -11}, {1, 1, -9}}});
  View view;
  std::vector<std::uint32_t> ids = std::vector<std::uint32_t>(64, 1);
  std::vector<float> depth;
  DepthErrorImage(DepthMode mode, float distance) {
    view = make_view({{0, 0, 0}, 0, 0}, {10.0f, 0.1f, 100.0f, mode}, 8, 8);  // every pixel's ray hits the cube
    const glm::vec4 c = view.view_proj * glm::vec4(0, 0, -distance, 1);
    const float stored = view.clip.depth == DepthRange::zero_to_one ? c.z / c.w : 0.5f * c.z / c.w + 0.5f;
    depth.assign(64, view.clip.reversed_z ? 1.0f - stored : stored);
  }
  std::vector<ObjectId> only() const { return seen_only_through_depth_errors(scene, view, ids, depth, 8, 8); }
};

}  // namespace

TEST(DepthErrors, PixelsNearerThanTheirBoxAreTheRasterisersOnly) {
  for (DepthMode mode : {DepthMode::standard, DepthMode::reversed}) {
    EXPECT_EQ(DepthErrorImage(mode, 5.0f).only(), std::vector<ObjectId>{0}) << int(mode);
    EXPECT_TRUE(DepthErrorImage(mode, 9.0f).only().empty()) << int(mode);   // its front face
    EXPECT_TRUE(DepthErrorImage(mode, 10.5f).only().empty()) << int(mode);  // inside
    EXPECT_TRUE(DepthErrorImage(mode, 20.0f).only().empty()) << int(mode);  // beyond: no surface, but not nearer
    // Within what a rasteriser may do (1 mm nearer than its face, 9 m away:
    // less than a 64th of a pixel there): its own. 5 cm nearer: not.
    EXPECT_TRUE(DepthErrorImage(mode, 8.999f).only().empty()) << int(mode);
    EXPECT_EQ(DepthErrorImage(mode, 8.95f).only(), std::vector<ObjectId>{0}) << int(mode);
    // One pixel of its own surface is enough.
    DepthErrorImage one(mode, 5.0f);
    one.depth[27] = DepthErrorImage(mode, 9.5f).depth[27];
    EXPECT_TRUE(one.only().empty()) << int(mode);
    // The background and ids past the scene are nobody's.
    DepthErrorImage none(mode, 5.0f);
    std::fill(none.ids.begin(), none.ids.end(), 0u);
    none.ids[3] = 7;
    EXPECT_TRUE(none.only().empty()) << int(mode);
  }
}

// The box bound on the same image: the cube's box reaches in front of the
// depth where the depth lies at or behind its front face.
TEST(BoxReach, ABoxReachesWhereItLiesNoFartherThanTheDepth) {
  const auto reach = [](const DepthErrorImage& image) {
    const std::vector<ObjectId> all{0};
    return !boxes_reaching_depth(image.scene, image.view, all, image.depth, 8, 8).empty();
  };
  for (DepthMode mode : {DepthMode::standard, DepthMode::reversed}) {
    EXPECT_FALSE(reach(DepthErrorImage(mode, 5.0f))) << int(mode);  // a wall before it
    EXPECT_TRUE(reach(DepthErrorImage(mode, 9.0f))) << int(mode);   // its front face
    EXPECT_TRUE(reach(DepthErrorImage(mode, 10.5f))) << int(mode);
    EXPECT_TRUE(reach(DepthErrorImage(mode, 20.0f))) << int(mode);
    // Within a rasteriser's error of its face (1 mm, 9 m away): reaches. 5 cm nearer: hidden.
    EXPECT_TRUE(reach(DepthErrorImage(mode, 8.999f))) << int(mode);
    EXPECT_FALSE(reach(DepthErrorImage(mode, 8.95f))) << int(mode);
    // One pixel is enough.
    DepthErrorImage one(mode, 5.0f);
    one.depth[27] = DepthErrorImage(mode, 9.5f).depth[27];
    EXPECT_TRUE(reach(one)) << int(mode);
    // Pixels showing nothing: anything on their rays reaches.
    DepthErrorImage none(mode, 5.0f);
    std::fill(none.depth.begin(), none.depth.end(), 1.0f);
    EXPECT_TRUE(reach(none)) << int(mode);
    // A box beside the image holds none of its pixels; one around the eye
    // reaches whatever the depth.
    DepthErrorImage aside(mode, 20.0f);
    aside.scene = test::box_scene({{{40, -1, -11}, {42, 1, -9}}, {{-1, -1, -1}, {1, 1, 1}}});
    const std::vector<ObjectId> both{0, 1};
    EXPECT_EQ(boxes_reaching_depth(aside.scene, aside.view, both, aside.depth, 8, 8), std::vector<ObjectId>{1})
        << int(mode);
  }
}

TEST(SummarizeRuns, MediansOverRepeatsAndRatiosWithinARepeat) {
  const auto run = [](const char* name, int rep, std::vector<double> ms, std::uint32_t missed) {
    AlgorithmRun r{name, rep, true, {}, 0};
    for (double m : ms) {
      FrameStats f;
      f.frame_ms = m;
      f.queries = 10;
      f.missed_objects = missed;
      r.frames.push_back(f);
    }
    return r;
  };
  // Repeat 1 ran on a machine twice as slow: ratios stay 0.5.
  const std::vector<AlgorithmRun> runs{run("vfc", 0, {10, 10}, 0), run("fast", 0, {5, 5}, 0),
                                       run("vfc", 1, {20, 20}, 0), run("fast", 1, {10, 10}, 1),
                                       run("vfc", 2, {12, 12}, 0), run("fast", 2, {6, 6}, 0)};
  const auto s = summarize_runs(runs);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].name, "vfc");
  EXPECT_DOUBLE_EQ(s[0].frame_ms.mean, 12.0);
  EXPECT_DOUBLE_EQ(s[1].ratio_to_vfc, 0.5);
  EXPECT_DOUBLE_EQ(s[1].queries_per_frame, 10.0);
  EXPECT_EQ(s[1].missed_objects, 2u);  // the worst repeat
  EXPECT_EQ(s[1].ratio_to_oracle, 0.0);
}

TEST(Verdict, MissesOfConservativeRunsFailThoseOfOthersArePopping) {
  const auto run = [](const char* name, bool conservative, std::uint32_t missed) {
    AlgorithmRun r{name, 0, conservative, {}, 0};
    FrameStats f;
    f.frame_ms = 1.0;
    f.missed_objects = missed;
    f.truth_objects = 100;
    r.frames.assign(3, f);
    return r;
  };
  BenchResult r;
  r.verified = true;
  r.width = r.height = 8;
  r.frames = 3;
  r.runs = {run("vfc", true, 0), run("perobject", false, 2), run("chc:threshold=4", false, 1)};
  r.summaries = summarize_runs(r.runs);
  EXPECT_TRUE(verification_failures(r).empty());
  std::ostringstream table;
  print_table(r, table);
  EXPECT_NE(table.str().find("verification passed: the conservative algorithms (vfc)"), std::string::npos)
      << table.str();
  EXPECT_NE(table.str().find("perobject: 6 missed (2.00% of the visible object-frames) over 3 frames"),
            std::string::npos)
      << table.str();

  r.runs.push_back(run("chc", true, 1));
  r.summaries = summarize_runs(r.runs);
  const auto failed = verification_failures(r);
  ASSERT_EQ(failed.size(), 1u);
  EXPECT_EQ(failed[0]->name, "chc");
  std::ostringstream failing;
  print_table(r, failing);
  EXPECT_NE(failing.str().find("verification FAILED"), std::string::npos) << failing.str();
  EXPECT_NE(failing.str().find("chc missed 3 visible objects in 3 frames"), std::string::npos) << failing.str();
  r.verified = false;  // nothing was checked: nothing failed
  EXPECT_TRUE(verification_failures(r).empty());
}

TEST(Report, OcclusionCapturedIsTheShareOfTheOraclesAndTheBoxBoundsCulling) {
  const auto run = [](const char* name, std::uint64_t draws) {
    AlgorithmRun r{name, 0, true, {}, 0};
    FrameStats f;
    f.frame_ms = 1.0;
    f.objects_rendered = draws;
    r.frames.assign(2, f);
    return r;
  };
  BenchResult r;
  r.width = r.height = 8;
  r.frames = 2;
  const auto table = [&] {
    r.summaries = summarize_runs(r.runs);
    std::ostringstream out;
    print_table(r, out);
    return out.str();
  };
  // none draws more than vfc (it culls nothing): left out, not a negative share.
  r.runs = {run("none", 1500), run("vfc", 1000), run("soc", 680), run("oracle", 200), run("oracle:set=boxes", 400)};
  EXPECT_NE(table().find("oracle:set=boxes): soc 0.40 / 0.53\n"), std::string::npos) << table();
  r.runs.pop_back();
  EXPECT_NE(table().find("down to the oracle's): soc 0.40\n"), std::string::npos) << table();
  r.runs.pop_back();  // no oracle: nothing to share
  EXPECT_EQ(table().find("occlusion captured"), std::string::npos) << table();
}

TEST(GroundTruth, WallHidesTheBoxBehindItNotTheOneBeside) {
  auto context = gl::Context::create();
  const Scene scene = test::box_scene({{{-3, -3, -11}, {3, 3, -10}},   // wall
                                       {{-1, -1, -21}, {1, 1, -19}},   // behind it
                                       {{7, -1, -21}, {9, 1, -19}},    // beside it
                                       {{-1, -1, 5}, {1, 1, 7}}});     // behind the camera
  gl::RendererOptions o;
  o.width = o.height = 128;
  gl::Renderer r(scene, o);
  const View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 100.0f}, 128, 128);
  const ObjectId all[] = {0, 1, 2, 3};
  const auto visible = r.visible_pixels(view, all);
  ASSERT_EQ(visible.size(), 2u);
  EXPECT_EQ(visible[0].id, 0u);
  EXPECT_EQ(visible[1].id, 2u);
  EXPECT_GT(visible[0].pixels, visible[1].pixels);  // the near wall is bigger on screen
  EXPECT_EQ(r.stats().draw_calls, 0u) << "the truth pass is not counted";
}

TEST(GroundTruth, TranslucentObjectsAreVisibleWithoutHidingWhatIsBehind) {
  auto context = gl::Context::create();
  const Scene scene = test::glass_scene();
  gl::RendererOptions o;
  o.width = o.height = 128;
  gl::Renderer r(scene, o);
  const View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 100.0f}, 128, 128);
  const ObjectId all[] = {0, 1, 2};
  const auto visible = r.visible_pixels(view, all);
  ASSERT_EQ(visible.size(), 2u);
  EXPECT_EQ(visible[0].id, 0u);
  EXPECT_EQ(visible[1].id, 1u);
}

TEST_F(LabTest, TruthIsNonEmptyAndSortedForEveryFrame) {
  ASSERT_EQ(truth_.size(), std::size_t(kFrames));
  for (const FrameTruth& t : truth_) {
    EXPECT_FALSE(t.visible.empty());
    EXPECT_GT(t.coverage.pixels, 0u);
    EXPECT_TRUE(std::is_sorted(t.visible.begin(), t.visible.end(), [](auto& a, auto& b) { return a.id < b.id; }));
  }
}

TEST_F(LabTest, VfcAndNoneMissNothing) {
  for (const char* name : {"none", "vfc"}) {
    auto culler = session_->make(name, {});
    const AlgorithmRun run = session_->run_path(name, *culler, *path_, kFrames, &truth_);
    for (const FrameStats& f : run.frames) {
      EXPECT_EQ(f.missed_objects, 0u) << name;
      EXPECT_EQ(f.wrong_pixels, 0u) << name;
      EXPECT_GT(f.truth_objects, 0u);
    }
    EXPECT_EQ(run.longest_miss_frames, 0u);
  }
}

TEST_F(LabTest, OracleRendersExactlyTheTruth) {
  auto oracle = session_->make("oracle", {});
  const AlgorithmRun run = session_->run_path("oracle", *oracle, *path_, kFrames, &truth_);
  for (std::size_t k = 0; k < run.frames.size(); ++k) {
    EXPECT_EQ(run.frames[k].missed_objects, 0u);
    EXPECT_EQ(run.frames[k].extra_objects, 0u);
    EXPECT_EQ(run.frames[k].objects_rendered, truth_[k].visible.size());
    EXPECT_EQ(run.frames[k].queries, 0u);
  }
}

TEST_F(LabTest, VerificationCatchesACullerThatDropsAVisibleObject) {
  const auto victim = always_visible(truth_);
  ASSERT_TRUE(victim.has_value()) << "the turn path keeps the crossing under the camera in view";
  DroppingCuller broken(session_->make("vfc", {}), *victim);
  const AlgorithmRun run = session_->run_path("broken", broken, *path_, kFrames, &truth_);
  std::uint64_t missed = 0, wrong = 0;
  for (const FrameStats& f : run.frames) {
    EXPECT_EQ(f.missed_objects, 1u);
    missed += f.missed_objects;
    wrong += f.wrong_pixels;
  }
  EXPECT_EQ(missed, std::uint64_t(kFrames));
  EXPECT_GT(wrong, 0u);
  EXPECT_EQ(run.longest_miss_frames, std::uint32_t(kFrames));
  const auto summary = summarize_runs(std::span<const AlgorithmRun>(&run, 1));
  EXPECT_EQ(summary[0].frames_with_misses, std::uint64_t(kFrames));
}

TEST_F(LabTest, OracleWithoutTruthIsRefused) {
  auto oracle = session_->make("oracle", {});
  EXPECT_THROW(session_->run_path("oracle", *oracle, *path_, 2, nullptr), InputError);
}

TEST(Lab, RecordsMemoryEveryThousandFrames) {
  Session session("tiles_city:far=150", test::small_target(64, 36));
  auto culler = session.make("tiles", {});
  const AlgorithmRun run = session.run_path("tiles", *culler, session.path("walk10k"), 2000, nullptr);
  ASSERT_EQ(run.memory.size(), 2u);
  EXPECT_EQ(run.memory[0].frame, 1000);
  EXPECT_EQ(run.memory[1].frame, 2000);
  for (const MemorySample& m : run.memory) {
    EXPECT_GT(m.rss_mb, 10.0);
    EXPECT_GT(m.gpu_mb, 0.0) << "the meshes and the transforms of the window are in GL buffers";
  }
  const auto summary = summarize_runs(std::span<const AlgorithmRun>(&run, 1));
  EXPECT_EQ(summary[0].memory.size(), 2u);
  EXPECT_GT(summary[0].tiles_rendered_per_frame, 0.0);
  EXPECT_GT(summary[0].tiles_instantiated, 0.0);
}

TEST(Report, JsonCarriesEveryDocumentedField) {
  BenchConfig c;
  c.scene = kSmallCity;
  c.algorithms = {"vfc", "oracle", "none"};
  c.frames = 4;
  c.warmup = 1;
  c.repeat = 2;
  c.width = 96;
  c.height = 54;
  BenchResult r = run_bench(c);
  EXPECT_EQ(r.runs.size(), 6u);
  EXPECT_EQ(r.runs[3].name, "vfc");  // interleaved: A B C A B C
  // Memory is sampled every 1000 frames (Lab.RecordsMemoryEveryThousandFrames):
  // one sample stands in, so that its fields are seen.
  EXPECT_TRUE(r.summaries[0].memory.empty());
  r.summaries[0].memory.push_back({1000, 100.0, 2.0});
  std::ostringstream out;
  write_json(r, out);
  const auto doc = nlohmann::json::parse(out.str());
  // Every key the JSON has is documented in the README's "JSON output"
  // block, and every name documented there is in the JSON.
  const std::set<std::string> documented = readme_json_names();
  ASSERT_GT(documented.size(), 40u) << "the README block was found";
  std::set<std::string> keys;
  collect_keys(doc, keys);
  for (const std::string& k : keys) EXPECT_TRUE(documented.count(k)) << "undocumented JSON field " << k;
  for (const std::string& d : documented) EXPECT_TRUE(keys.count(d)) << "documented field " << d << " missing";
  EXPECT_EQ(doc["scene"]["name"], kSmallCity);
  EXPECT_GT(doc["scene"]["objects"].get<int>(), 0);
  EXPECT_GT(doc["scene"]["triangles"].get<int>(), 0);
  EXPECT_EQ(doc["path"], "street");
  EXPECT_EQ(doc["frames"], 4);
  EXPECT_EQ(doc["size"], nlohmann::json::array({96, 54}));
  EXPECT_TRUE(doc["verified"].get<bool>());
  EXPECT_GT(doc["truth_probes"].get<int>(), 0);
  ASSERT_EQ(doc["algorithms"].size(), 3u);
  for (const auto& a : doc["algorithms"]) {
    EXPECT_EQ(a["missed_objects"], 0);
    EXPECT_TRUE(a["conservative"].get<bool>());
    EXPECT_TRUE(a["model_ms_per_frame"].is_null()) << "not modelled";
  }
  EXPECT_DOUBLE_EQ(doc["algorithms"][0]["ratio_to_vfc"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(doc["algorithms"][1]["ratio_to_oracle"].get<double>(), 1.0);

  // CSV: a header and one row per algorithm, repeat and frame.
  std::ostringstream csv;
  write_csv(r, csv);
  const std::string text = csv.str();
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1 + 6 * 4);
  // Every row has a value for every column of the header.
  std::istringstream rows(text);
  std::string header, row;
  std::getline(rows, header);
  const auto columns = std::count(header.begin(), header.end(), ',');
  while (std::getline(rows, row)) EXPECT_EQ(std::count(row.begin(), row.end(), ','), columns) << row;

  // Report folder: Markdown plus well-formed SVG charts.
  const std::string dir = ::testing::TempDir() + "occull_report_test";
  std::filesystem::remove_all(dir);
  const auto files = write_report(r, dir);
  EXPECT_EQ(files.size(), 6u);
  for (const char* svg : {"frame_ms.svg", "queries.svg", "triangles.svg"}) {
    tinyxml2::XMLDocument xml;
    ASSERT_EQ(xml.LoadFile((dir + "/" + svg).c_str()), tinyxml2::XML_SUCCESS) << svg << ": " << xml.ErrorStr();
    EXPECT_STREQ(xml.RootElement()->Name(), "svg");
  }
  EXPECT_TRUE(std::filesystem::exists(dir + "/report.md"));
}

TEST(Bench, SplitScreenRunsEachViewOnItsPathAndReportsTheFrameAndEachView) {
  BenchConfig c;
  c.scene = kSmallCity;
  c.views = 2;
  c.view_paths = {"street", "turn"};
  c.algorithms = {"vfc", "grid", "oracle"};
  c.frames = 3;
  c.warmup = 1;
  c.width = 128;
  c.height = 54;
  const BenchResult r = run_bench(c);
  EXPECT_EQ(r.path, "street | turn");
  std::vector<std::string> names;
  for (const AlgorithmSummary& a : r.summaries) names.push_back(a.name);
  EXPECT_EQ(names, (std::vector<std::string>{"vfc", "vfc [view 1]", "vfc [view 2]", "grid", "grid [view 1]",
                                             "grid [view 2]", "oracle", "oracle [view 1]", "oracle [view 2]"}));
  EXPECT_TRUE(verification_failures(r).empty());
  // A frame's figures are the sums of its views'.
  for (std::size_t run = 0; run < r.runs.size(); run += 3) {
    const AlgorithmRun &whole = r.runs[run], &a = r.runs[run + 1], &b = r.runs[run + 2];
    ASSERT_EQ(whole.frames.size(), 3u);
    for (std::size_t f = 0; f < 3; ++f) {
      EXPECT_DOUBLE_EQ(whole.frames[f].frame_ms, a.frames[f].frame_ms + b.frames[f].frame_ms);
      EXPECT_EQ(whole.frames[f].objects_rendered, a.frames[f].objects_rendered + b.frames[f].objects_rendered);
      EXPECT_EQ(whole.frames[f].truth_objects, a.frames[f].truth_objects + b.frames[f].truth_objects);
    }
  }
  // The two views look at different things: their truths differ somewhere.
  bool differ = false;
  for (std::size_t f = 0; f < 3; ++f) differ = differ || r.runs[7].frames[f].objects_rendered != r.runs[8].frames[f].objects_rendered;
  EXPECT_TRUE(differ) << "the oracle of view 1 and view 2 drew the same in every frame";
  // Each view compares with the same view of vfc.
  EXPECT_DOUBLE_EQ(r.summaries[1].ratio_to_vfc, 1.0);
  EXPECT_DOUBLE_EQ(r.summaries[2].ratio_to_vfc, 1.0);
  EXPECT_DOUBLE_EQ(r.summaries[0].ratio_to_vfc, 1.0);
  c.views = 9;
  EXPECT_THROW((void)run_bench(c), InputError);
}

// auto's warm-up warms each of its candidates too: spread over the path, the
// warm-up frames are camera cuts to auto, whose schedule stays on its first
// candidate over them, and the others would pay the driver's one-off costs
// (shader variants compiled at first use) in their first timed frame.
TEST(Bench, AutosWarmUpWarmsEachOfItsCandidatesAsTheirOwnRunsWould) {
  BenchConfig c;
  c.scene = kSmallCity;
  c.algorithms = {"vfc", "auto"};
  c.frames = 2;
  c.warmup = 3;
  c.width = 128;
  c.height = 54;
  std::map<std::string, int> warm;
  const BenchResult r = run_bench(c, [&](std::string_view label, int, int, bool warmup) {
    if (warmup) ++warm[std::string(label)];
  });
  ASSERT_EQ(r.summaries.size(), 2u);
  const std::size_t candidates = r.runs[1].choices.size();
  ASSERT_GE(candidates, 2u);
  EXPECT_EQ(warm["vfc"], 3);
  EXPECT_EQ(warm["auto"], int(3 * (1 + candidates))) << "auto's " << candidates << " candidates not warmed up";
}

// The lab's watchdog: a step that does not finish is named once its time
// is up; a step that finishes is never reported. (No timing is asserted: the
// first waits as long as the watchdog takes, the second uses a time no test
// machine reaches.)
TEST(Watchdog, AStepPastItsTimeIsNamedAndAFinishedOneIsNot) {
  std::mutex mutex;
  std::condition_variable fired;
  std::vector<std::string> messages;
  const auto record = [&](const std::string& m) {
    const std::lock_guard lock(mutex);
    messages.push_back(m);
    fired.notify_all();
  };
  {
    detail::Watchdog patient(1e6, record);
    { const auto step = patient.step("a quick step"); }
  }
  EXPECT_TRUE(messages.empty());
  detail::Watchdog dog(0.01, record);
  const auto step = dog.step("ground-truth frame 7 of path street");
  std::unique_lock lock(mutex);
  fired.wait(lock, [&] { return !messages.empty(); });
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_NE(messages[0].find("ground-truth frame 7 of path street has not finished after"), std::string::npos)
      << messages[0];
  EXPECT_NE(messages[0].find("exit 1"), std::string::npos) << messages[0];
}
