// NOHC: the probability and cost formulas against hand-computed values, and
// the branches of the reasonability test.
#include "cull/nohc.hpp"
#include "occull/cost_model.hpp"
#include "occull/error.hpp"
#include "occull/profile_io.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

using namespace occull;
using namespace occull::detail;

namespace {

HardwareProfile test_profile() { return test::hardware_profile(); }

}  // namespace

TEST(CostModel, BoundingBoxScreenFractionMatchesThePaperFormula) {
  // d = 10, w = h, theta = 90 deg: k = 1 / (10 * 1 * 2 * 1) = 0.05;
  // c_bb = k^2 * A_bb / 6 = 0.0025 * 24 / 6 = 0.01 for a 2 m cube.
  EXPECT_NEAR(bbox_screen_fraction(24.0, 10.0, 100, 100, M_PI / 2), 0.01, 1e-12);
  EXPECT_DOUBLE_EQ(bbox_screen_fraction(24.0, 0.0, 100, 100, M_PI / 2), 1.0);
  EXPECT_DOUBLE_EQ(bbox_screen_fraction(1e9, 1.0, 100, 100, 1.0), 1.0);  // clamped
}

TEST(CostModel, CoverageRatioOfASphereInItsBox) {
  // A sphere of radius 1: A = 4 pi, its box A_bb = 24: R_cov = 1.5 * 4 pi / 24 = pi / 4,
  // the ratio of a disc to its square.
  EXPECT_NEAR(coverage_ratio(4.0 * M_PI, 24.0), M_PI / 4.0, 1e-12);
  NodeCost n;
  n.c_bb = 0.2;
  n.r_cov = 3.0;  // many objects in one box: coverage never exceeds the box's
  EXPECT_DOUBLE_EQ(object_screen_fraction(n), 0.2);
}

TEST(CostModel, ScreenCoverageAccumulatesFrontToBack) {
  double c = 0.0;
  c = accumulate_coverage(c, 0.5);
  EXPECT_DOUBLE_EQ(c, 0.5);
  c = accumulate_coverage(c, 0.5);
  EXPECT_DOUBLE_EQ(c, 0.75);
}

TEST(CostModel, CoverageProbabilityCases) {
  EXPECT_NEAR(coverage_probability(0.81, 0.01), (0.9 - 0.1) * (0.9 - 0.1), 1e-12);
  EXPECT_DOUBLE_EQ(coverage_probability(0.3, 0.3), 0.0);  // box as big as the covered part
  EXPECT_DOUBLE_EQ(coverage_probability(0.1, 0.5), 0.0);
  EXPECT_DOUBLE_EQ(coverage_probability(1.0, 0.0), 1.0);
}

TEST(CostModel, OcclusionProbabilityByPreviousState) {
  EXPECT_DOUBLE_EQ(occlusion_probability(PreviousState::visible, 0.6), 0.5 * 0.36);
  EXPECT_DOUBLE_EQ(occlusion_probability(PreviousState::outside, 0.6), 0.6);
  EXPECT_DOUBLE_EQ(occlusion_probability(PreviousState::occluded, 0.0), 1.0);
}

TEST(CostModel, RenderTimeIsTheSlowestStage) {
  const HardwareProfile hw = test_profile();
  NodeCost n;
  n.draws = 2;
  n.triangles = 100;
  n.c_bb = 0.5;
  n.r_cov = 1.0;
  // setup 0.02, vertex 0.001, fragment 2 * 10000 * 0.5 * 1e-6 = 0.01
  EXPECT_DOUBLE_EQ(render_time(hw, n, 100, 100), 0.02);
  n.triangles = 10000;  // vertex 0.1
  EXPECT_DOUBLE_EQ(render_time(hw, n, 100, 100), 0.1);
  n.shading_cost = 10;  // fragment 2 * 5000 * 11e-6 = 0.11
  EXPECT_NEAR(render_time(hw, n, 100, 100), 0.11, 1e-12);
}

TEST(CostModel, QueryTimeAndFragmentClassInterpolation) {
  const HardwareProfile hw = test_profile();
  EXPECT_NEAR(query_time(hw, 0.5, 100, 100), 0.02 + 5000 * 1e-7, 1e-12);
  EXPECT_NEAR(hw.fragment_cost(5), 6e-6, 1e-15);    // between 0 and 10
  EXPECT_NEAR(hw.fragment_cost(20), 21e-6, 1e-15);  // beyond: extrapolated
}

// Where the model says more work costs more, it never costs less.
TEST(CostModel, TimesNeverFallAsTheWorkGrows) {
  const HardwareProfile hw = test_profile();
  NodeCost base;
  base.draws = 1;
  base.triangles = 10;
  base.c_bb = 0.01;
  for (int step = 0; step < 40; ++step) {
    NodeCost more = base;
    more.draws += std::uint32_t(step % 4);
    more.triangles += std::uint64_t(step) * 97;
    more.c_bb = std::min(1.0, base.c_bb * (1.0 + 0.3 * step));
    more.shading_cost = 0.5 * step;
    EXPECT_GE(render_time(hw, more, 100, 100), render_time(hw, base, 100, 100)) << step;
    EXPECT_GE(query_time(hw, more.c_bb, 100, 100), query_time(hw, base.c_bb, 100, 100)) << step;
    EXPECT_GE(hw.fragment_cost(step + 1), hw.fragment_cost(step)) << step;
  }
  // Coverage only grows front to back, and the probabilities stay in [0, 1].
  double c = 0.0;
  for (int i = 0; i < 50; ++i) {
    const double next = accumulate_coverage(c, 0.07);
    EXPECT_GE(next, c);
    EXPECT_LE(next, 1.0);
    c = next;
    for (double c_bb : {0.0, 0.01, 0.3, 1.0}) {
      const double p_cov = coverage_probability(c, c_bb);
      EXPECT_GE(p_cov, 0.0);
      EXPECT_LE(p_cov, 1.0);
      for (auto prev : {PreviousState::visible, PreviousState::outside, PreviousState::occluded}) {
        const double p = occlusion_probability(prev, p_cov);
        EXPECT_GE(p, 0.0);
        EXPECT_LE(p, 1.0);
      }
    }
  }
}

TEST(CostModel, MaxParallelQueries) {
  HardwareProfile hw = test_profile();
  // N_q = ceil(0.2 / min(0.02, 0.005 + 0.01)) + 1 = ceil(13.3) + 1 = 15
  EXPECT_EQ(hw.max_parallel_queries(), 15);
  hw.query_latency_ms = 0.0;
  EXPECT_EQ(hw.max_parallel_queries(), 1);
}

TEST(Reasonable, NeverWhenRenderingIsCheaperThanQuerying) {
  ReasonabilityInput in;
  in.node = {0.01, 0.05, 1.0, 1};
  in.previous = PreviousState::occluded;
  EXPECT_FALSE(query_reasonable(in));
}

TEST(Reasonable, NeverWhenQueryingTheChildrenIsCheaper) {
  const NodeEstimate kids[2] = {{1.0, 0.01, 0.5, 1}, {0.0, 0.0, 0.0, 0}};  // one child outside
  ReasonabilityInput in;
  in.node = {2.0, 0.1, 1.0, 2};
  in.children = kids;
  in.previous = PreviousState::occluded;
  EXPECT_FALSE(query_reasonable(in));
}

TEST(Reasonable, AlwaysWhenPreviouslyOccluded) {
  ReasonabilityInput in;
  in.node = {2.0, 0.1, 1.0, 1};
  in.previous = PreviousState::occluded;
  EXPECT_TRUE(query_reasonable(in));
}

TEST(Reasonable, VisibleNodeWaitsUntilTheBenefitPaysForTheQuery) {
  // B = 0.1 * (1.0 - 0.1) / 1 = 0.09 per frame; C = 0.1: needs n >= 2 frames.
  const NodeEstimate kids[2] = {{0.05, 0.1, 0.1, 1}, {0.5, 0.06, 0.1, 1}};  // first child too cheap to query
  ReasonabilityInput in;
  in.node = {1.0, 0.1, 0.1, 2};
  in.children = kids;
  in.previous = PreviousState::visible;
  in.levels = 1.0;
  in.frames_since_query = 1;
  EXPECT_FALSE(query_reasonable(in));
  in.frames_since_query = 2;
  EXPECT_TRUE(query_reasonable(in));
}

TEST(Reasonable, PreviouslyOutsideQueriesOnlyWhenExpectedFaster) {
  ReasonabilityInput in;
  in.previous = PreviousState::outside;
  in.query_overhead_ms = 1.0;  // make the leaf rule pass
  in.node = {1.0, 0.1, 0.05, 1};  // t_e = 0.1 + 0.95 = 1.05 > 1.0
  EXPECT_FALSE(query_reasonable(in));
  in.node = {1.0, 0.1, 0.5, 1};  // t_e = 0.6 < 1.0
  EXPECT_TRUE(query_reasonable(in));
}

TEST(Reasonable, GranularityPrefersLeafQueriesDuringRendering) {
  // Benefit higher than the children's, but querying every leaf while
  // rendering (T_o^o * N_l) is cheaper than this query: no query here.
  const NodeEstimate kids[2] = {{0.5, 0.05, 0.1, 2}, {0.5, 0.05, 0.1, 2}};
  ReasonabilityInput in;
  in.node = {1.0, 0.08, 0.9, 4};
  in.children = kids;
  in.previous = PreviousState::visible;
  in.frames_since_query = 100;
  in.levels = 1.0;
  in.query_overhead_ms = 0.01;  // 0.04 < 0.08
  EXPECT_FALSE(query_reasonable(in));
  in.query_overhead_ms = 0.1;  // 0.4 > 0.08
  EXPECT_TRUE(query_reasonable(in));
}

TEST(Profile, RoundTripsThroughJson) {
  const HardwareProfile p = test_profile();
  const HardwareProfile q = profile_from_json(profile_to_json(p), "test");
  EXPECT_EQ(q.renderer, p.renderer);
  EXPECT_EQ(q.fragment_ms, p.fragment_ms);
  EXPECT_DOUBLE_EQ(q.query_latency_ms, p.query_latency_ms);
}

TEST(Profile, CorruptFilesSayWhatIsWrong) {
  const auto error = [](std::string_view text) {
    try {
      (void)profile_from_json(text, "p.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("{not json").find("p.json: not a JSON"), std::string::npos);
  std::string text = profile_to_json(test_profile());
  const auto without = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    t.replace(t.find(from), from.size(), to);
    return t;
  };
  EXPECT_NE(error(without("\"triangle_ms\"", "\"x\"")).find("triangle_ms"), std::string::npos);
  EXPECT_NE(error(without("\"query_setup_ms\": 0.02", "\"query_setup_ms\": -1")).find("query_setup_ms"),
            std::string::npos);
  EXPECT_NE(error("[]").find("not an object"), std::string::npos);
  // Found by fuzz_profile: a number too large for a double escaped as nlohmann's out_of_range.
  EXPECT_NE(error("[[3E967,,]").find("p.json: not a JSON"), std::string::npos);
  std::string wide = text;  // a width that int cannot hold
  const std::size_t digits = wide.find_first_of("0123456789", wide.find("\"size\""));
  wide.replace(digits, wide.find_first_not_of("0123456789", digits) - digits, "4294967297");
  EXPECT_NE(error(wide).find("\"size\" must be in [1, 16384]"), std::string::npos) << wide;
}

TEST(Profile, CachePathNamesTheRenderer) {
  const std::string path = default_profile_path("llvmpipe (LLVM 15.0.6, 256 bits) | 4.5 Mesa");
  EXPECT_NE(path.find("occull"), std::string::npos);
  EXPECT_NE(path.find("llvmpipe"), std::string::npos);
  EXPECT_EQ(path.find(' '), std::string::npos);
}

TEST(Profile, SaveReplacesTheFileAndLeavesNoTemporaryBehind) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(::testing::TempDir()) / "occull_profile_save";
  fs::remove_all(dir);
  const std::string path = (dir / "sub" / "p.json").string();
  HardwareProfile p = test_profile();
  save_profile(p, path);
  p.triangle_ms = 3e-5;
  save_profile(p, path);
  EXPECT_DOUBLE_EQ(load_profile(path)->triangle_ms, 3e-5);
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir / "sub")) ++files;
  EXPECT_EQ(files, 1u);
  EXPECT_THROW(save_profile(p, "/proc/occull/p.json"), InputError);
}

TEST(OcclusionCalibration, ScalesTheModelByWhatTheQueriesFound) {
  OcclusionCalibration c;
  EXPECT_DOUBLE_EQ(c.ratio(PreviousState::outside), 1.0) << "the model alone until there are outcomes";
  for (int i = 0; i < 300; ++i) c.record(PreviousState::outside, 0.5, i % 10 == 0);  // 10% found occluded
  EXPECT_NEAR(c.ratio(PreviousState::outside), 0.2, 0.03);
  EXPECT_NEAR(c.scale(PreviousState::outside, 0.5), 0.1, 0.015);
  EXPECT_DOUBLE_EQ(c.ratio(PreviousState::visible), 1.0) << "each previous state on its own";
  for (int i = 0; i < 300; ++i) c.record(PreviousState::visible, 0.1, true);  // the model underrates
  EXPECT_DOUBLE_EQ(c.ratio(PreviousState::visible), 4.0) << "at most 4x";
  EXPECT_DOUBLE_EQ(c.scale(PreviousState::visible, 0.5), 1.0) << "a probability stays within [0, 1]";
  for (int i = 0; i < 300; ++i) c.record(PreviousState::outside, 0.5, false);
  EXPECT_DOUBLE_EQ(c.ratio(PreviousState::outside), 1.0 / 16.0) << "never below 1/16";
  EXPECT_DOUBLE_EQ(c.scale(PreviousState::occluded, 1.0), 1.0) << "an occluded node stays certain";
}
