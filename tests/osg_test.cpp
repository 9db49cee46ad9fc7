// occull inside OpenSceneGraph: OcclusionCullingGroup in a real headless
// OSG viewer (llvmpipe), and `occull osg`'s rows against the ground truth.
#include "occull/osg/culling_group.hpp"
#include "occull/osg/osg_bench.hpp"
#include "occull/osg/scene_graph.hpp"

#include "occull/view.hpp"

#include <gtest/gtest.h>
#include <osg/ComputeBoundsVisitor>
#include <osg/Geode>
#include <osg/MatrixTransform>
#include <osg/Projection>
#include <osg/ShapeDrawable>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>

namespace {

using osgOccull::HeadlessViewer;
using osgOccull::OcclusionCullingGroup;

// A box drawable of the given size centred at `centre` (its own geometry).
osg::ref_ptr<osg::Geode> box(const osg::Vec3& centre, const osg::Vec3& size) {
  osg::ref_ptr<osg::Geode> g = new osg::Geode;
  g->addDrawable(new osg::ShapeDrawable(new osg::Box(centre, size.x(), size.y(), size.z())));
  return g;
}

// A camera at the origin looking down -Z, 60 degrees, 64 x 64 pixels.
occull::View camera_view() {
  const glm::mat4 proj = glm::perspective(glm::radians(60.0f), 1.0f, 0.1f, 100.0f);
  return occull::make_view(glm::mat4(1.0f), proj, 64, 64);
}

// The group's object for `drawable`'s first instance (or -1).
std::int64_t object_of(const OcclusionCullingGroup& group, const osg::Drawable* drawable) {
  const auto instances = group.instances();
  for (std::size_t i = 0; i < instances.size(); ++i)
    if (instances[i].drawable.get() == drawable) return std::int64_t(i);
  return -1;
}

bool drew(const OcclusionCullingGroup& group, const osg::Camera& camera, std::int64_t object) {
  const osgOccull::CameraFrame* f = group.last_frame(&camera);
  return f != nullptr && std::binary_search(f->drawn.begin(), f->drawn.end(), occull::ObjectId(object));
}

struct Walled {
  osg::ref_ptr<OcclusionCullingGroup> group = new OcclusionCullingGroup("stopwait");
  osg::ref_ptr<osg::Geode> wall = box({0, 0, -5}, {20, 20, 0.2f});
  osg::ref_ptr<osg::Geode> hidden = box({0, 0, -10}, {1, 1, 1});
  osg::ref_ptr<osg::MatrixTransform> mover = new osg::MatrixTransform;
  osg::ref_ptr<osg::Geode> shown = box({0, 0, 0}, {1, 1, 1});  // under `mover`, in front of the wall
  Walled() {
    mover->setMatrix(osg::Matrix::translate(1, 0, -3));
    mover->addChild(shown);
    group->addChild(wall);
    group->addChild(hidden);
    group->addChild(mover);
  }
};

TEST(OsgCullingGroup, ABoxBehindAWallIsNotDrawnAndAVisibleOneIs) {
  HeadlessViewer v(64, 64);
  Walled s;
  v.set_scene(s.group.get());
  v.frame(camera_view(), 0.0);
  const std::int64_t hidden = object_of(*s.group, s.hidden->getDrawable(0));
  const std::int64_t shown = object_of(*s.group, s.shown->getDrawable(0));
  ASSERT_GE(hidden, 0);
  ASSERT_GE(shown, 0);
  EXPECT_FALSE(drew(*s.group, v.camera(), hidden));
  EXPECT_TRUE(drew(*s.group, v.camera(), shown));
  EXPECT_TRUE(drew(*s.group, v.camera(), object_of(*s.group, s.wall->getDrawable(0))));
  // The same box with the wall gone is drawn: the query saw depth, not a rule.
  s.group->removeChild(s.wall);
  v.frame(camera_view(), 0.1);
  EXPECT_TRUE(drew(*s.group, v.camera(), hidden));
}

TEST(OsgCullingGroup, TheFrameTimeTheApplicationMeasuresReachesAnAdaptiveCuller) {
  // auto between vfc and chcpp; the application reports vfc's frames as
  // 100x chcpp's. Inside its draw callback chcpp's queries cost more than
  // vfc's three boxes, so only the reported times make it keep chcpp.
  HeadlessViewer v(64, 64);
  Walled s;
  occull::Options o;
  o.set("auto.candidates", "vfc+chcpp");
  s.group->set_algorithm("auto", o);
  v.set_scene(s.group.get());
  std::uint32_t choice = 0;
  for (int k = 0; k < 12; ++k) {
    v.frame(camera_view(), 0.1 * k);
    const osgOccull::CameraFrame* f = s.group->last_frame(&v.camera());
    ASSERT_NE(f, nullptr);
    for (const auto& [name, value] : f->counters)
      if (name == "auto_choice") choice = std::uint32_t(value);
    occull::FrameMeasure measured;
    measured.frame_ms = choice == 1 ? 100.0 : 1.0;
    s.group->frame_finished(&v.camera(), measured);
  }
  EXPECT_EQ(choice, 2u) << "auto keeps chcpp, the cheaper by the frame times reported";
}

TEST(OsgCullingGroup, OsgsOwnFrustumAndSmallFeatureCullingDoNotChangeWhatTheGroupDraws) {
  std::vector<occull::ObjectId> drawn[2];
  for (int k = 0; k < 2; ++k) {
    HeadlessViewer v(64, 64);
    v.camera().setCullingMode(k == 0 ? osg::CullSettings::NO_CULLING
                                     : osg::CullSettings::DEFAULT_CULLING | osg::CullSettings::SMALL_FEATURE_CULLING);
    v.camera().setSmallFeatureCullingPixelSize(k == 0 ? 0.0f : 1000.0f);  // would cull every box we have
    Walled s;
    v.set_scene(s.group.get());
    v.frame(camera_view(), 0.0);
    ASSERT_NE(s.group->last_frame(&v.camera()), nullptr);
    drawn[k] = s.group->last_frame(&v.camera())->drawn;
    EXPECT_FALSE(drew(*s.group, v.camera(), object_of(*s.group, s.hidden->getDrawable(0))));
  }
  EXPECT_EQ(drawn[0], drawn[1]);
  EXPECT_EQ(drawn[0].size(), 2u);  // the wall and the box in front of it
}

TEST(OsgCullingGroup, MovingATransformMovesTheObjectsBox) {
  HeadlessViewer v(64, 64);
  Walled s;
  v.set_scene(s.group.get());
  v.frame(camera_view(), 0.0);
  const auto id = occull::ObjectId(object_of(*s.group, s.shown->getDrawable(0)));
  EXPECT_NEAR(s.group->scene().object(id).bounds.center().x, 1.0f, 1e-4f);
  s.mover->setMatrix(osg::Matrix::translate(-2, 0.5, -3));
  v.frame(camera_view(), 0.1);
  const glm::vec3 c = s.group->scene().object(id).bounds.center();
  EXPECT_NEAR(c.x, -2.0f, 1e-4f);
  EXPECT_NEAR(c.y, 0.5f, 1e-4f);
  EXPECT_TRUE(drew(*s.group, v.camera(), id));
}

TEST(OsgCullingGroup, RemovingAChildRemovesItFromTheCuller) {
  HeadlessViewer v(64, 64);
  Walled s;
  v.set_scene(s.group.get());
  v.frame(camera_view(), 0.0);
  const auto id = occull::ObjectId(object_of(*s.group, s.shown->getDrawable(0)));
  ASSERT_TRUE(s.group->scene().alive(id));
  s.group->removeChild(s.mover);
  v.frame(camera_view(), 0.1);
  EXPECT_FALSE(s.group->scene().alive(id));
  EXPECT_FALSE(drew(*s.group, v.camera(), id));
  EXPECT_EQ(object_of(*s.group, s.shown->getDrawable(0)), -1);
}

TEST(OsgCullingGroup, NestedTransformsComposeAsOsgDoesAndSharedGeometryIsOneMesh) {
  HeadlessViewer v(64, 64);
  osg::ref_ptr<OcclusionCullingGroup> group = new OcclusionCullingGroup("chcpp");
  osg::ref_ptr<osg::Geode> shared = box({0, 0, 0}, {1, 2, 1});
  osg::ref_ptr<osg::MatrixTransform> outer = new osg::MatrixTransform(osg::Matrix::rotate(0.7, 0, 1, 0) *
                                                                       osg::Matrix::translate(0, 0, -8));
  osg::ref_ptr<osg::MatrixTransform> inner = new osg::MatrixTransform(osg::Matrix::scale(2, 1, 1) *
                                                                       osg::Matrix::translate(1.5, 0, 0));
  inner->addChild(shared);
  outer->addChild(inner);
  outer->addChild(shared);  // the same geode twice: two instances of one mesh
  group->addChild(outer);
  v.set_scene(group.get());
  v.frame(camera_view(), 0.0);
  ASSERT_EQ(group->instances().size(), 2u);
  ASSERT_EQ(group->scene().meshes().size(), 1u);             // one mesh for the shared drawable,
  EXPECT_TRUE(group->scene().mesh(0).positions.empty());       // its bounds only: no vertex was copied
  EXPECT_EQ(group->scene().object(0).triangles, 12u);
  EXPECT_EQ(group->scene().object(0).mesh, group->scene().object(1).mesh);
  for (occull::ObjectId id = 0; id < 2; ++id) {
    // OSG's own bounds of the instance, through the same node path.
    osg::ComputeBoundsVisitor cbv;
    osg::NodePath path = group->instances()[id].path;
    const osg::Matrix m = osg::computeLocalToWorld(path);
    cbv.pushMatrix(const_cast<osg::Matrix&>(m));
    group->instances()[id].drawable->accept(cbv);
    const osg::BoundingBox& want = cbv.getBoundingBox();
    const occull::Aabb got = group->scene().object(id).bounds;
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(got.min[a], want._min[a], 1e-3f) << "instance " << id << " axis " << a;
      EXPECT_NEAR(got.max[a], want._max[a], 1e-3f) << "instance " << id << " axis " << a;
    }
  }
}

TEST(OsgCullingGroup, ATypedConfigMakesTheCullersAndIsCheckedAtOnce) {
  osg::ref_ptr<OcclusionCullingGroup> made = new OcclusionCullingGroup(occull::ChcppConfig{.batch = 20});
  EXPECT_EQ(made->algorithm(), "chcpp");
  HeadlessViewer v(64, 64);
  Walled s;
  s.group->set_config(occull::StopWaitConfig{.common = {.virtual_leaf_triangles = 0}});
  v.set_scene(s.group.get());
  v.frame(camera_view(), 0.0);
  EXPECT_FALSE(drew(*s.group, v.camera(), object_of(*s.group, s.hidden->getDrawable(0))));
  EXPECT_TRUE(drew(*s.group, v.camera(), object_of(*s.group, s.shown->getDrawable(0))));
  EXPECT_THROW(s.group->set_config(occull::ChcppConfig{.batch = 0}), occull::InputError);  // outside [1, 100000]
  EXPECT_THROW(s.group->set_config(occull::HizConfig{}), occull::InputError);  // needs device culling
  EXPECT_EQ(s.group->algorithm(), "stopwait");  // neither was taken
}

TEST(OsgCullingGroup, ACameraOrProjectionBelowTheGroupIsRefused) {
  HeadlessViewer v(64, 64);
  osg::ref_ptr<OcclusionCullingGroup> group = new OcclusionCullingGroup("vfc");
  osg::ref_ptr<osg::Projection> hud = new osg::Projection;
  hud->setName("hud");
  hud->addChild(box({0, 0, -3}, {1, 1, 1}));
  group->addChild(hud);
  v.set_scene(group.get());
  try {
    v.frame(camera_view(), 0.0);
    FAIL() << "a projection below the group was culled";
  } catch (const osgOccull::UnsupportedNode& e) {
    EXPECT_NE(std::string(e.what()).find("osg::Projection ('hud'"), std::string::npos) << e.what();
  }
}

TEST(OsgCullingGroup, ThreadingModelsThatDrawWhileTheNextFrameIsCulledAreRefused) {
  for (auto model : {osgViewer::ViewerBase::DrawThreadPerContext,
                     osgViewer::ViewerBase::CullThreadPerCameraDrawThreadPerContext}) {
    osg::ref_ptr<osgViewer::Viewer> viewer = new osgViewer::Viewer;
    viewer->setThreadingModel(model);
    EXPECT_THROW(osgOccull::require_supported_threading(*viewer), osgOccull::UnsupportedThreading);
  }
  for (auto model : {osgViewer::ViewerBase::SingleThreaded, osgViewer::ViewerBase::CullDrawThreadPerContext}) {
    osg::ref_ptr<osgViewer::Viewer> viewer = new osgViewer::Viewer;
    viewer->setThreadingModel(model);
    EXPECT_NO_THROW(osgOccull::require_supported_threading(*viewer));
  }
  EXPECT_THROW(HeadlessViewer(64, 64, osgViewer::ViewerBase::DrawThreadPerContext).set_scene(new osg::Group),
               osgOccull::UnsupportedThreading);
}

TEST(OsgCullingGroup, AnUnknownAlgorithmIsRefusedListingTheValidOnes) {
  try {
    osg::ref_ptr<OcclusionCullingGroup> group = new OcclusionCullingGroup("chc++");
    FAIL() << "made a group with an unknown algorithm";
  } catch (const occull::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("chcpp"), std::string::npos) << e.what();
  }
}

TEST(OsgCullingGroup, ACullerThatNeedsDeviceCullingIsRefusedAtOnce) {
  try {
    osg::ref_ptr<OcclusionCullingGroup> group = new OcclusionCullingGroup("hiz:texels=4");
    FAIL() << "made a group with hiz over a backend without device culling";
  } catch (const occull::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("DeviceCulling"), std::string::npos) << e.what();
  }
}

// The exported city (shared meshes, one transform per object, moving cars)
// flown in OSG: occull's conservative rows miss nothing, and culled something.
TEST(OsgBench, OccullRowsInsideOsgMissNoVisibleObjectOverAPath) {
  osgOccull::OsgBenchConfig c;
  c.scene = "city:blocks=3";
  c.rows = {"osg", "oqn", "vfc", "chcpp", "stopwait", "auto"};
  c.frames = 24;
  c.warmup = 2;
  c.width = 160;
  c.height = 90;
  for (const std::string& threading : {"single", "cull-draw"}) {
    c.threading = threading;
    const occull::BenchResult r = osgOccull::run_osg_bench(c);
    ASSERT_EQ(r.summaries.size(), c.rows.size());
    const auto row = [&](const std::string& name) {
      return *std::find_if(r.summaries.begin(), r.summaries.end(), [&](const auto& s) { return s.name == name; });
    };
    for (const char* name : {"vfc", "chcpp", "stopwait", "auto"}) {
      EXPECT_TRUE(row(name).conservative) << name;
      EXPECT_EQ(row(name).missed_objects, 0u) << name << " (" << threading << "): " << row(name).first_miss;
    }
    EXPECT_FALSE(row("oqn").conservative);
    EXPECT_GT(row("vfc").truth_object_frames, 0u);
    EXPECT_LT(row("stopwait").objects_rendered_per_frame, row("vfc").objects_rendered_per_frame) << threading;
    EXPECT_GT(row("chcpp").queries_per_frame, 0.0);
    // auto reports what it ran; soc, with no vertex registered by the group, never runs.
    const auto& choices = row("auto").auto_choices;
    ASSERT_FALSE(choices.empty()) << threading;
    const auto soc = std::find_if(choices.begin(), choices.end(), [](const auto& c) { return c.first == "soc"; });
    ASSERT_NE(soc, choices.end());
    EXPECT_EQ(soc->second, 0.0) << threading;
  }
}

TEST(OsgBench, AnUnknownRowIsRefusedNamingTheOsgRowsAndTheAlgorithms) {
  osgOccull::OsgBenchConfig c;
  c.scene = "city:blocks=3";
  c.rows = {"osg", "occlusionquerynode"};
  c.frames = 2;
  try {
    (void)osgOccull::run_osg_bench(c);
    FAIL() << "ran an unknown row";
  } catch (const occull::InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("oqn-strict"), std::string::npos) << m;
    EXPECT_NE(m.find("chcpp"), std::string::npos) << m;
  }
}

}  // namespace
