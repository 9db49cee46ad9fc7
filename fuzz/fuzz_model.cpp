// Model files through assimp (--scene file:MODEL): the first byte picks the
// file name's extension (assimp chooses its importer by it), the rest is the file.
//
// assimp runs in a child process (run_in_child), as in the product, so what
// this fuzzes is occull's handling around it: the checks before assimp, the
// child's limits and the way back. A hang, crash or runaway allocation
// inside assimp ends the child and is an InputError here, not a finding;
// the limits are small so that such an input costs seconds, under
// fuzz.sh's 10 s timeout. Coverage inside the child is not seen by
// libFuzzer.
#include "fuzz_util.hpp"
#include "scenes/model_file.hpp"

#include <array>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static constexpr std::array<const char*, 5> kExtensions = {"obj", "ply", "stl", "off", "gltf"};
  static const occull::ChildLimits kLimits{2, 5.0, std::uint64_t(512) << 20};
  const occull::fuzz::TempFile file({data + 1, size - 1}, kExtensions[data[0] % kExtensions.size()]);
  occull::fuzz::accept_or_reject([&] { (void)occull::scenes::load_model_file(file.path(), 200, kLimits); });
  return 0;
}
