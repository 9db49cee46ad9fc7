// occull — writing benchmark results: terminal table, JSON, CSV, and a
// report folder with Markdown and SVG charts.
#pragma once

#include "occull/lab.hpp"

#include <iosfwd>
#include <string>
#include <vector>

namespace occull {

/// The per-algorithm table: frame ms mean / median / p95 / max, ratio to
/// vfc and to oracle (mean), queries, state changes, draw calls and
/// triangles per frame, missed objects and wrong pixels; then the set-up.
void print_table(const BenchResult& result, std::ostream& out);

/// JSON document: {"device", "scene", "path", "frames", "size",
/// "algorithms": [...]} and more (see README, "JSON output"). Field names
/// are stable.
void write_json(const BenchResult& result, std::ostream& out);

/// CSV, one row per algorithm, repeat and frame, with a header row.
void write_csv(const BenchResult& result, std::ostream& out);

/// Creates `dir` (and parents) and checks that a file can be written in it.
/// Throws InputError naming the folder otherwise. Call it before a long run.
void prepare_report_folder(const std::string& dir);

/// Writes report.md (table and set-up), frame_ms.svg, queries.svg,
/// triangles.svg, results.json and frames.csv into `dir` (created if
/// missing). Returns the files written. Throws InputError when the folder
/// cannot be created or written.
std::vector<std::string> write_report(const BenchResult& result, const std::string& dir);

}  // namespace occull
