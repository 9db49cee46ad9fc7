// occull — reading and writing hardware profiles (JSON) and where they are cached.
#pragma once

#include "occull/cost_model.hpp"

#include <optional>
#include <string>
#include <string_view>

namespace occull {

/// JSON text of a profile (times in milliseconds).
[[nodiscard]] std::string profile_to_json(const HardwareProfile& profile);

/// Parses a profile. Throws InputError naming `source` and what is wrong
/// (not JSON, a missing or negative field) — never a partial profile.
[[nodiscard]] HardwareProfile profile_from_json(std::string_view text, std::string_view source);

/// The cache file for a renderer: $XDG_CACHE_HOME/occull/profile-<name>.json
/// (or ~/.cache/...), <name> derived from the renderer string.
[[nodiscard]] std::string default_profile_path(std::string_view renderer);

/// Reads a profile file; nullopt when it does not exist. Throws InputError
/// when it exists but is unreadable or corrupt.
[[nodiscard]] std::optional<HardwareProfile> load_profile(const std::string& path);

/// Writes a profile file, creating its folder. Atomic: the text goes to a
/// temporary file beside `path` that is then renamed over it, so a
/// concurrent reader sees the old file or the new one, never a part.
/// Throws InputError on failure (and leaves no temporary file).
void save_profile(const HardwareProfile& profile, const std::string& path);

}  // namespace occull
