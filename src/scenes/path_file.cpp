#include "occull/error.hpp"
#include "occull/input_limits.hpp"
#include "occull/view.hpp"

#include <fmt/format.h>
#include <glm/gtc/constants.hpp>

#include <cmath>
#include <fstream>
#include <sstream>

namespace occull {

CameraPath read_path_file(const std::string& file) {
  std::istringstream in(limits::read_file(file, limits::text_file_bytes, "a path file (occull::limits::text_file_bytes)"));
  std::vector<CameraPath::Key> keys;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    CameraPath::Key k;
    float yaw = 0, pitch = 0;
    if (!(fields >> k.time >> k.pose.position.x >> k.pose.position.y >> k.pose.position.z >> yaw >> pitch))
      throw InputError(fmt::format("{}:{}: expected \"time x y z yaw pitch [cut]\", got \"{}\"", file, number, line));
    std::string extra;
    if (fields >> extra) {
      if (extra != "cut") throw InputError(fmt::format("{}:{}: unexpected \"{}\" (only \"cut\" may follow)", file, number, extra));
      k.cut = true;
    }
    if (!std::isfinite(k.time) || !std::isfinite(k.pose.position.x) || !std::isfinite(k.pose.position.y) ||
        !std::isfinite(k.pose.position.z) || !std::isfinite(yaw) || !std::isfinite(pitch))
      throw InputError(fmt::format("{}:{}: numbers must be finite", file, number));
    if (std::abs(pitch) >= 89.9f) throw InputError(fmt::format("{}:{}: pitch {} must be within (-89.9, 89.9) degrees", file, number, pitch));
    if (!keys.empty() && k.time <= keys.back().time)
      throw InputError(fmt::format("{}:{}: time {} does not increase (previous {})", file, number, k.time, keys.back().time));
    k.pose.yaw = glm::radians(yaw);
    k.pose.pitch = glm::radians(pitch);
    keys.push_back(k);
  }
  if (keys.empty()) throw InputError(fmt::format("{}: no poses", file));
  const std::size_t slash = file.find_last_of('/');
  return CameraPath("file:" + file.substr(slash == std::string::npos ? 0 : slash + 1), "recorded path " + file,
                    std::move(keys));
}

void write_path_file(const CameraPath& path, const std::string& file) {
  std::ofstream out(file);
  out << "# occull camera path '" << path.name() << "': time x y z yaw pitch [cut]\n"
      << "# seconds, scene units, degrees (yaw about +Y, 0 looks down -Z; pitch up is positive)\n";
  for (const auto& k : path.keys())
    out << fmt::format("{:.4f} {:.4f} {:.4f} {:.4f} {:.3f} {:.3f}{}\n", k.time, k.pose.position.x, k.pose.position.y,
                       k.pose.position.z, glm::degrees(k.pose.yaw), glm::degrees(k.pose.pitch), k.cut ? " cut" : "");
  out.flush();
  if (!out) throw InputError(fmt::format("cannot write '{}'", file));
}

}  // namespace occull
