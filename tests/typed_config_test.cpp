// Cullers made from typed configs (occull/configs.hpp) are the cullers the
// string specs make, and a config's values are checked as the spec's are.
#include "occull/configs.hpp"
#include "occull/culler.hpp"
#include "occull/error.hpp"
#include "occull/grid_views.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace occull {
namespace {

// What a culler did over a few frames against the test double: every draw
// and every query's boxes, in order. Boxes behind z = -25 are hidden. Each
// frame is reported finished at a cost computed from its draws and queries.
struct Trace {
  std::vector<ObjectId> rendered;
  std::vector<std::vector<Aabb>> queried;
};

Trace trace(Culler& culler) {
  const View view = test::unsampled(make_view({{0, 0, 0}, 0, 0}, {70.0f, 0.1f, 500.0f}, 64, 64));
  test::ScriptedBackend backend;
  backend.visible_samples = [](std::span<const Aabb> boxes) {
    std::uint64_t samples = 0;
    for (const Aabb& b : boxes) samples += b.max.z > -25.0f ? 1 : 0;
    return samples;
  };
  for (int f = 0; f < 8; ++f) {
    const FrameResult r = culler.render_frame(view, backend);
    // A frame's cost from what it did, not from the clock: auto decides by
    // cost, and its own timing would make two equal cullers differ under load.
    culler.frame_finished({.frame_ms = 1.0 + 0.01 * double(r.objects_drawn) + 0.05 * double(r.queries),
                           .draw_calls = r.objects_drawn});
  }
  culler.release(backend);
  return {backend.rendered, backend.queried};
}

void expect_same_trace(const Trace& a, const Trace& b, const std::string& what) {
  EXPECT_EQ(a.rendered, b.rendered) << what;
  ASSERT_EQ(a.queried.size(), b.queried.size()) << what;
  for (std::size_t q = 0; q < a.queried.size(); ++q) {
    ASSERT_EQ(a.queried[q].size(), b.queried[q].size()) << what << ", query " << q;
    for (std::size_t k = 0; k < a.queried[q].size(); ++k) {
      EXPECT_EQ(a.queried[q][k].min, b.queried[q][k].min) << what << ", query " << q;
      EXPECT_EQ(a.queried[q][k].max, b.queried[q][k].max) << what << ", query " << q;
    }
  }
}

TEST(TypedConfig, MakesTheCullerItsSpecMakes) {
  Scene scene = test::box_scene(test::scattered_boxes(150));
  const Bvh bvh = Bvh::build(scene);
  const SceneIndex index{scene, bvh};
  const HardwareProfile profile = test::hardware_profile();
  const CullerContext context = with_profile(profile);
  struct Case {
    std::string spec;
    std::function<std::unique_ptr<Culler>()> typed;
  };
  const std::vector<Case> cases = {
      {"vfc", [&] { return make_culler(VfcConfig{}, index, context); }},
      {"stopwait", [&] { return make_culler(StopWaitConfig{}, index, context); }},
      {"chc:skip=2", [&] { return make_culler(ChcConfig{.skip = 2}, index, context); }},
      {"chcpp", [&] { return make_culler(ChcppConfig{}, index, context); }},
      {"chcpp:batch=3:multiquery=off:tight=off",
       [&] { return make_culler(ChcppConfig{.batch = 3, .multiquery = false, .shape = {.tight = false}}, index, context); }},
      {"nohc:learn=off", [&] { return make_culler(NohcConfig{.learn = false}, index, context); }},
      {"perobject:interval=2", [&] { return make_culler(PerObjectConfig{.interval = 2}, index, context); }},
      {"grid:cap=7", [&] { return make_culler(GridConfig{.cap = 7}, index, context); }},
      {"auto:candidates=chcpp+vfc", [&] { return make_culler(AutoConfig{.candidates = "chcpp+vfc"}, index, context); }},
  };
  std::size_t differing = 0;
  Trace first;
  for (const Case& c : cases) {
    auto from_spec = make_culler(c.spec, index, {}, context);
    auto typed = c.typed();
    const Trace expected = trace(*from_spec);
    expect_same_trace(trace(*typed), expected, c.spec);
    if (&c == &cases.front()) first = expected;
    else differing += expected.rendered != first.rendered || expected.queried.size() != first.queried.size();
  }
  // The cases differ from each other: the comparison is not of one culler with itself.
  EXPECT_GE(differing, cases.size() - 2);
}

TEST(TypedConfig, AutosCandidatesAreSpecsThatCarryTheirOptions) {
  Scene scene = test::box_scene(test::scattered_boxes(150));
  const Bvh bvh = Bvh::build(scene);
  const SceneIndex index{scene, bvh};
  Options base;
  base.set("chcpp.batch=3");
  base.set("chcpp.tight=off");
  auto from_spec = make_culler("auto:candidates=chcpp", index, base);
  auto typed = make_culler(AutoConfig{.candidates = "chcpp:batch=3:tight=off"}, index);
  const Trace expected = trace(*from_spec);
  expect_same_trace(trace(*typed), expected, "auto over chcpp:batch=3:tight=off");
  auto defaults = make_culler(AutoConfig{.candidates = "chcpp"}, index);
  const Trace plain = trace(*defaults);
  EXPECT_FALSE(plain.rendered == expected.rendered && plain.queried == expected.queried)
      << "the options make a difference here";
}

TEST(TypedConfig, MakesTheSplitScreenItsSpecMakes) {
  Scene scene = test::box_scene(test::scattered_boxes(150));
  const Bvh bvh = Bvh::build(scene);
  const SceneIndex index{scene, bvh};
  const auto compare = [&](std::string_view spec, std::unique_ptr<SplitScreen> typed) {
    auto from_spec = make_split_screen(spec, index, 2);
    ASSERT_EQ(typed->size(), 2) << spec;
    EXPECT_EQ(dynamic_cast<GridViews*>(typed.get()) != nullptr, dynamic_cast<GridViews*>(from_spec.get()) != nullptr)
        << spec << ": the views share state as the spec's do";
    for (int k = 0; k < 2; ++k)
      expect_same_trace(trace(typed->view(k)), trace(from_spec->view(k)), std::string(spec) + ", view " + std::to_string(k));
  };
  compare("chcpp:batch=3:multiquery=off", make_split_screen(ChcppConfig{.batch = 3, .multiquery = false}, index, 2));
  compare("grid:cap=7:split=even", make_split_screen(GridConfig{.cap = 7, .split = SplitPolicy::even}, index, 2));
  auto grid = make_split_screen(GridConfig{.cap = 7, .split = SplitPolicy::even}, index, 2);
  EXPECT_EQ(dynamic_cast<GridViews&>(*grid).budget().total(), 7);
  EXPECT_THROW((void)make_split_screen(GridConfig{.cap = 0}, index, 2), InputError);
  EXPECT_THROW((void)make_split_screen(ChcppConfig{}, index, 17), InputError);
}

TEST(TypedConfig, AValueOutsideItsRangeThrowsNamingItsOption) {
  Scene scene = test::box_scene(test::scattered_boxes(10));
  const Bvh bvh = Bvh::build(scene);
  const SceneIndex index{scene, bvh};
  const auto message = [](const std::function<void()>& make) -> std::string {
    try {
      make();
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no error)";
  };
  EXPECT_EQ(message([&] { (void)make_culler(ChcppConfig{.batch = 0}, index); }),
            "option chcpp.batch: 0 is outside [1, 100000]");
  EXPECT_EQ(message([&] { (void)make_culler(ChcppConfig{.shape = {.s_max = 0.5f}}, index); }),
            "option chcpp.s_max: 0.5 is outside [1, 100]");
  EXPECT_NE(message([&] { (void)make_culler(GridConfig{.split_floor = std::nan("")}, index); }).find("grid.split_floor"),
            std::string::npos);
  EXPECT_NE(message([&] { (void)make_culler(HizConfig{.texels = 3}, index); }).find("hiz.texels"), std::string::npos);
  EXPECT_NE(message([&] { (void)make_culler(NohcConfig{}, index); }).find("nohc needs a hardware profile"),
            std::string::npos);
  EXPECT_NE(message([&] { (void)make_culler(TilesConfig{}, index); }).find("tiles does not run on"), std::string::npos);
  EXPECT_EQ(message([&] { (void)make_culler(ChcppConfig{.batch = 1}, index); }), "(no error)");
}

}  // namespace
}  // namespace occull
