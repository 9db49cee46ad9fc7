// A typed config's fields are checked by the compiler. Built as it is, this
// program makes a CHC++ culler with batch 20 and exits 0; built with
// OCCULL_MISSPELT (the test TypedConfig.AMisspeltFieldDoesNotCompile) it
// names a field that does not exist, and must not compile.
#include <occull/bvh.hpp>
#include <occull/configs.hpp>
#include <occull/culler.hpp>

int main() {
  occull::Scene scene("spelling");
  const occull::Bvh bvh = occull::Bvh::build(scene);
#ifdef OCCULL_MISSPELT
  const occull::ChcppConfig config{.bach = 20};
#else
  const occull::ChcppConfig config{.batch = 20};
#endif
  return occull::make_culler(config, {scene, bvh}) ? 0 : 1;
}
