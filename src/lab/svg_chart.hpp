// Internal: a small SVG line-chart writer for the benchmark report.
#pragma once

#include <string>
#include <vector>

namespace occull::detail {

struct Series {
  std::string name;
  std::vector<double> values;  ///< y per x = 0, 1, 2, ...
};

struct LineChart {
  std::string title;
  std::string x_label;  ///< with unit, e.g. "frame"
  std::string y_label;  ///< with unit, e.g. "frame time (ms)"
  std::vector<Series> series;
};

/// A standalone SVG document: axes with ticks and labels, one polyline per
/// series in distinct colours, a legend. Text is XML-escaped.
std::string render_svg(const LineChart& chart);

/// The colour of series i (distinct for the first 12).
std::string series_color(std::size_t i);

}  // namespace occull::detail
