// Hardware profiles (NOHC's cost model, JSON).
#include "fuzz_util.hpp"
#include "occull/profile_io.hpp"

#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  occull::fuzz::accept_or_reject([&] {
    const occull::HardwareProfile profile =
        occull::profile_from_json(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
    (void)occull::profile_to_json(profile);
  });
  return 0;
}
