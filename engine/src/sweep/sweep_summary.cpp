// SweepSummary::BriefReport(): the one-line account of a sweep (status, steps, work, threads, warnings, time) that
// the command line and the tests print. Apart because it only reads the summary the sweep filled.
#include <sstream>

#include "phiq/sweep.hpp"

namespace phiq {

std::string SweepSummary::BriefReport() const {
  std::ostringstream s;
  s << to_string(status) << ": " << steps_completed << " steps, " << counters.newton_iterations
    << " Newton iterations, " << counters.factorizations << " factorizations, " << counters.velocity_solves
    << " velocity and " << counters.acceleration_solves << " acceleration solves";
  if (counters.point_evaluations) s << ", " << counters.point_evaluations << " point evaluations";
  if (counters.sensitivity_solves)
    s << ", " << counters.sensitivity_solves << " sensitivity solves (" << to_string(sensitivity_form)
      << (counters.sensitivity_direct_rows ? ", " + std::to_string(counters.sensitivity_direct_rows) + " rows direct"
                                           : std::string())
      << ")";
  if (counters.effort_solves) s << ", " << counters.effort_solves << " effort solves";
  if (subdivisions) s << ", " << subdivisions << " step subdivisions";
  if (singular_positions) s << ", " << singular_positions << " singular positions passed";
  if (threads > 1)
    s << ", " << threads << " threads (" << parallel_chunks << " parallel chunk" << (parallel_chunks == 1 ? ")" : "s)");
  if (!warnings.empty())
    s << ", " << warnings.size() << (warnings.size() == 1 ? " warning" : " warnings")
      << " (first at t = " << warnings[0].t << ")";
  s.precision(3);
  s << ", " << std::scientific << solve_seconds << " s";
  if (!message.empty()) s << " — " << message;
  return s.str();
}

}  // namespace phiq
