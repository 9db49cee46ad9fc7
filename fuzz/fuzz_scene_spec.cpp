// Scene spec strings of the embedded scenes, "name[:key=value,...]" (parsed,
// not built: a valid spec may ask for a scene of minutes; q3: and file:
// specs are the other targets).
#include "fuzz_util.hpp"
#include "scenes/scenes_internal.hpp"

#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view spec(reinterpret_cast<const char*>(data), size);
  if (spec.rfind("q3:", 0) == 0 || spec.rfind("file:", 0) == 0) return 0;
  occull::fuzz::accept_or_reject([&] { (void)occull::scenes::parse_spec(spec); });
  return 0;
}
