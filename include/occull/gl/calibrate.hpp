// occull — startup calibration of the NOHC hardware cost model on the
// current OpenGL renderer (Guthe et al. 2006, Section 3.2.2).
#pragma once

#include "occull/cost_model.hpp"

#include <functional>
#include <string>
#include <vector>

namespace occull::gl {

struct CalibrationOptions {
  int width = 1280;       ///< render-target size, pixels
  int height = 720;
  int repeats = 5;        ///< each measurement is repeated; the median is kept
  std::vector<int> shading_classes{0, 4, 16, 64};  ///< material shading costs to time T_r^f for
};

/// One calibrated quantity with its spread over the repeats.
struct CalibratedValue {
  std::string name;     ///< e.g. "T_r^s"
  std::string meaning;
  double value_ms = 0.0;
  double spread = 0.0;  ///< (max - min) / median over the repeats; 0 when all agree
};

struct CalibrationResult {
  HardwareProfile profile;
  std::vector<CalibratedValue> values;  ///< every quantity, for printing
  double seconds = 0.0;                 ///< wall time the calibration took
};

/// Measures the characteristic times with the paper's method: a low- (2
/// triangles) and a high-triangle mesh (about 100k) drawn pixel-sized for
/// the per-draw and per-triangle times, the low one full-screen (with depth
/// always passing) for the per-fragment time of each shading class, and
/// pixel-sized and full-screen query boxes for the query times; the query
/// latency is the longest wait from issue to result, and the overhead of a
/// query issued while rendering is the difference of drawing with and
/// without interleaved queries. Wall-clock time with glFinish around each
/// measured batch, an empty frame subtracted. Precondition: a gl::Context is
/// current. `progress` (optional) gets a line per measurement.
CalibrationResult calibrate(const CalibrationOptions& options = {},
                            const std::function<void(const std::string&)>& progress = {});

/// One sanity check of calibrations (occull calibrate --check).
struct CalibrationCheck {
  std::string name;    ///< what is checked
  bool ok = false;
  std::string detail;  ///< the figures behind the verdict
};

/// Sanity checks of two calibrations of the same renderer, in order: every
/// time finite and >= 0; a triangle cheaper than a draw call; fragment
/// times not decreasing with shading cost (and the costliest class above
/// the cheapest); a measured query latency; then, per quantity, the two
/// runs within a factor of 2 of each other. Timings on a shared machine
/// are noisy: this is a report for people, never a test. Pure function.
[[nodiscard]] std::vector<CalibrationCheck> check_calibrations(const CalibrationResult& first,
                                                               const CalibrationResult& second);

}  // namespace occull::gl
