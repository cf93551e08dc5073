// sweep_rows() and scene_clearance() (phiq/clearance.hpp): a sweep's rows kept with q̇ and q̈, then a scene's
// clearance over them.
#include "phiq/clearance.hpp"
#include "phiq/scene.hpp"

namespace phiq {

ClearanceRows sweep_rows(const Model& model, SweepOptions options, Workspace& ws, SweepSummary* summary) {
  options.velocities = options.accelerations = true;
  ClearanceRows rows;
  SweepSummary own;
  (void)run_sweep(  // its outcome is in the summary
      model, options, ws,
      [&](const StepView& v) {
        rows.t.push_back(v.t);
        rows.q.push_back(v.q);
        rows.qd.push_back(*v.qd);
        rows.qdd.push_back(*v.qdd);
        return true;
      },
      summary ? summary : &own);
  return rows;
}

ClearanceReport scene_clearance(const Scene& scene, SweepSummary* summary) {
  SweepOptions options = scene.sweep;
  // the rows' rates bound the motion between them and start the positions solved there
  options.sensitivities.clear();  // solved at the minima only
  Workspace ws(*scene.model);
  const ClearanceRows rows = sweep_rows(*scene.model, options, ws, summary);
  ClearanceOptions co;
  co.solver = scene.sweep;
  co.sensitivities = scene.sweep.sensitivities;
  return clearance_along(*scene.model, scene.parts, scene.clearance, rows, co);
}

}  // namespace phiq
