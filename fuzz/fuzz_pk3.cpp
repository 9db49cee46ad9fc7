// pk3 (zip) archives: listing their maps and reading each (then parsed as IBSP).
#include "fuzz_util.hpp"
#include "occull/q3bsp.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const occull::fuzz::TempFile file({data, size}, "pk3");
  occull::fuzz::accept_or_reject([&] {
    const std::vector<std::string> maps = occull::q3::list_maps(file.path());
    for (std::size_t i = 0; i < maps.size() && i < 4; ++i) {
      occull::fuzz::accept_or_reject([&] {
        const std::vector<std::byte> bsp = occull::q3::read_map_from_pk3(file.path(), maps[i]);
        (void)occull::q3::read_bsp(bsp, maps[i]);
      });
    }
    (void)occull::q3::read_map_from_pk3(file.path(), "fuzz");
  });
  return 0;
}
