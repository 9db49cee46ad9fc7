// export_scene: an occull Scene as an OpenSceneGraph graph.
#include "occull/osg/scene_graph.hpp"

#include "occull/error.hpp"

#include <osg/BlendFunc>
#include <osg/Depth>
#include <osg/Geode>
#include <osg/Geometry>
#include <osg/Material>

#include <fmt/format.h>
#include <glm/gtc/type_ptr.hpp>

namespace osgOccull {
using namespace occull;
namespace {

::osg::Matrix to_osg(const glm::mat4& m) { return ::osg::Matrix(glm::value_ptr(m)); }

const char* occluder_name(OccluderClass c) {
  switch (c) {
    case OccluderClass::always: return "always";
    case OccluderClass::sometimes: return "sometimes";
    case OccluderClass::never: return "never";
  }
  return "sometimes";
}

::osg::ref_ptr<::osg::Geode> make_geode(const Mesh& mesh) {
  ::osg::ref_ptr<::osg::Vec3Array> positions = new ::osg::Vec3Array;
  ::osg::ref_ptr<::osg::Vec3Array> normals = new ::osg::Vec3Array;
  positions->reserve(mesh.positions.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    positions->push_back({mesh.positions[i].x, mesh.positions[i].y, mesh.positions[i].z});
    const glm::vec3 n = i < mesh.normals.size() ? mesh.normals[i] : glm::vec3(0, 1, 0);
    normals->push_back({n.x, n.y, n.z});
  }
  ::osg::ref_ptr<::osg::DrawElementsUInt> triangles =
      new ::osg::DrawElementsUInt(GL_TRIANGLES, mesh.indices.begin(), mesh.indices.end());
  ::osg::ref_ptr<::osg::Geometry> g = new ::osg::Geometry;
  g->setVertexArray(positions);
  g->setNormalArray(normals, ::osg::Array::BIND_PER_VERTEX);
  g->addPrimitiveSet(triangles);
  g->setUseDisplayList(false);
  g->setUseVertexBufferObjects(true);
  ::osg::ref_ptr<::osg::Geode> geode = new ::osg::Geode;
  geode->addDrawable(g);
  return geode;
}

::osg::ref_ptr<::osg::StateSet> make_state(const Material& m) {
  ::osg::ref_ptr<::osg::StateSet> s = new ::osg::StateSet;
  ::osg::ref_ptr<::osg::Material> mat = new ::osg::Material;
  const ::osg::Vec4 colour(m.color.r, m.color.g, m.color.b, m.translucent ? m.color.a : 1.0f);
  mat->setDiffuse(::osg::Material::FRONT_AND_BACK, colour);
  mat->setAmbient(::osg::Material::FRONT_AND_BACK, colour * 0.3f);
  s->setAttributeAndModes(mat);
  if (m.translucent) {
    s->setAttributeAndModes(new ::osg::BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA));
    s->setAttributeAndModes(new ::osg::Depth(::osg::Depth::LESS, 0.0, 1.0, false));
    s->setRenderingHint(::osg::StateSet::TRANSPARENT_BIN);
  } else {
    s->setMode(GL_CULL_FACE, ::osg::StateAttribute::ON);
  }
  return s;
}

}  // namespace

ExportedScene export_scene(const Scene& scene) {
  ExportedScene out;
  out.root = new ::osg::Group;
  out.root->setName(scene.name());
  std::vector<::osg::ref_ptr<::osg::Geode>> geodes(scene.meshes().size());
  std::vector<::osg::ref_ptr<::osg::StateSet>> states;
  for (const Material& m : scene.materials()) states.push_back(make_state(m));
  out.objects.resize(scene.objects().size());
  for (ObjectId id = 0; id < scene.objects().size(); ++id) {
    const Object& o = scene.object(id);
    if (o.removed) continue;
    const Mesh& mesh = scene.mesh(o.mesh);
    if (mesh.positions.empty() && o.triangles > 0)
      throw InputError(fmt::format("{}: mesh {} has no vertices (added as MeshInfo): it cannot be exported to OSG",
                                   scene.name(), o.mesh));
    if (!geodes[o.mesh]) geodes[o.mesh] = make_geode(mesh);
    ::osg::ref_ptr<::osg::MatrixTransform> t = new ::osg::MatrixTransform(to_osg(o.transform));
    t->setUserValue("occull.object", int(id));
    t->setUserValue("occull.occluder", std::string(occluder_name(o.occluder)));
    t->setStateSet(states[o.material].get());
    if (o.dynamic()) t->setDataVariance(::osg::Object::DYNAMIC);
    t->addChild(geodes[o.mesh]);
    out.root->addChild(t);
    out.objects[id] = t;
  }
  return out;
}

void update_exported(const Scene& scene, ExportedScene& exported) {
  for (ObjectId id : scene.dynamic_objects())
    if (id < exported.objects.size() && exported.objects[id]) exported.objects[id]->setMatrix(to_osg(scene.object(id).transform));
}

std::int64_t exported_object(const ::osg::NodePath& path) {
  for (auto it = path.rbegin(); it != path.rend(); ++it) {
    int id = -1;
    if ((*it)->getUserValue("occull.object", id)) return id;
  }
  return -1;
}

}  // namespace osgOccull
