// Recorded camera path files (--path file:F), and sampling what was read.
#include "fuzz_util.hpp"
#include "occull/view.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const occull::fuzz::TempFile file({data, size}, "path");
  occull::fuzz::accept_or_reject([&] {
    const occull::CameraPath path = occull::read_path_file(file.path());
    for (int k = 0; k <= 8; ++k) {
      const occull::CameraPose pose = path.sample(path.duration() * double(k) / 8.0);
      (void)occull::make_view(pose, occull::Lens{}, 64, 36);
    }
  });
  return 0;
}
