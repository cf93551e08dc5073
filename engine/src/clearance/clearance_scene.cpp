// scene_clearance() (phiq/clearance.hpp): the scene's sweep, its rows kept with q̇ and q̈, then its clearance.
#include "phiq/clearance.hpp"
#include "phiq/scene.hpp"

namespace phiq {

ClearanceReport scene_clearance(const Scene& scene, SweepSummary* summary) {
  SweepOptions options = scene.sweep;
  // the rows' rates bound the motion between them and start the positions solved there
  options.velocities = options.accelerations = true;
  options.sensitivities.clear();  // solved at the minima only
  ClearanceRows rows;
  Workspace ws(*scene.model);
  SweepSummary own;
  (void)run_sweep(  // its outcome is in the summary
      *scene.model, options, ws,
      [&](const StepView& v) {
        rows.t.push_back(v.t);
        rows.q.push_back(v.q);
        rows.qd.push_back(*v.qd);
        rows.qdd.push_back(*v.qdd);
        return true;
      },
      summary ? summary : &own);
  ClearanceOptions co;
  co.solver = scene.sweep;
  co.sensitivities = scene.sweep.sensitivities;
  return clearance_along(*scene.model, scene.parts, scene.clearance, rows, co);
}

}  // namespace phiq
