// occull — bench suites: fixed lists of scene/path pairs run with the same
// settings, summarised per culler over all of them (geometric mean and
// worst ratio to vfc and to the oracle).
#pragma once

#include "occull/lab.hpp"

#include <iosfwd>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace occull {

struct SuiteEntry {
  std::string scene;  ///< scene spec (make_scene)
  std::string path;   ///< camera path of that scene
  /// A file the scene reads (an OpenArena archive), relative to the working
  /// directory; empty for embedded scenes. Entries whose file is missing
  /// are skipped and named (make data fetches the maps).
  std::string needs_file;
};

struct Suite {
  std::string name;
  std::string description;
  std::vector<SuiteEntry> entries;
};

/// Every suite, `default` first.
[[nodiscard]] std::span<const Suite> suites();
/// The named suite. Throws InputError listing the valid names.
[[nodiscard]] const Suite& find_suite(std::string_view name);

/// One culler over every scene of a suite run.
struct SuiteRow {
  std::string algorithm;
  int scenes = 0;                     ///< entries it ran in
  double geomean_to_vfc = 0.0;        ///< geometric mean of its mean-frame-time ratio to vfc (0: no vfc)
  double worst_to_vfc = 0.0;          ///< largest such ratio
  std::string worst_to_vfc_entry;     ///< "scene / path" of that ratio
  double geomean_to_oracle = 0.0;
  double worst_to_oracle = 0.0;
  std::uint64_t missed_objects = 0;   ///< summed over entries (verified runs)
  bool conservative = true;
};

/// Per culler, in the order of the first result's summaries.
[[nodiscard]] std::vector<SuiteRow> summarize_suite(std::span<const BenchResult> results);

/// The summary table (one row per culler) with the entries listed above it.
void print_suite_summary(const Suite& suite, std::span<const BenchResult> results,
                         std::span<const std::string> skipped, std::ostream& out);

/// {"suite", "skipped": [...], "summary": [{"algorithm", "scenes", "geomean_to_vfc", "worst_to_vfc",
/// "worst_to_vfc_entry", "geomean_to_oracle", "worst_to_oracle", "missed_objects", "conservative"}],
/// "runs": [<write_json document of each entry>]}
void write_suite_json(const Suite& suite, std::span<const BenchResult> results,
                      std::span<const std::string> skipped, std::ostream& out);

/// suite.md (summary and one table per entry), suite.json, and
/// ratio_to_vfc.svg / ratio_to_oracle.svg (one line per culler over the
/// entries) into `dir`. Returns the files written. Throws InputError when
/// the folder cannot be written.
std::vector<std::string> write_suite_report(const Suite& suite, std::span<const BenchResult> results,
                                            std::span<const std::string> skipped, const std::string& dir);

}  // namespace occull
