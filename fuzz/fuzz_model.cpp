// Model files through assimp (--scene file:MODEL): the first byte picks the
// file name's extension (assimp chooses its importer by it), the rest is the file.
#include "fuzz_util.hpp"
#include "scenes/model_file.hpp"

#include <array>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static constexpr std::array<const char*, 5> kExtensions = {"obj", "ply", "stl", "off", "gltf"};
  const occull::fuzz::TempFile file({data + 1, size - 1}, kExtensions[data[0] % kExtensions.size()]);
  occull::fuzz::accept_or_reject([&] { (void)occull::scenes::load_model_file(file.path(), 200); });
  return 0;
}
