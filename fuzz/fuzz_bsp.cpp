// IBSP (Quake 3 level) reader and the scene built from it.
#include "fuzz_util.hpp"
#include "occull/q3bsp.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  occull::fuzz::accept_or_reject([&] {
    const occull::q3::Map map =
        occull::q3::read_bsp(std::span(reinterpret_cast<const std::byte*>(data), size), "fuzz.bsp");
    occull::q3::LoadOptions options;
    options.patch_level = 2;  // patches: every path, fewer triangles
    (void)occull::q3::build_scene(map, "fuzz", options);
  });
  return 0;
}
