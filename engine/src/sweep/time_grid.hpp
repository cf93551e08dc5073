// Internal to the engine: whether a sweep's time grid moves time at every step (run_sweep's check, and the scene
// loader's, which reports it at the scene's `time.end`).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "phiq/types.hpp"

namespace phiq::detail {

// Why `steps` steps from t_begin to t_end do not each move time, or "" when they do. The predictors and the
// warnings' rows divide by the spacing of the times: t_begin = t_end with steps > 0, a spacing below the rounding
// of the times (rows that coincide) or a span that overflows made NaN predictions, reported as a failed sweep
// ("starting point has non-finite coordinates", "t = -nan"). Steps of more than 8 ulps of the largest |t| keep the
// grid's times t_begin + k h (each within 1.5 ulps of its exact value, t_end exact) strictly ordered.
inline std::string time_grid_problem(double t_begin, double t_end, Index steps) {
  if (steps == 0) return "";
  if (t_end == t_begin) return "t_end equals t_begin but steps > 0";
  const double span = t_end - t_begin, h = span / static_cast<double>(steps);
  std::ostringstream m;
  m.precision(3);
  if (!std::isfinite(span)) {
    m << "the span from t = " << format_time(t_begin) << " to " << format_time(t_end) << " is not a finite number";
    return m.str();
  }
  const double rounding = 8.0 * std::numeric_limits<double>::epsilon() * std::max(std::fabs(t_begin), std::fabs(t_end));
  if (std::fabs(h) > rounding && std::isnormal(h)) return "";
  m << steps << " steps from t = " << format_time(t_begin) << " to " << format_time(t_end) << " are " << std::fabs(h)
    << " s each, below the rounding of the times (8 ulps: " << rounding << " s): they would not move time";
  return m.str();
}

}  // namespace phiq::detail
