// Builds a scene, its BVH and a vfc culler through the installed headers.
#include <occull/bvh.hpp>
#include <occull/culler.hpp>
#include <occull/gl/renderer.hpp>
#include <occull/scenes.hpp>

#include <cstdio>

int main() {
  const occull::SceneBundle bundle = occull::make_scene("city:blocks=3,traffic=0");
  const occull::Bvh bvh = occull::Bvh::build(bundle.scene);
  auto culler = occull::make_culler("vfc", {bundle.scene, bvh});
  std::printf("consumer: %zu objects, %zu nodes\n", bundle.scene.objects().size(), bvh.size());
  return culler ? 0 : 1;
}
