// The run summary of `phiq run --summary` (run_summary.hpp).
#include "run_summary.hpp"

#include <nlohmann/json.hpp>

#include "command_support.hpp"
#include "host_info.hpp"
#include "report_header.hpp"

namespace phiq::tools {

void add_outcome(nlohmann::ordered_json& j, const Model& swept, const SweepSummary& s) {
  j["status"] = to_string(s.status);
  j["message"] = s.message;
  // where it failed: null on success
  if (s.status == SolveStatus::kSuccess) {
    j["failed_step"] = nullptr;
    j["failed_time"] = nullptr;
  } else {
    j["failed_step"] = s.failed_step;
    j["failed_time"] = s.failed_time;
  }
  j["worst_constraints"] = nlohmann::ordered_json::array();
  for (const auto& [row, residual] : s.worst_rows)
    j["worst_constraints"].push_back({{"name", swept.row_name(row)}, {"residual", residual}});
}

nlohmann::ordered_json host_json() { return {{"name", host_name()}, {"cpu", cpu_model()}}; }

std::string run_summary_json(const Scene& scene, const Model& swept, const SweepSummary& s, const RunTimes& times,
                             const nlohmann::ordered_json& modes) {
  // where and with what it ran: a summary kept by a harness says so without the command line
  nlohmann::ordered_json j = report_header(kRunSummaryFormat, scene.path, scene);
  j["host"] = host_json();
  add_outcome(j, swept, s);
  j["steps"] = s.steps_completed;
  j["threads"] = s.threads;
  j["parallel_chunks"] = s.parallel_chunks;
  j["coordinates"] = scene.model->num_coordinates();
  j["linear_solver"] = to_string(scene.model->linear_solver());
  j["load_seconds"] = times.load;
  j["solve_seconds"] = times.solve;
  // the sweep's wall time: the solve and the writing done in its callback, which other threads' solving overlaps
  j["sweep_seconds"] = s.solve_seconds;
  j["write_seconds"] = times.write;
  j["newton_iterations"] = s.counters.newton_iterations;
  j["factorizations"] = s.counters.factorizations;
  j["pivoting_factorizations"] = s.counters.pivoting_factorizations;
  j["velocity_solves"] = s.counters.velocity_solves;
  j["acceleration_solves"] = s.counters.acceleration_solves;
  j["phi_t_evaluations"] = s.counters.phi_t_evaluations;
  j["gamma_evaluations"] = s.counters.gamma_evaluations;
  j["residual_evaluations"] = s.counters.residual_evaluations;
  j["point_evaluations"] = s.counters.point_evaluations;
  j["sensitivity_solves"] = s.counters.sensitivity_solves;
  j["sensitivity_direct_rows"] = s.counters.sensitivity_direct_rows;
  j["effort_solves"] = s.counters.effort_solves;
  // direct or adjoint (OutputPlan::sensitivity_form resolved); absent without sensitivities
  if (s.sensitivity_form != phiq::SensitivityForm::kAuto) j["sensitivity_form"] = to_string(s.sensitivity_form);
  j["subdivisions"] = s.subdivisions;
  j["singular_positions"] = s.singular_positions;
  // 0 in the summary means no row measured it (a positions-only sweep factorises at Newton iterates, not at the
  // solutions): null, not a condition number of 0, which would read as a singular Jacobian
  if (s.min_rcond > 0.0)
    j["min_rcond"] = s.min_rcond;
  else
    j["min_rcond"] = nullptr;
  // how well q is known per class of row (SweepAccuracy): the estimated error in units of the tolerance test
  auto row_class = [](const phiq::RowClassAccuracy& c) {
    nlohmann::ordered_json r;
    r["rows"] = c.rows;
    r["worst_error"] = c.worst_error;
    r["worst_time"] = c.worst_time;
    // the same estimate in the coordinate's own unit (null where no solve said which coordinate)
    if (c.worst_coordinate.empty()) {
      r["worst_coordinate"] = nullptr, r["worst_known_to"] = nullptr, r["worst_unit"] = nullptr;
    } else {
      r["worst_coordinate"] = c.worst_coordinate, r["worst_known_to"] = c.worst_known_to;
      r["worst_unit"] = phiq::unit_symbol(c.worst_unit);
    }
    r["unestimated"] = c.unestimated;
    return r;
  };
  j["accuracy"] = {{"tolerance", scene.sweep.newton.tolerance},
                   {"converged", row_class(s.accuracy.converged)},
                   {"rounding_level", row_class(s.accuracy.rounding_level)},
                   {"singular", row_class(s.accuracy.singular)}};
  j["warnings"] = nlohmann::ordered_json::array();
  for (const auto& w : s.warnings) j["warnings"].push_back({{"t", w.t}, {"kind", w.kind}, {"message", w.message}});
  // the real assembly modes at the start and the first row's (mode_count.hpp)
  j["modes"] = modes;
  return json_text(j, 2) + "\n";
}

}  // namespace phiq::tools
