// Internal: pieces the bench report and the suite report share — the JSON
// document of one bench result (write_json writes it; suite reports embed
// it) and writing one file of a report folder.
#pragma once

#include "occull/lab.hpp"

#include <nlohmann/json.hpp>

namespace occull::detail {

[[nodiscard]] nlohmann::ordered_json bench_json(const BenchResult& result);

/// A ratio with two decimals, or "-" when it is 0 (its baseline did not run).
[[nodiscard]] std::string ratio_text(double ratio);

/// Writes `text` to dir/name and returns that path. Throws InputError when it cannot.
std::string write_report_file(const std::string& dir, const std::string& name, const std::string& text);

}  // namespace occull::detail
