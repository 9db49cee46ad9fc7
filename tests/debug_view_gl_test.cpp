// The debug views on llvmpipe: the painter's pixels on a tiny scene, and
// the views of real cullers' frames against what the verifier knows.
#include "occull/debug_view.hpp"
#include "occull/gl/context.hpp"
#include "occull/gl/painter.hpp"
#include "occull/gl/renderer.hpp"
#include "occull/lab.hpp"
#include "gl_test_util.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace occull;

namespace {

constexpr int kSize = 128;

struct Rgb {
  int r, g, b;
};
Rgb pixel(const std::vector<std::uint8_t>& rgba, int width, int x, int y) {  // y from the top
  const std::size_t i = (std::size_t(y) * std::size_t(width) + std::size_t(x)) * 4;
  return {rgba[i], rgba[i + 1], rgba[i + 2]};
}
Rgb unorm(const glm::vec3& c) {
  return {int(std::lround(c.r * 255.0f)), int(std::lround(c.g * 255.0f)), int(std::lround(c.b * 255.0f))};
}
bool near(Rgb a, Rgb b) { return std::abs(a.r - b.r) <= 1 && std::abs(a.g - b.g) <= 1 && std::abs(a.b - b.b) <= 1; }
// One of the three face shades of a box of colour c.
bool box_colour(Rgb p, const glm::vec3& c) {
  return near(p, unorm(c * 0.65f)) || near(p, unorm(c * 0.8f)) || near(p, unorm(c));
}

// Where a world point lands in an image (top row 0), or nothing behind the eye.
std::optional<std::pair<int, int>> project(const glm::mat4& view_proj, const glm::vec3& p, int w, int h) {
  const glm::vec4 c = view_proj * glm::vec4(p, 1.0f);
  if (c.w <= 0.0f) return std::nullopt;
  const float x = (c.x / c.w * 0.5f + 0.5f) * float(w), y = (1.0f - (c.y / c.w * 0.5f + 0.5f)) * float(h);
  if (x < 0 || y < 0 || x >= float(w) || y >= float(h)) return std::nullopt;
  return std::pair{int(x), int(y)};
}

class DebugViewGl : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { context_ = gl::Context::create(); }
  static void TearDownTestSuite() { context_.reset(); }
  static std::unique_ptr<gl::Context> context_;
};
std::unique_ptr<gl::Context> DebugViewGl::context_;

// A wall 10 m ahead hides a box 20 m ahead; another box stands in plain view to the right.
Scene wall_scene() {
  return test::box_scene({{{-3, -3, -11}, {3, 3, -10}}, {{-1, -1, -21}, {1, 1, -19}}, {{7, -1, -21}, {9, 1, -19}}});
}

}  // namespace

TEST_F(DebugViewGl, AnOccludedQueryBoxIsPaintedInItsColourOverTheFrame) {
  const Scene scene = wall_scene();
  const View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 100.0f}, kSize, kSize);
  gl::RendererOptions ro = test::small_target(kSize, kSize);
  gl::Renderer renderer(scene, ro);
  gl::Painter painter(scene, kSize, kSize);
  renderer.begin_frame(view);
  const ObjectId all[] = {0, 1, 2};
  renderer.render(all);
  (void)renderer.end_frame();
  const std::vector<std::uint8_t> frame = renderer.read_rgba();

  FrameLog log;
  log.queries.push_back({{scene.object(1).bounds}, 0, 0, 1});  // the hidden box: 0 samples
  const DebugFrame f{scene, view, log, {}, {}, {}};
  const Picture picture = make_picture(DebugView::queries, f, 1.0f);
  const std::vector<std::uint8_t> image = painter.paint(picture, frame);
  ASSERT_EQ(image.size(), frame.size());
  // The box's face toward the eye (a z face) in the occluded colour, exactly.
  EXPECT_TRUE(near(pixel(image, kSize, kSize / 2, kSize / 2), unorm(palette::occluded * 0.65f)));
  // Elsewhere the frame, pixel for pixel: the sky and the wall around the box.
  for (const auto& [x, y] : {std::pair{2, 2}, std::pair{kSize / 2 + 20, kSize / 2}, std::pair{kSize - 3, kSize - 3}}) {
    const Rgb a = pixel(image, kSize, x, y), b = pixel(frame, kSize, x, y);
    EXPECT_TRUE(a.r == b.r && a.g == b.g && a.b == b.b) << x << "," << y;
  }
  // The painter set its own state: the renderer still draws the same frame after it.
  renderer.begin_frame(view);
  renderer.render(all);
  (void)renderer.end_frame();
  EXPECT_EQ(renderer.read_rgba(), frame);
}

TEST_F(DebugViewGl, TheOverviewShowsAMissedObjectInRedFromAbove) {
  const Scene scene = wall_scene();
  const View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 100.0f}, kSize, kSize);
  gl::Painter painter(scene, kSize, kSize);
  const FrameLog log;
  const ObjectId drawn[] = {0};
  const ObjectId truth[] = {0, 2};  // 2 was visible and not drawn
  const DebugFrame f{scene, view, log, {}, drawn, truth};
  const Picture picture = make_picture(DebugView::overview, f, 1.0f);
  const std::vector<std::uint8_t> image = painter.paint(picture, {});
  const auto at = [&](ObjectId id) {
    const auto p = project(picture.view_proj, scene.object(id).bounds.center(), kSize, kSize);
    EXPECT_TRUE(p.has_value());
    return pixel(image, kSize, p->first, p->second);
  };
  const Rgb missed = at(2), hidden = at(1), wall = at(0);
  EXPECT_GT(missed.r, 200);
  EXPECT_LT(missed.g, 30);
  EXPECT_LT(missed.b, 30);
  EXPECT_GT(hidden.b, hidden.r + 60);  // occlusion-culled: blue
  EXPECT_GT(wall.g, wall.r + 60);      // drawn: green
}

TEST_F(DebugViewGl, OccludedQueriesOfARealFrameShowWhereTheVerifierFoundNothing) {
  Session session("city:blocks=4,traffic=40", test::small_target(160, 90));
  session.set_sampling({30.0, 0.0});
  const CameraPath& path = session.path("");
  auto culler = session.make("chc", {});
  const int frames = 40, k = frames - 1;
  FrameLog log;
  FrameStats stats;
  for (int i = 0; i <= k; ++i)
    stats = session.run_frame(*culler, session.view_at(path, i, frames), session.frame_time(path, i, frames),
                              i == k ? &log : nullptr);
  const View view = session.view_at(path, k, frames);
  const auto drawn_span = session.recording().objects();
  const std::vector<ObjectId> drawn(drawn_span.begin(), drawn_span.end());
  const std::vector<std::uint8_t> frame = session.renderer().read_rgba();
  std::vector<ObjectId> truth;
  for (const auto& v : session.truth_at(path, k, frames).visible) truth.push_back(v.id);
  const Scene& scene = session.bundle().scene;
  const DebugFrame f{scene, view, log, {}, drawn, truth};

  // The log is the frame's: as many queries and state changes as the renderer counted.
  ASSERT_EQ(log.queries.size(), stats.queries);
  const Picture batches = make_picture(DebugView::batches, f, 160.0f / 90.0f);
  EXPECT_EQ(batches.legend.at(2).count, stats.state_changes);

  const std::vector<QueryOutcome> outcome = classify_queries(scene, log);
  gl::Painter painter(scene, 160, 90);
  const std::vector<std::uint8_t> image = painter.paint(make_picture(DebugView::queries, f, 160.0f / 90.0f), frame);
  std::size_t checked = 0;
  for (std::size_t q = 0; q < outcome.size(); ++q) {
    if (outcome[q] != QueryOutcome::occluded) continue;
    for (const Aabb& b : log.queries[q].boxes) {
      // Every object in a box found occluded that the frame did not draw
      // is invisible in the truth (a node's box may hold other nodes'
      // objects too: those may be drawn, and visible).
      for (ObjectId id = 0; id < scene.objects().size(); ++id)
        if (b.contains(scene.object(id).bounds.center()) && std::find(drawn.begin(), drawn.end(), id) == drawn.end())
          EXPECT_FALSE(std::binary_search(truth.begin(), truth.end(), id)) << "object " << id << " in query " << q;
      // And the box is painted in the occluded colour where its centre lands
      // (the top layer; a box wholly in front of the eye covers its centre).
      // Only boxes a few pixels across: a smaller one may cover no pixel centre.
      bool in_front = true;
      glm::vec2 lo(1e9f), hi(-1e9f);
      for (int i = 0; i < 8; ++i) {
        const glm::vec4 c = view.view_proj * glm::vec4(b.corner(i), 1.0f);
        in_front = in_front && c.w > view.near;
        const glm::vec2 px = (glm::vec2(c) / c.w * 0.5f + 0.5f) * glm::vec2(160, 90);
        lo = glm::min(lo, px);
        hi = glm::max(hi, px);
      }
      const auto p = project(view.view_proj, b.center(), 160, 90);
      if (!in_front || !p || hi.x - lo.x < 4.0f || hi.y - lo.y < 4.0f) continue;
      const Rgb got = pixel(image, 160, p->first, p->second);
      EXPECT_TRUE(box_colour(got, palette::occluded))
          << "query " << q << " at " << p->first << "," << p->second << ": " << got.r << " " << got.g << " " << got.b
          << " box " << b.min.x << " " << b.min.y << " " << b.min.z << " .. " << b.max.x << " " << b.max.y << " "
          << b.max.z << " eye " << view.eye.x << " " << view.eye.y << " " << view.eye.z;
      ++checked;
    }
  }
  EXPECT_GT(checked, 0u) << "no occluded query box on screen: the test checks nothing";
}

TEST_F(DebugViewGl, GridAndTileCullersReportTheirRegions) {
  {
    Session session("city:blocks=4,traffic=40", test::small_target(160, 90));
    auto grid = session.make("grid", {});
    const CameraPath& path = session.path("");
    for (int i = 0; i < 3; ++i) (void)session.run_frame(*grid, session.view_at(path, i, 100), session.frame_time(path, i, 100));
    const auto regions = grid->regions();
    EXPECT_FALSE(regions.empty());
    EXPECT_TRUE(std::any_of(regions.begin(), regions.end(), [](const CullRegion& r) { return r.visible; }));
  }
  {
    Session session("tiles_city:far=300", test::small_target(160, 90));
    auto tiles = session.make("tiles", {});
    const CameraPath& path = session.path("");
    for (int i = 0; i < 3; ++i)
      (void)session.run_frame(*tiles, session.view_at(path, i, 100), session.frame_time(path, i, 100));
    const auto regions = tiles->regions();
    EXPECT_TRUE(std::any_of(regions.begin(), regions.end(), [](const CullRegion& r) { return r.visible; }));
    EXPECT_TRUE(std::any_of(regions.begin(), regions.end(), [](const CullRegion& r) { return !r.visible; }));
  }
}
