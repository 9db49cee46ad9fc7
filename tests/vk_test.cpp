// The Vulkan renderer (occull::vk) on lavapipe, with the Khronos validation
// layer on in every test (and any error it reports fails the test): the
// same visible sets as the OpenGL renderer, conservative cullers that miss
// nothing through it, and the cost of reading results mid-frame counted.
#include "occull/bvh.hpp"
#include "occull/culler.hpp"
#include "occull/error.hpp"
#include "occull/gl/context.hpp"
#include "occull/gl/renderer.hpp"
#include "occull/scenes.hpp"
#include "occull/vk/context.hpp"
#include "occull/vk/renderer.hpp"
#include "occull/lab.hpp"

#include "conservative_walk.hpp"
#include "gl_test_util.hpp"
#include "require_data.hpp"
#include "vk/vk.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>

namespace occull {
namespace {

constexpr int kWidth = 160, kHeight = 90;

// One context for the whole process, never destroyed (reachable from here,
// so not a leak): the Vulkan loader unloads the driver and the validation
// layer with the last instance, and LeakSanitizer then reports blocks they
// left as leaks in an unknown module, which nothing can attribute or
// suppress. Kept, they stay loaded and their blocks stay reachable.
[[gnu::used]] const vk::Context* g_keeps_the_driver_loaded = []() -> const vk::Context* {
  vk::ContextOptions o;
  o.validation = true;
  try {
    return vk::Context::create(o).release();
  } catch (const VulkanUnavailable&) {
    return nullptr;  // each test then fails, saying why
  }
}();

// A validated Vulkan context for one test; fails the test on any error
// the layer reported over its life.
class VulkanTest : public ::testing::Test {
 protected:
  void SetUp() override {
    vk::ContextOptions o;
    o.validation = true;
    context = vk::Context::create(o);
  }
  void TearDown() override {
    EXPECT_EQ(context->validation_errors(), 0) << context->first_validation_error();
  }
  std::unique_ptr<vk::Context> context;
};

std::vector<ObjectId> all_objects(const Scene& scene) {
  std::vector<ObjectId> ids;
  for (ObjectId id = 0; id < scene.objects().size(); ++id)
    if (!scene.object(id).removed) ids.push_back(id);
  return ids;
}

std::vector<View> path_views(const SceneBundle& b, int frames) {
  std::vector<View> views;
  const CameraPath& path = b.paths.front();
  for (int k = 0; k < frames; ++k)
    views.push_back(make_view(path.sample(path.frame_time(k, frames)), b.lens, kWidth, kHeight));
  return views;
}

TEST_F(VulkanTest, ContextNamesItsDeviceAndFeatures) {
  const vk::DeviceInfo& info = context->info();
  EXPECT_FALSE(info.name.empty());
  EXPECT_FALSE(info.api_version.empty());
  EXPECT_TRUE(info.validation);
  std::printf("device: %s | Vulkan %s | %s | conditional rendering %d | timestamps %d bits\n", info.name.c_str(),
              info.api_version.c_str(), info.driver.c_str(), int(info.conditional_rendering), info.timestamp_bits);
}

// The check of every other test: the layer's reports are counted, and
// check() turns them into VulkanError. Broken on purpose: a buffer of size 0.
TEST_F(VulkanTest, ValidationErrorsAreCountedAndThrown) {
  const auto& h = context->handles();
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = 0;  // VUID-VkBufferCreateInfo-size-00912
  info.usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT;
  VkBuffer buffer = VK_NULL_HANDLE;
  const VkResult r = vkCreateBuffer(h.device, &info, nullptr, &buffer);
  if (r == VK_SUCCESS && buffer) vkDestroyBuffer(h.device, buffer, nullptr);
  EXPECT_GE(context->validation_errors(), 1);
  EXPECT_THROW(context->check("a buffer of size 0"), VulkanError);
  EXPECT_NO_THROW(context->check("nothing since"));
  // This test's error was expected: the fixture's check is for the others.
  context.reset();
  vk::ContextOptions o;
  o.validation = true;
  context = vk::Context::create(o);
}

// The same frames through OpenGL and Vulkan show the same objects, up to
// the rasterisers' tie-breaking at pixel edges: an object seen by one only
// covers at most a few pixels in the other's image.
TEST_F(VulkanTest, VisibleSetsEqualOpenGlsUpToPixelEdges) {
  for (const char* spec : {"city:blocks=4", "field", "adversarial"}) {
    SCOPED_TRACE(spec);
    const SceneBundle b = make_scene(spec);
    const auto ids = all_objects(b.scene);
    auto gl_context = gl::Context::create();
    gl::RendererOptions go;
    go.width = kWidth;
    go.height = kHeight;
    gl::Renderer glr(b.scene, go);
    vk::RendererOptions vo;
    vo.width = kWidth;
    vo.height = kHeight;
    vk::Renderer vkr(*context, b.scene, vo);
    std::size_t objects = 0, only_one = 0, pixels = 0, pixels_differ = 0;
    for (const View& view : path_views(b, 8)) {
      std::map<ObjectId, std::uint32_t> g, v;
      for (const auto& p : glr.visible_pixels(view, ids)) g[p.id] = p.pixels;
      for (const auto& p : vkr.visible_pixels(view, ids)) v[p.id] = p.pixels;
      ASSERT_FALSE(g.empty());
      std::set<ObjectId> both;
      for (const auto& [id, n] : g) both.insert(id);
      for (const auto& [id, n] : v) both.insert(id);
      for (ObjectId id : both) {
        const std::uint32_t a = g.count(id) ? g[id] : 0, c = v.count(id) ? v[id] : 0;
        ++objects;
        pixels += std::max(a, c);
        pixels_differ += a > c ? a - c : c - a;
        if ((a == 0) != (c == 0)) {
          ++only_one;
          EXPECT_LE(std::max(a, c), 4u) << "object " << id << ": " << a << " pixels in OpenGL, " << c << " in Vulkan";
        }
      }
    }
    std::printf("%s: %zu objects seen, %zu by one renderer only; %zu of %zu pixels differ\n", spec, objects, only_one,
                pixels_differ, pixels);
    EXPECT_LE(double(pixels_differ), 0.01 * double(pixels));
  }
}

// The conservative cullers that need no device culling (hiz is the GL
// renderer's: DeviceCulling is not in vk::Renderer yet), through Vulkan.
const char* const kConservative[] = {"stopwait", "chc", "chcpp", "chcpp:multiquery=off", "nohc", "soc",
                                     "auto:candidates=soc+nohc+chcpp:trial=1:period=2"};

Options fixed_profile() {
  Options o;
  o.set("nohc.profile", OCCULL_TEST_PROFILE);
  return o;
}

gl::ContextOptions validated() {
  gl::ContextOptions c;
  c.debug = true;  // Vulkan: the validation layer
  return c;
}


// Every conservative culler over every path of `spec` through Vulkan misses
// nothing, and where the walks hide much, culls; the validation layer reports nothing.
void expect_conservative_through_vulkan(const std::string& spec, const gl::RendererOptions& target,
                                        std::vector<std::string_view> unbounded = {"nohc", "auto"}) {
  Session session(spec, target, {}, validated(), Api::vulkan);
  ASSERT_EQ(session.api(), Api::vulkan);
  test::CullingTally tally;
  for (const CameraPath& path : session.bundle().paths)
    test::run_walk(session, path, 8, kConservative, fixed_profile(), tally, spec + "/" + path.name());
  tally.expect_culling(unbounded);
  EXPECT_NO_THROW(session.render_device().check("the walks"));
}

TEST(VulkanCulling, ConservativeCullersMissNothingOnTheCity) {
  expect_conservative_through_vulkan("city:blocks=4,traffic=40", test::small_target(192, 108));
}

TEST(VulkanCulling, ConservativeCullersMissNothingOnTheField) {
  expect_conservative_through_vulkan("field:objects=800,size=300", test::small_target(192, 108));
}

TEST(VulkanCulling, ConservativeCullersMissNothingOnEveryAdversarialKind) {
#ifdef OCCULL_TEST_SANITIZED
  const char* const kinds[] = {"tiny", "coplanar", "far"};
#else
  const char* const kinds[] = {"mixed", "tiny", "thin", "coplanar", "near", "far", "farout"};
#endif
  for (const char* kind : kinds)
    expect_conservative_through_vulkan(std::string("adversarial:kind=") + kind, test::small_target(320, 180),
                                       {"nohc", "auto", "chcpp"});  // as the GL suite (adversarial_test.cpp)
}

TEST(VulkanCulling, ConservativeCullersMissNothingOnOpenArenaMaps) {
  const std::string pk3 = std::string(OCCULL_DATA_DIR) + "/openarena/pak1-maps.pk3";
  OCCULL_REQUIRE_DATA(pk3);
  for (const char* map : {"oasago2", "wrackdm17"})
    expect_conservative_through_vulkan(std::string("q3:") + pk3 + ":" + map, test::small_target(192, 108));
}

// What the verifier would say of a culler that misses: the check can fail.
// Drawing nothing through Vulkan (none draws every object: `oracle` with an
// empty truth is not available, so a culler that culls everything is made
// by the session's fault hooks) is caught as misses.
TEST(VulkanCulling, ACullerThatDrawsTooLittleIsCaught) {
  Session session("city:blocks=4", test::small_target(192, 108), {}, validated(), Api::vulkan);
  const CameraPath& path = session.bundle().paths.front();
  const auto truth = session.ground_truth(path, 4);
  ASSERT_FALSE(truth.front().visible.empty());
  auto vfc = session.make("vfc", Options{});
  const AlgorithmRun full = session.run_path("vfc", *vfc, path, 4, &truth);
  session.release(*vfc);
  std::uint64_t missed = 0;
  for (const FrameStats& f : full.frames) missed += f.missed_objects;
  EXPECT_EQ(missed, 0u);
  // chc with a threshold no query passes: it draws nothing it queried.
  auto blind = session.make("chc:threshold=1000000", Options{});
  const AlgorithmRun run = session.run_path("chc", *blind, path, 4, &truth);
  session.release(*blind);
  missed = 0;
  for (const FrameStats& f : run.frames) missed += f.missed_objects;
  EXPECT_GT(missed, 0u);
}

// Reading a result in the frame that issued it costs a submission in
// Vulkan: CHC's in-frame reads are counted as flushes, and wait time.
TEST(VulkanCulling, MidFrameReadsAreCountedAsSubmissions) {
  Session session("city:blocks=4", test::small_target(192, 108), {}, validated(), Api::vulkan);
  const CameraPath& path = session.bundle().paths.front();
  auto chc = session.make("chc", Options{});
  const AlgorithmRun run = session.run_path("chc", *chc, path, 6, nullptr);
  session.release(*chc);
  double flushes = 0, queries = 0;
  for (const FrameStats& f : run.frames) flushes += f.flushes, queries += f.queries;
  EXPECT_GT(queries, 0.0);
  EXPECT_GT(flushes, 0.0);
  EXPECT_LE(flushes, queries);  // at most one submission per query read
}

// hiz culls on the device, which vk::Renderer does not offer yet: refused
// up front as bad input (exit 2), not in the middle of a run.
TEST(VulkanCulling, DeviceCullersAreRefusedUpFront) {
  Session session("city:blocks=3", test::small_target(192, 108), {}, validated(), Api::vulkan);
  EXPECT_THROW((void)session.make("hiz", Options{}), InputError);
  EXPECT_NO_THROW((void)session.make("chcpp", Options{}));
}

// chc:reads=earlier reads results of earlier frames only, as engines on
// explicit APIs do: no submission mid-frame, nothing waited for, and it is
// not conservative (what it draws late is counted as popping, not failure).
TEST(VulkanCulling, ChcReadingEarlierFramesSubmitsNothingMidFrame) {
  EXPECT_FALSE(is_conservative(parse_algorithm_spec("chc:reads=earlier")));
  EXPECT_TRUE(is_conservative(parse_algorithm_spec("chc:reads=frame")));
  Session session("city:blocks=4", test::small_target(192, 108), {}, validated(), Api::vulkan);
  EXPECT_EQ(session.backend().result_reads(), ResultReads::after_submit);
  EXPECT_THROW((void)session.make("chc:reads=earlier:cpu_test=on", Options{}), InputError);
  const CameraPath& path = session.bundle().paths.front();
  session.set_sampling({30.0, 0.0});
  const auto truth = session.ground_truth(path, 12);
  auto latent = session.make("chc:reads=earlier", Options{});
  const AlgorithmRun run = session.run_path("chc:reads=earlier", *latent, path, 12, &truth);
  EXPECT_GT(latent->queries_held(), 0u);  // the last frame's, for the next
  session.release(*latent);
  EXPECT_EQ(latent->queries_held(), 0u);
  session.check_queries_returned("chc:reads=earlier");
  std::uint64_t flushes = 0, queries = 0, waits = 0, drawn = 0, visible = 0, missed = 0;
  for (std::size_t k = 0; k < run.frames.size(); ++k) {
    const FrameStats& f = run.frames[k];
    flushes += f.flushes, queries += f.queries, waits += f.blocking_waits, drawn += f.objects_rendered;
    visible += truth[k].visible.size();
    if (k >= 2) missed += f.missed_objects;  // past its start (frame 0 knows nothing yet)
  }
  EXPECT_GT(queries, 0u);
  EXPECT_EQ(flushes, 0u);
  EXPECT_EQ(waits, 0u);
  EXPECT_LE(double(missed), 0.1 * double(visible));  // a frame late on the few that turn visible
  std::uint64_t vfc_drawn = 0;
  auto vfc = session.make("vfc", Options{});
  for (const FrameStats& f : session.run_path("vfc", *vfc, path, 12, nullptr).frames) vfc_drawn += f.objects_rendered;
  session.release(*vfc);
  EXPECT_LT(drawn, vfc_drawn);  // and it culls
}

}  // namespace
}  // namespace occull
