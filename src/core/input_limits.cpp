// Reading files within the caps of occull/input_limits.hpp.
#include "occull/input_limits.hpp"

#include "occull/error.hpp"
#include "core/format.hpp"

#include <filesystem>
#include <fstream>

namespace occull::limits {

void check_viewport(int width, int height, std::string_view what) {
  if (width < 1 || height < 1 || width > viewport_side || height > viewport_side)
    throw InputError(
        detail::format("{} {}x{}: each side must be in [1, {}] pixels", what, width, height, viewport_side));
}

void check_file_size(const std::string& path, std::uint64_t limit, std::string_view what) {
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > limit)
    throw InputError(detail::format("{}: {} bytes is past the limit of {} bytes for {}", path, size, limit, what));
}

std::string read_file(const std::string& path, std::uint64_t limit, std::string_view what) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(detail::format("{}: is a folder, not a file", path));
  check_file_size(path, limit, what);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(detail::format("{}: cannot be opened", path));
  // Read in pieces, checking as it goes: a pipe has no size to ask for first,
  // and a file may grow while it is read.
  std::string out;
  char piece[1 << 16];
  while (in) {
    in.read(piece, sizeof piece);
    const auto got = std::size_t(in.gcount());
    if (out.size() + got > limit)
      throw InputError(detail::format("{}: more than {} bytes, the limit for {}", path, limit, what));
    out.append(piece, got);
  }
  if (in.bad()) throw InputError(detail::format("{}: read error after {} bytes", path, out.size()));
  return out;
}

}  // namespace occull::limits
