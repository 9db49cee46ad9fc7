// An occull scene as an OpenSceneGraph graph (what `occull osg` flies, and
// what `occull osg --export FILE` writes for OSG's own tools, osgviewer),
// and a graph read from a file as an occull scene (`occull osg --file`).
#pragma once

#include "occull/osg/culling_group.hpp"
#include "occull/scene.hpp"
#include "occull/scenes.hpp"

#include <osg/Group>
#include <osg/MatrixTransform>

#include <cstdint>
#include <span>
#include <string>
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
/// an animate() of the scripted ones, or an engine's set_transform).
void update_exported(const occull::Scene& scene, ExportedScene& exported);

/// A graph read from a file (`occull osg --file`) as an occull scene.
struct ImportedGraph {
  /// One object per drawable instance, in the order a walk meets them, its
  /// triangles copied (occull's renderer draws the ground truth from them);
  /// materials from the instance's osg::Material diffuse colour; lens and
  /// camera paths `orbit` and `through` (add_model_views).
  occull::SceneBundle bundle;
  /// Per object: the drawable as loaded, its transform to the graph's root,
  /// the state sets of its path merged.
  std::vector<Instance> instances;
  ::osg::ref_ptr<::osg::Node> root;  ///< the graph, kept: the instances' paths point into it
};

/// Reads `root`'s drawable instances (active children, as
/// OcclusionCullingGroup gathers them). Throws UnsupportedNode for a camera
/// or projection in the graph, occull::InputError (naming `name`) for a
/// graph without triangles.
[[nodiscard]] ImportedGraph import_graph(::osg::Node& root, const std::string& name);

/// The instances as a flat graph every row of `occull osg` can name its
/// objects in: one MatrixTransform per instance ("occull.object" = its id,
/// its merged state set) over its drawable as loaded (shared, not copied).
[[nodiscard]] ExportedScene flatten(std::span<const Instance> instances);

/// The "occull.object" id on the nearest node of `path` that carries one,
/// or -1: which object of an exported scene a drawable instance is.
[[nodiscard]] std::int64_t exported_object(const ::osg::NodePath& path);

}  // namespace osgOccull
