// RecordingBackend: what a frame drew and queried, as the instrument reads it.
#include "occull/recording_backend.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <vector>

using namespace occull;

namespace {

std::vector<ObjectId> drawn(const RecordingBackend& r) { return {r.objects().begin(), r.objects().end()}; }

}  // namespace

TEST(RecordingBackend, RecordsDrawsInCallOrderAndEachQuerysBoxes) {
  const Scene scene = test::glass_scene();
  test::ScriptedBackend device;
  RecordingBackend rec(device, scene);
  rec.start_frame();
  const ObjectId a[] = {1, 0}, b[] = {2};
  rec.render(a);
  const Aabb boxes[] = {scene.object(1).bounds, scene.object(2).bounds};
  const QueryId q = rec.issue_query(boxes);
  rec.render(b);
  (void)rec.result(q);
  EXPECT_EQ(drawn(rec), (std::vector<ObjectId>{1, 0, 2}));
  ASSERT_EQ(rec.query_sizes().size(), 1u);
  EXPECT_EQ(rec.query_sizes()[0], 2u);
  EXPECT_EQ(rec.query_boxes().size(), 2u);
  EXPECT_EQ(device.rendered, (std::vector<ObjectId>{1, 0, 2})) << "every call forwarded";
  rec.start_frame();
  EXPECT_TRUE(rec.objects().empty() && rec.query_boxes().empty()) << "a new frame's record starts empty";
}

// Opaque objects of a conditional draw count once their query is known to
// have passed samples: read through the recorder, or at the frame's end;
// translucent ones (drawn in any case) at once.
TEST(RecordingBackend, ConditionalDrawsCountOnlyWhereTheirQueryPassed) {
  const Scene scene = test::glass_scene();  // 0 and 2 translucent, 1 opaque
  test::ScriptedBackend device;
  device.conditional = true;
  device.visible_samples = [](std::span<const Aabb>) { return std::uint64_t(0); };  // every query: hidden
  RecordingBackend rec(device, scene);
  rec.start_frame();
  const Aabb box[] = {scene.object(1).bounds};
  const ObjectId all[] = {0, 1, 2};
  const QueryId read_now = rec.issue_query(box);
  rec.render_conditional(all, read_now, ConditionalWait::wait);
  EXPECT_EQ(drawn(rec), (std::vector<ObjectId>{0, 2})) << "translucent: drawn in any case";
  EXPECT_EQ(rec.result(read_now), 0u);
  EXPECT_EQ(drawn(rec), (std::vector<ObjectId>{0, 2})) << "its query passed nothing: 1 was skipped";

  const QueryId later = rec.issue_query(box);
  const ObjectId opaque[] = {1};
  rec.render_conditional(opaque, later, ConditionalWait::wait);
  std::vector<QueryId> asked;
  rec.finish_frame([&](QueryId q) {
    asked.push_back(q);
    return std::uint64_t(5);  // the device drew it
  });
  EXPECT_EQ(asked, (std::vector<QueryId>{later})) << "only the query still in flight is asked";
  EXPECT_EQ(drawn(rec), (std::vector<ObjectId>{0, 2, 1}));
  (void)rec.result(later);  // the culler still owns it
  EXPECT_EQ(drawn(rec), (std::vector<ObjectId>{0, 2, 1})) << "settled once";
}

TEST(RecordingBackend, StatsAreTheDevicesWithRecordingAsBackendTime) {
  const Scene scene = test::glass_scene();
  test::ScriptedBackend device;
  RecordingBackend rec(device, scene);
  const ObjectId a[] = {1};
  rec.render(a);
  EXPECT_EQ(rec.stats().draw_calls, device.stats().draw_calls);
  EXPECT_GE(rec.stats().backend_ms, device.stats().backend_ms);
}
