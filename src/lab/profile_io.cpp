#include "occull/profile_io.hpp"

#include "occull/error.hpp"
#include "occull/input_limits.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <unistd.h>

namespace occull {
namespace {

using nlohmann::json;

const char* const kTimes[] = {"draw_setup_ms",  "triangle_ms",      "query_setup_ms",
                              "query_fragment_ms", "query_latency_ms", "query_overhead_ms"};

double* time_field(HardwareProfile& p, std::string_view key) {
  if (key == "draw_setup_ms") return &p.draw_setup_ms;
  if (key == "triangle_ms") return &p.triangle_ms;
  if (key == "query_setup_ms") return &p.query_setup_ms;
  if (key == "query_fragment_ms") return &p.query_fragment_ms;
  if (key == "query_latency_ms") return &p.query_latency_ms;
  if (key == "query_overhead_ms") return &p.query_overhead_ms;
  return nullptr;
}

}  // namespace

std::string profile_to_json(const HardwareProfile& p) {
  json doc;
  doc["format"] = "occull hardware profile 1";
  doc["renderer"] = p.renderer;
  doc["size"] = {p.width, p.height};
  HardwareProfile copy = p;
  for (const char* key : kTimes) doc[key] = *time_field(copy, key);
  json frag = json::object();
  for (const auto& [cost, ms] : p.fragment_ms) frag[std::to_string(cost)] = ms;
  doc["fragment_ms"] = frag;
  return doc.dump(2) + "\n";
}

HardwareProfile profile_from_json(std::string_view text, std::string_view source) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {  // a syntax error, or a number out of range (fuzz_profile)
    throw InputError(fmt::format("{}: not a JSON hardware profile ({})", source, e.what()));
  }
  const auto fail = [&](const std::string& what) {
    return InputError(fmt::format("{}: bad hardware profile: {}", source, what));
  };
  if (!doc.is_object()) throw fail("the top level is not an object");
  HardwareProfile p;
  if (!doc.contains("renderer") || !doc["renderer"].is_string()) throw fail("no \"renderer\" string");
  p.renderer = doc["renderer"].get<std::string>();
  if (!doc.contains("size") || !doc["size"].is_array() || doc["size"].size() != 2 ||
      !doc["size"][0].is_number_integer() || !doc["size"][1].is_number_integer())
    throw fail("\"size\" is not [width, height]");
  const auto w = doc["size"][0].get<std::int64_t>(), h = doc["size"][1].get<std::int64_t>();
  if (w < 1 || h < 1 || w > limits::viewport_side || h > limits::viewport_side)
    throw fail(fmt::format("\"size\" must be in [1, {}] pixels per side", limits::viewport_side));
  p.width = int(w);
  p.height = int(h);
  for (const char* key : kTimes) {
    if (!doc.contains(key) || !doc[key].is_number()) throw fail(fmt::format("no number \"{}\"", key));
    const double v = doc[key].get<double>();
    if (!(v >= 0.0) || !std::isfinite(v)) throw fail(fmt::format("\"{}\" must be a finite time >= 0", key));
    *time_field(p, key) = v;
  }
  if (!doc.contains("fragment_ms") || !doc["fragment_ms"].is_object() || doc["fragment_ms"].empty())
    throw fail("no \"fragment_ms\" object with at least one shading class");
  for (const auto& [cost, ms] : doc["fragment_ms"].items()) {
    int c = 0;
    try {
      std::size_t used = 0;
      c = std::stoi(cost, &used);
      if (used != cost.size() || c < 0) throw std::invalid_argument(cost);
    } catch (const std::exception&) {
      throw fail(fmt::format("shading class \"{}\" is not a whole number >= 0", cost));
    }
    if (!ms.is_number() || !(ms.get<double>() >= 0.0))
      throw fail(fmt::format("fragment time of class {} must be a time >= 0", c));
    p.fragment_ms[c] = ms.get<double>();
  }
  return p;
}

std::string default_profile_path(std::string_view renderer) {
  namespace fs = std::filesystem;
  fs::path base;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    base = xdg;
  else if (const char* home = std::getenv("HOME"); home && *home)
    base = fs::path(home) / ".cache";
  else
    base = fs::temp_directory_path();
  std::string name;
  for (char c : renderer) {
    const bool keep = std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-';
    if (keep) name += char(std::tolower(static_cast<unsigned char>(c)));
    else if (!name.empty() && name.back() != '_') name += '_';
  }
  while (!name.empty() && name.back() == '_') name.pop_back();
  if (name.size() > 120) name.resize(120);
  return (base / "occull" / ("profile-" + (name.empty() ? std::string("unknown") : name) + ".json")).string();
}

std::optional<HardwareProfile> load_profile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return std::nullopt;
  return profile_from_json(
      limits::read_file(path, limits::text_file_bytes, "a hardware profile (occull::limits::text_file_bytes)"), path);
}

void save_profile(const HardwareProfile& profile, const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path target(path);
  const fs::path dir = target.parent_path();
  if (!dir.empty()) fs::create_directories(dir, ec);
  if (ec) throw InputError(fmt::format("cannot create '{}': {}", dir.string(), ec.message()));
  // Written beside the target, then renamed over it: a reader (another
  // process calibrating the same renderer) sees the old file or the new
  // one, never half of one.
  fs::path temp = target;
  temp += fmt::format(".tmp-{}-{:x}", ::getpid(), std::random_device{}());
  {
    std::ofstream f(temp, std::ios::binary);
    f << profile_to_json(profile);
    f.flush();
    if (!f) {
      fs::remove(temp, ec);
      throw InputError(fmt::format("cannot write '{}'", temp.string()));
    }
  }
  fs::rename(temp, target, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw InputError(fmt::format("cannot write '{}': {}", path, ec.message()));
  }
}

}  // namespace occull
