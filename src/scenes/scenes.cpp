// Registry of the embedded scenes and parsing of scene specs.
#include "occull/error.hpp"
#include "occull/input_limits.hpp"
#include "model_file.hpp"
#include "occull/q3bsp.hpp"
#include "scenes_internal.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>

namespace occull {
namespace {

struct Generator {
  SceneInfo info;
  SceneBundle (*make)(const scenes::Params&);
};

// Where a scene stands in the world: a parameter of every scene that is not
// a tiled world (those place their own tiles around the eye, 10 km and more
// from their origin already). make_scene applies it (SceneBundle::origin).
constexpr double kMaxOffset = 1e7;  // metres: 10,000 km
SceneInfo with_offset(SceneInfo info) {
  info.params.push_back({"offset", 0.0, -kMaxOffset, kMaxOffset, false,
                         "the scene and its paths placed this many metres along x and along z from the world's "
                         "origin (far from it, occull works relative to a floating origin near the camera: "
                         "docs/library.md)"});
  return info;
}

const std::vector<Generator>& generators() {
  static const std::vector<Generator> all = {
      {with_offset(scenes::city_info()), &scenes::make_city},
      {with_offset(scenes::field_info()), &scenes::make_field},
      {with_offset(scenes::track_info()), &scenes::make_track},
      {with_offset(scenes::adversarial_info()), &scenes::make_adversarial},
      {scenes::tiles_city_info(), &scenes::make_tiles_city},
      {scenes::tiles_forest_info(), &scenes::make_tiles_forest},
      {scenes::tiles_hybrid_info(), &scenes::make_tiles_hybrid},
  };
  return all;
}

std::string scene_names() {
  std::string names;
  for (const auto& g : generators()) names += (names.empty() ? "" : ", ") + g.info.name;
  return names;
}

std::string param_names(const SceneInfo& info) {
  std::string names;
  for (const auto& p : info.params) names += (names.empty() ? "" : ", ") + p.key;
  return names;
}

double parse_number(std::string_view text, const SceneInfo& info, const SceneParamInfo& p) {
  if (!p.choices.empty()) {
    std::string names;
    for (std::size_t i = 0; i < p.choices.size(); ++i) {
      if (p.choices[i] == text) return double(i);
      names += (names.empty() ? "" : ", ") + p.choices[i];
    }
    throw InputError(fmt::format("scene {}: parameter {}: unknown value '{}'; valid values: {}", info.name,
                                 p.key, text, names));
  }
  double v = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v))
    throw InputError(fmt::format("scene {}: parameter {}: '{}' is not a number", info.name, p.key, text));
  if (p.integer && v != std::floor(v))
    throw InputError(fmt::format("scene {}: parameter {}: '{}' is not a whole number", info.name,
                                 p.key, text));
  if (v < p.min || v > p.max)
    throw InputError(fmt::format("scene {}: parameter {}: {} is outside [{}, {}]", info.name, p.key,
                                 text, p.min, p.max));
  return v;
}

}  // namespace

std::span<const SceneInfo> embedded_scenes() {
  static const std::vector<SceneInfo> infos = [] {
    std::vector<SceneInfo> v;
    for (const auto& g : generators()) v.push_back(g.info);
    return v;
  }();
  return infos;
}

const CameraPath& SceneBundle::path(std::string_view name) const {
  std::string names;
  for (const auto& p : paths) {
    if (p.name() == name) return p;
    names += (names.empty() ? "" : ", ") + p.name();
  }
  throw InputError(fmt::format("unknown path '{}' for scene {}; valid paths: {}", name, scene.name(), names));
}

namespace scenes {

ParsedSpec parse_spec(std::string_view spec) {
  const auto colon = spec.find(':');
  const std::string_view name = spec.substr(0, colon);
  const Generator* gen = nullptr;
  for (const auto& g : generators())
    if (g.info.name == name) gen = &g;
  if (!gen)
    throw InputError(fmt::format("unknown scene '{}'; valid scenes: {} (or q3:FILE.pk3:MAP, q3:FILE.bsp, "
                                 "file:MODEL)",
                                 name, scene_names()));

  ParsedSpec parsed{&gen->info, {}, gen->make};
  Params& params = parsed.params;
  for (const auto& p : gen->info.params) params[p.key] = p.default_value;
  std::string_view rest = colon == std::string_view::npos ? std::string_view{} : spec.substr(colon + 1);
  while (!rest.empty()) {
    const auto comma = rest.find(',');
    const std::string_view item = rest.substr(0, comma);
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
    const auto eq = item.find('=');
    if (eq == std::string_view::npos)
      throw InputError(fmt::format("scene {}: '{}' is not key=value; parameters: {}", gen->info.name,
                                   item, param_names(gen->info)));
    const std::string_view key = item.substr(0, eq);
    const SceneParamInfo* info = nullptr;
    for (const auto& p : gen->info.params)
      if (p.key == key) info = &p;
    if (!info)
      throw InputError(fmt::format("scene {}: unknown parameter '{}'; valid parameters: {}",
                                   gen->info.name, key, param_names(gen->info)));
    params[info->key] = parse_number(item.substr(eq + 1), gen->info, *info);
  }
  return parsed;
}

}  // namespace scenes

SceneBundle make_scene(std::string_view spec) {
  if (spec.size() > limits::spec_chars)
    throw InputError(fmt::format("scene spec '{}...': {} characters is past the limit of {} "
                                 "(occull::limits::spec_chars)",
                                 spec.substr(0, 32), spec.size(), limits::spec_chars));
  if (spec.rfind("q3:", 0) == 0) return q3::load(spec.substr(3));
  if (spec.rfind("file:", 0) == 0) return scenes::load_model_file(std::string(spec.substr(5)));
  const scenes::ParsedSpec parsed = scenes::parse_spec(spec);
  SceneBundle bundle = parsed.make(parsed.params);
  if (const auto offset = parsed.params.find("offset"); offset != parsed.params.end())
    bundle.origin = glm::dvec3(offset->second, 0.0, offset->second);
  return bundle;
}

}  // namespace occull
