// `phiq sweep-accuracy SCENE`: what accuracy costs in time (tools/README.md, bench/README.md). For each setting of
// the knobs (Newton tolerance, step count, predictor, full or modified Newton, sparse LU) the scene's sweep is run
// and compared with a reference: the worst error in positions, velocities and accelerations, the Newton iterations
// and factorisations per step, and the best time per step of a few repetitions.
#pragma once

#include <atomic>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "phiq/phiq.hpp"

namespace phiq::tools {

// One point of the grid.
struct AccuracySetting {
  double tolerance = 1e-10;
  Index steps = 100;
  Predictor predictor = Predictor::kQuadratic;
  JacobianUpdate newton = JacobianUpdate::kWhenSlow;
  LinearSolverKind linear_solver = LinearSolverKind::kKlu;
};

// What one setting measured.
struct AccuracyRow {
  AccuracySetting setting;
  // Worst error over all time points and coordinates, each coordinate divided by its tolerance scale (the model's
  // length scale for lengths, 1 for angles): positions (angles modulo 2π), velocities (1/s), accelerations (1/s²).
  // NaN when the scene does not output that derivative or the sweep failed.
  double err_q = 0.0, err_v = 0.0, err_a = 0.0;
  double iterations_per_step = 0.0;      // Newton iterations of the drive steps (the assembly left out)
  double factorizations_per_step = 0.0;  // numeric LU factorisations, including those for q̇ and q̈
  double us_per_step = 0.0;              // best wall time of run_sweep over the timing rounds ÷ steps, µs
  std::string status = "ok";             // "ok", or the solver's status words when the sweep failed
  bool is_default = false;               // the scene's own settings (predictor auto resolved)
};

// The grid and the reference. Empty lists mean the defaults (below).
struct AccuracyOptions {
  std::vector<double> tolerances;                // default 1e-4, 1e-5, ..., 1e-14
  std::vector<Index> steps;                      // default the scene's steps × {1/4, 1, 4}
  std::vector<Predictor> predictors;             // default previous, secant, parabolic, linear, quadratic, cubic
  std::vector<JacobianUpdate> newton;            // default modified, full
  std::vector<LinearSolverKind> linear_solvers;  // default klu, umfpack
  // "auto" (the closed form the scene's name suggests if it satisfies the scene's constraints, else numerical),
  // "numerical" (the same scene at tolerance 1e-14, full Newton, reference_substeps sub-steps per step), or
  // "closed-form:KIND[:NAME=VALUE,...]" (closed_forms.hpp).
  std::string reference = "auto";
  // Timing rounds over the whole grid (best of), after one untimed run per setting that measures the errors; in
  // each round a sweep is repeated until 10 ms are timed.
  int repeat = 3;
  int reference_substeps = 4;  // numerical reference: sub-steps per step of the setting
  // When set and it becomes true (Ctrl-C), the running sweep stops and measure_accuracy throws AccuracyCancelled.
  const std::atomic<bool>* stop = nullptr;
};

// measure_accuracy was stopped through AccuracyOptions::stop.
struct AccuracyCancelled : std::runtime_error {
  AccuracyCancelled() : std::runtime_error("interrupted") {}
};

struct AccuracyReport {
  std::string scene_path, scene_name;
  std::string reference;       // "closed-form:<spec>" or "numerical: tolerance 1e-14, full Newton, ..."
  std::string reference_kind;  // "closed-form:<kind>" or "numerical"
  Index coordinates = 0;
  double length_scale = 1.0;
  AccuracySetting scene_default;
  std::vector<AccuracyRow> rows;
  std::vector<std::string> notes;  // settings skipped and why, reference fallbacks
  // Set by the command: where it ran (the times mean little without the machine), and, when the measurement could
  // not be made (the numerical reference failed), why: status "failed" and the message, with no rows.
  std::string host = "unknown", cpu = "unknown";
  std::string status = "success", message;
};

// Parses the command line's lists ("1e-4,1e-8", "previous,quadratic", "modified,full", "klu,umfpack", "45,180").
// Throws std::invalid_argument with a one-line message naming the option.
std::vector<double> parse_tolerances(const std::string& list);
std::vector<Index> parse_steps(const std::string& list);
std::vector<Predictor> parse_predictors(const std::string& list);
std::vector<JacobianUpdate> parse_newton(const std::string& list);
std::vector<LinearSolverKind> parse_linear_solvers(const std::string& list);

// Runs the grid on a loaded scene. `progress` (may be empty) gets one line per setting. Throws
// std::invalid_argument for a reference that does not fit the scene, std::runtime_error when the reference run fails.
AccuracyReport measure_accuracy(const Scene& scene, const AccuracyOptions& options,
                                const std::function<void(const std::string&)>& progress = {});

// The report as CSV (columns: scene, reference, tolerance, steps, predictor, newton, linear_solver, err_q, err_v,
// err_a, iterations_per_step, factorizations_per_step, us_per_step, status, default) and as JSON (format
// kSweepAccuracyJsonFormat; a failed report has only the format, phiq, host, scene, name, status, message, notes and
// an empty rows list).
std::string accuracy_csv(const AccuracyReport& report);
std::string accuracy_json(const AccuracyReport& report);

}  // namespace phiq::tools
