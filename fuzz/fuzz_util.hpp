// Shared by the fuzz targets (libFuzzer, make fuzz): every reader must
// either accept an input or reject it with InputError; any other exception,
// crash, sanitizer report, hang or runaway allocation is a finding.
#pragma once

#include "occull/error.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <span>
#include <string>
#include <unistd.h>

namespace occull::fuzz {

/// The input as a file, for readers that take a path: /tmp/occull-fuzz-PID.EXT,
/// removed when this goes.
class TempFile {
 public:
  TempFile(std::span<const std::uint8_t> data, const std::string& extension)
      : path_("/tmp/occull-fuzz-" + std::to_string(::getpid()) + "." + extension) {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size()));
  }
  ~TempFile() { std::remove(path_.c_str()); }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  [[nodiscard]] const std::string& path() const noexcept { return path_; }

 private:
  std::string path_;
};

/// Runs `read`; a rejection (InputError) is a valid outcome, and its message
/// must say something.
template <class F>
void accept_or_reject(F&& read) {
  try {
    read();
  } catch (const InputError& e) {
    if (e.what()[0] == '\0') __builtin_trap();  // a rejection must say why
  }
}

}  // namespace occull::fuzz
