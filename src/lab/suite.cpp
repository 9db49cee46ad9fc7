#include "occull/suite.hpp"

#include "occull/error.hpp"
#include "occull/report.hpp"
#include "report_internal.hpp"
#include "svg_chart.hpp"

#include <fmt/format.h>

#include <cmath>
#include <ostream>
#include <sstream>

namespace occull {
namespace {

constexpr const char* kMaps = "data/openarena/pak1-maps.pk3";

std::string q3(const char* map) { return fmt::format("q3:{}:{}", kMaps, map); }

std::string entry_name(const BenchResult& r) { return r.scene + " / " + r.path; }

const AlgorithmSummary* find(const BenchResult& r, const std::string& name) {
  for (const AlgorithmSummary& a : r.summaries)
    if (a.name == name) return &a;
  return nullptr;
}

}  // namespace

std::span<const Suite> suites() {
  static const std::vector<Suite> all = {
      {"default",
       "where culling pays and where it does not: the city walked, flown over and turned in, a city five "
       "times as large, open fields, three OpenArena maps (oasago2, ctf_inyard, wrackdm17; after make data) and the race track of small "
       "meshes",
       {{"city", "street", ""},
        {"city", "flyover", ""},
        {"city", "turn", ""},
        {"city:blocks=20", "street", ""},
        {"field", "glide", ""},
        {"field", "overview", ""},
        {q3("oasago2"), "tour", kMaps},
        {q3("ctf_inyard"), "tour", kMaps},
        {q3("wrackdm17"), "tour", kMaps},
        {"track", "lap", ""}}},
      {"quick",
       "the default suite's kinds of scene at a size CI can run in seconds: a small city, a small field, a "
       "short track",
       {{"city:blocks=3,traffic=3", "street", ""},
        {"field:objects=400,size=200", "glide", ""},
        {"track:radius=120,trees=300", "lap", ""}}},
  };
  return all;
}

const Suite& find_suite(std::string_view name) {
  std::string names;
  for (const Suite& s : suites()) {
    if (s.name == name) return s;
    names += (names.empty() ? "" : ", ") + s.name;
  }
  throw InputError(fmt::format("unknown suite '{}'; valid suites: {}", name, names));
}

std::vector<SuiteRow> summarize_suite(std::span<const BenchResult> results) {
  std::vector<SuiteRow> rows;
  if (results.empty()) return rows;
  for (const AlgorithmSummary& first : results.front().summaries) {
    SuiteRow row;
    row.algorithm = first.name;
    row.conservative = first.conservative;
    double log_vfc = 0.0, log_oracle = 0.0;
    int n_vfc = 0, n_oracle = 0;
    for (const BenchResult& r : results) {
      const AlgorithmSummary* a = find(r, first.name);
      if (!a) continue;
      ++row.scenes;
      row.missed_objects += a->missed_objects;
      row.conservative = row.conservative && a->conservative;
      if (a->ratio_to_vfc > 0) {
        log_vfc += std::log(a->ratio_to_vfc);
        ++n_vfc;
        if (a->ratio_to_vfc > row.worst_to_vfc) {
          row.worst_to_vfc = a->ratio_to_vfc;
          row.worst_to_vfc_entry = entry_name(r);
        }
      }
      if (a->ratio_to_oracle > 0) {
        log_oracle += std::log(a->ratio_to_oracle);
        ++n_oracle;
        row.worst_to_oracle = std::max(row.worst_to_oracle, a->ratio_to_oracle);
      }
    }
    if (n_vfc > 0) row.geomean_to_vfc = std::exp(log_vfc / n_vfc);
    if (n_oracle > 0) row.geomean_to_oracle = std::exp(log_oracle / n_oracle);
    rows.push_back(row);
  }
  return rows;
}

void print_suite_summary(const Suite& suite, std::span<const BenchResult> results,
                         std::span<const std::string> skipped, std::ostream& out) {
  out << fmt::format("suite {} — {} of {} entries ran:", suite.name, results.size(), suite.entries.size());
  for (const BenchResult& r : results) out << "\n  " << entry_name(r);
  out << "\n";
  for (const std::string& s : skipped) out << "  skipped: " << s << "\n";
  const std::vector<SuiteRow> rows = summarize_suite(results);
  std::size_t w = 10;
  for (const SuiteRow& row : rows) w = std::max(w, row.algorithm.size());
  out << fmt::format("\n{:<{}} {:>6} {:>11} {:>9} {:>14} {:>9} {:>7}  {}\n", "algorithm", w, "scenes",
                     "geomean/vfc", "worst/vfc", "geomean/oracle", "worst/orc", "missed", "worst vs vfc in");
  for (const SuiteRow& row : rows)
    out << fmt::format("{:<{}} {:>6} {:>11} {:>9} {:>14} {:>9} {:>7}  {}\n", row.algorithm, w, row.scenes,
                       detail::ratio_text(row.geomean_to_vfc), detail::ratio_text(row.worst_to_vfc),
                       detail::ratio_text(row.geomean_to_oracle), detail::ratio_text(row.worst_to_oracle), row.missed_objects,
                       row.worst_to_vfc_entry.empty() ? "-" : row.worst_to_vfc_entry);
  out << "\nratios: each entry's mean frame time over vfc's / the oracle's in the same run; geomean: their "
         "geometric mean over the entries; worst: the largest. missed: visible objects culled, summed over "
         "the entries.\n";
}

void write_suite_json(const Suite& suite, std::span<const BenchResult> results,
                      std::span<const std::string> skipped, std::ostream& out) {
  using nlohmann::ordered_json;
  const auto ratio = [](double r) { return r > 0 ? ordered_json(r) : ordered_json(); };
  ordered_json doc;
  doc["suite"] = suite.name;
  doc["skipped"] = skipped;
  ordered_json summary = ordered_json::array();
  for (const SuiteRow& row : summarize_suite(results))
    summary.push_back({{"algorithm", row.algorithm},
                       {"scenes", row.scenes},
                       {"geomean_to_vfc", ratio(row.geomean_to_vfc)},
                       {"worst_to_vfc", ratio(row.worst_to_vfc)},
                       {"worst_to_vfc_entry", row.worst_to_vfc_entry},
                       {"geomean_to_oracle", ratio(row.geomean_to_oracle)},
                       {"worst_to_oracle", ratio(row.worst_to_oracle)},
                       {"missed_objects", row.missed_objects},
                       {"conservative", row.conservative}});
  doc["summary"] = summary;
  ordered_json runs = ordered_json::array();
  for (const BenchResult& r : results) runs.push_back(detail::bench_json(r));
  doc["runs"] = runs;
  out << doc.dump(2) << "\n";
}

std::vector<std::string> write_suite_report(const Suite& suite, std::span<const BenchResult> results,
                                            std::span<const std::string> skipped, const std::string& dir) {
  prepare_report_folder(dir);
  std::vector<std::string> written;
  const auto write = [&](const std::string& name, const std::string& text) {
    written.push_back(detail::write_report_file(dir, name, text));
  };
  const auto chart = [&](std::string title, std::string y_label, double AlgorithmSummary::*ratio) {
    detail::LineChart c;
    c.title = std::move(title);
    c.x_label = "suite entry (in the order of suite.md)";
    c.y_label = std::move(y_label);
    for (const SuiteRow& row : summarize_suite(results)) {
      detail::Series s{row.algorithm, {}};
      for (const BenchResult& r : results) {
        const AlgorithmSummary* a = find(r, row.algorithm);
        s.values.push_back(a ? a->*ratio : 0.0);
      }
      c.series.push_back(std::move(s));
    }
    return detail::render_svg(c);
  };
  write("ratio_to_vfc.svg", chart("Mean frame time over vfc's — suite " + suite.name, "ratio to vfc",
                                  &AlgorithmSummary::ratio_to_vfc));
  write("ratio_to_oracle.svg", chart("Mean frame time over the oracle's — suite " + suite.name,
                                     "ratio to oracle", &AlgorithmSummary::ratio_to_oracle));
  std::ostringstream json, summary;
  write_suite_json(suite, results, skipped, json);
  write("suite.json", json.str());
  print_suite_summary(suite, results, skipped, summary);
  std::string md = fmt::format("# occull suite `{}`\n\n{}\n\n## Summary\n\n```\n{}```\n\n", suite.name,
                               suite.description, summary.str());
  md += "![ratio to vfc per entry](ratio_to_vfc.svg)\n\n![ratio to the oracle per entry](ratio_to_oracle.svg)\n\n";
  for (std::size_t i = 0; i < results.size(); ++i) {
    std::ostringstream table;
    print_table(results[i], table);
    md += fmt::format("## {}. {}\n\n```\n{}```\n\n", i + 1, entry_name(results[i]), table.str());
  }
  write("suite.md", md);
  return written;
}

}  // namespace occull
