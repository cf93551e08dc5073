// Internal to the engine: a warning that recurs along a sweep, said once per stretch of rows (run_sweep's
// slow_convergence, which a long chain at its rounding level raises at most rows).
#pragma once

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "phiq/sweep.hpp"

namespace phiq::detail {

// A stretch goes on across at most this many rows without the warning: a long chain at its rounding level warns at
// one row, converges to the tolerance at the next, warns again (10⁶ scissor stages in order, positions only: 45
// warnings one or two rows apart over 100 rows, one line each on the command line).
constexpr int kStretchGapRows = 2;

// Keeps the first warning of `kind` of every stretch of rows of the sweep's grid, rows at most kStretchGapRows apart
// from the last that warned, and says on it how far the stretch went: "the same at the next N rows, to t = …" when
// every row warned, "the same at N of the next M rows, to t = …" otherwise. Warnings at sub-steps (between grid rows)
// stand alone; the other kinds and the order are kept. Done on the merged list, so that sequential and parallel
// sweeps report alike.
inline void once_per_stretch(std::vector<SweepWarning>& warnings, const char* kind, const SweepOptions& opt) {
  if (opt.steps <= 0) return;
  const double h = (opt.t_end - opt.t_begin) / static_cast<double>(opt.steps);
  std::vector<SweepWarning> kept;
  kept.reserve(warnings.size());
  bool open = false;  // a stretch is open: its warning is kept[first]
  std::size_t first = 0;
  Index first_row = 0, last_row = 0, more = 0;  // the stretch's first and last rows; rows after the first that warned
  double last_t = 0.0;
  auto close = [&] {
    if (open && more > 0) {
      const Index span = last_row - first_row;
      kept[first].message += "; the same at " +
                             (more == span ? "the next " + std::to_string(more)
                                           : std::to_string(more) + " of the next " + std::to_string(span)) +
                             " rows, to t = " + format_time(last_t);
    }
    open = false, more = 0;
  };
  for (SweepWarning& w : warnings) {
    if (w.kind != kind) {
      kept.push_back(std::move(w));
      continue;
    }
    const double t = w.t, r = (t - opt.t_begin) / h;  // fractional at a sub-step
    const double nearest = std::round(r);
    if (std::fabs(r - nearest) > 1e-6) {  // a sub-step: by itself
      close();
      kept.push_back(std::move(w));
      continue;
    }
    const Index row = static_cast<Index>(nearest);
    if (open && row > last_row && row - last_row <= kStretchGapRows + 1) {
      ++more;
    } else {
      close();
      open = true, first = kept.size(), first_row = row;
      kept.push_back(std::move(w));
    }
    last_row = row, last_t = t;
  }
  close();
  warnings.swap(kept);
}

}  // namespace phiq::detail
