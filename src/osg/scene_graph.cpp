// export_scene: an occull Scene as an OpenSceneGraph graph.
#include "occull/osg/scene_graph.hpp"

#include "occull/error.hpp"
#include "gatherer.hpp"

#include <osg/BlendFunc>
#include <osg/Depth>
#include <osg/Geode>
#include <osg/Geometry>
#include <osg/Material>
#include <osg/TriangleFunctor>

#include <fmt/format.h>
#include <glm/gtc/type_ptr.hpp>

#include <map>
#include <tuple>
#include <unordered_map>

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

namespace {

// A drawable's triangles in its own coordinates, flat-shaded.
struct TriangleCopy {
  Mesh* mesh = nullptr;
  void operator()(const ::osg::Vec3& a, const ::osg::Vec3& b, const ::osg::Vec3& c) {
    const ::osg::Vec3 n0 = (b - a) ^ (c - a);
    const float length = n0.length();
    const ::osg::Vec3 n = length > 0.0f ? n0 / length : ::osg::Vec3(0, 1, 0);
    for (const ::osg::Vec3* v : {&a, &b, &c}) {
      mesh->indices.push_back(std::uint32_t(mesh->positions.size()));
      mesh->positions.push_back({v->x(), v->y(), v->z()});
      mesh->normals.push_back({n.x(), n.y(), n.z()});
    }
  }
};

glm::vec4 diffuse_of(const ::osg::StateSet* s) {
  if (s != nullptr)
    if (const auto* m = dynamic_cast<const ::osg::Material*>(s->getAttribute(::osg::StateAttribute::MATERIAL))) {
      const ::osg::Vec4 d = m->getDiffuse(::osg::Material::FRONT);
      return {d.r(), d.g(), d.b(), d.a()};
    }
  return {0.8f, 0.8f, 0.8f, 1.0f};
}

}  // namespace

ImportedGraph import_graph(::osg::Node& root, const std::string& name) {
  ImportedGraph out{SceneBundle{Scene(name), {}, Lens{}}, {}, &root};
  Scene& scene = out.bundle.scene;
  std::unordered_map<const ::osg::Drawable*, MeshId> meshes;
  detail::MergedStates merged;
  std::map<std::tuple<float, float, float, float, bool>, MaterialId> materials;
  auto found = [&](::osg::Drawable& drawable, const ::osg::NodePath& path, std::uint64_t, const ::osg::Matrix& to_root,
                   std::span<const ::osg::StateSet* const> states, std::uint64_t state_key) {
    auto [mesh_it, new_mesh] = meshes.try_emplace(&drawable, 0);
    if (new_mesh) {
      Mesh mesh;
      ::osg::TriangleFunctor<TriangleCopy> copy;
      copy.mesh = &mesh;
      drawable.accept(copy);
      mesh_it->second = scene.add_mesh(std::move(mesh));
    }
    const ::osg::ref_ptr<::osg::StateSet> state = merged.get(states, state_key);
    const bool translucent = detail::is_translucent(state.get());
    const glm::vec4 colour = diffuse_of(state.get());
    auto [m, new_material] = materials.try_emplace({colour.r, colour.g, colour.b, colour.a, translucent}, 0);
    if (new_material) m->second = scene.add_material({"", colour, translucent, 0});
    scene.add_object(mesh_it->second, m->second, glm::make_mat4(::osg::Matrixf(to_root).ptr()),
                     detail::occluder_of(path, translucent));
    out.instances.push_back(Instance{&drawable, path, to_root, state, translucent});
  };
  detail::Gatherer<decltype(found)> walk(found);
  root.accept(walk);
  if (scene.triangle_count() == 0) throw InputError(fmt::format("{}: has no triangles OpenSceneGraph can draw", name));
  add_model_views(out.bundle);
  return out;
}

ExportedScene flatten(std::span<const Instance> instances) {
  ExportedScene out;
  out.root = new ::osg::Group;
  for (std::size_t id = 0; id < instances.size(); ++id) {
    const Instance& i = instances[id];
    ::osg::ref_ptr<::osg::MatrixTransform> t = new ::osg::MatrixTransform(i.to_group);
    t->setUserValue("occull.object", int(id));
    t->setUserValue("occull.occluder", std::string(occluder_name(detail::occluder_of(i.path, i.translucent))));
    if (i.state) t->setStateSet(i.state.get());
    ::osg::ref_ptr<::osg::Geode> geode = new ::osg::Geode;
    geode->addDrawable(i.drawable.get());
    t->addChild(geode);
    out.root->addChild(t);
    out.objects.push_back(t);
  }
  return out;
}

std::int64_t exported_object(const ::osg::NodePath& path) {
  for (auto it = path.rbegin(); it != path.rend(); ++it) {
    int id = -1;
    if ((*it)->getUserValue("occull.object", id)) return id;
  }
  return -1;
}

}  // namespace osgOccull
