// An occull scene as an OpenSceneGraph graph: what `occull osg` flies, and
// what `occull osg --export FILE` writes for OSG's own tools (osgviewer).
#pragma once

#include "occull/scene.hpp"

#include <osg/Group>
#include <osg/MatrixTransform>

#include <cstdint>
#include <vector>

namespace osgOccull {

/// The exported graph and, per object id, its transform node.
struct ExportedScene {
  ::osg::ref_ptr<::osg::Group> root;
  std::vector<::osg::ref_ptr<::osg::MatrixTransform>> objects;  ///< by ObjectId; null for removed objects
};

/// Exports `scene` (its meshes need vertices: occull::Scene::add_mesh(Mesh)): one
/// MatrixTransform per object, with user values "occull.object" (its id) and
/// "occull.occluder" (always | sometimes | never, which OcclusionCullingGroup
/// reads), over one Geode per mesh shared by every object of that mesh
/// (OSG's instancing: shared geometry stays shared), vertex buffer objects;
/// one StateSet per material: its colour as an osg::Material (lit by the
/// viewer's head light), translucent ones blended in the transparent bin
/// without depth writes. Throws occull::InputError for a mesh without vertices.
[[nodiscard]] ExportedScene export_scene(const occull::Scene& scene);

/// Moves the exported objects to where `scene`'s objects are now (after
/// occull::Scene::update moved the dynamic ones, or an engine's set_transform).
void update_exported(const occull::Scene& scene, ExportedScene& exported);

/// The "occull.object" id on the nearest node of `path` that carries one,
/// or -1: which object of an exported scene a drawable instance is.
[[nodiscard]] std::int64_t exported_object(const ::osg::NodePath& path);

}  // namespace osgOccull
