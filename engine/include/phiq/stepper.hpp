/// @file
/// Stepping the caller's own clock: a Stepper solves position, velocity and acceleration at the times a simulator
/// chooses, one call at a time, with everything run_sweep does per step — the predictor from the rows before,
/// modified Newton reusing the factorisation, sub-steps on failure, derivatives from the factorisation at the
/// solution, singular positions and bifurcations found by the sign of det Φq, warnings, accuracy classes and work
/// counters. Over the times of a sweep's grid it computes, to the bit, the rows of run_sweep in order (one chunk:
/// ParallelSettings::chunk_steps ≥ steps).
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "phiq/sweep.hpp"

namespace phiq {

/// What a Stepper computes and how: the solver settings of a sweep (predictor, Newton, assembly, sub-steps), what
/// it solves at each step and the points it evaluates there.
struct StepperOptions : SolverSettings {
  bool velocities = true;     ///< solve q̇ at every step
  bool accelerations = true;  ///< solve q̈ at every step (q̇ is then solved too, whatever `velocities` says)
  /// Points whose motion is evaluated at every step (Stepper::point_motions()): position always, velocity when q̇
  /// is solved, acceleration when q̈ is.
  std::vector<OutputPoint> points;
  /// The step the caller expects to take (s, finite and non-zero). Used only where the first position (after
  /// construction or restart()) is exactly a singular one: the points that bracket it for the branch's own
  /// velocity lie at a fraction of this step on either side. The steps taken may differ from it.
  double expected_step = 0.01;
  /// Design parameters whose sensitivities ∂q/∂p (with ∂q̇/∂p, ∂q̈/∂p as q̇, q̈ are solved) every step delivers
  /// (Stepper::sensitivities()), solved with the step's own factorisation of Φq: as a sweep's rows
  /// (OutputPlan::sensitivities; sensitivity_along() of scene.hpp or of sensitivity.hpp makes them).
  std::vector<OutputSensitivity> sensitivities;
  /// How they are solved: kAuto is the direct form, every coordinate's (a stepper writes no columns); kAdjoint
  /// solves for no coordinate here, and is refused.
  SensitivityForm sensitivity_form = SensitivityForm::kAuto;
  /// Driver efforts and powers every step delivers (Stepper::efforts()), as a sweep's rows (OutputPlan::efforts):
  /// q̇ and q̈ are then solved whatever `velocities` and `accelerations` say.
  OutputEfforts efforts;
  /// Ranges every step checks (OutputPlan::limits, as a sweep's rows): a step whose value leaves one warns `limit`
  /// there, once until it comes back (StepSummary::limits lists those outside at each step). An effort's needs it
  /// in `efforts`, a rate q̇.
  std::vector<OutputLimit> limits;
};

/// What one Stepper::step did.
struct StepSummary {
  SolveStatus status = SolveStatus::kSuccess;  ///< the outcome (also the step's return value)
  double t = 0.0;                              ///< the time asked for
  /// One line naming the time, the cause and the worst constraints, as run_sweep's summary does; empty on success.
  std::string message;
  /// At a failed position: its worst rows (row, |Φ_i| / scale_i), largest first, at most 3 (SweepSummary::worst_rows).
  std::vector<std::pair<Index, double>> worst_rows;
  bool assembled = false;  ///< the step assembled from the placement (the first step, or the first after restart())
  bool moved = false;      ///< the step solved anything (false for a step of zero length, or one refused outright)
  WorkCounters counters;   ///< the work this step did, its failed attempts included
  Index subdivisions = 0;  ///< sub-steps this step inserted after Newton failures
  std::vector<SweepWarning> warnings;  ///< the warnings this step raised (none when it failed)
  std::vector<std::string> limits;     ///< the names of StepperOptions::limits outside their range at this step
  double seconds = 0.0;                ///< wall time of the step
};

/// Solves the kinematics of a model at the times its caller chooses, keeping the sweep's predictors and
/// diagnostics from one step to the next (see the file comment). The first step assembles from the placement
/// (the model's initial positions, or restart()'s); each later one predicts from the steps before and solves from
/// there. Time may go forward or backward with any spacing. A step that fails leaves the stepper at its last good
/// state, so that the caller may retry with a smaller step.
///
/// The Stepper owns its Workspace; it keeps a reference to the Model, which must outlive it and stay where it is
/// (not moved) while the stepper exists. Movable, not copyable; one thread at a time.
class Stepper {
 public:
  /// A stepper for `model`, its placement the model's initial positions. Throws phiq::Error for settings no step can
  /// honour (those run_sweep refuses in SolverSettings; a predictor whose derivatives are not solved; a point that
  /// reads a coordinate the model does not have; expected_step not finite or zero; a sensitivity whose models do
  /// not match the model, check_sensitivity_models(); the adjoint form).
  explicit Stepper(const Model& model, StepperOptions options = {});
  ~Stepper();                              ///< frees the workspace and the history
  Stepper(Stepper&&) noexcept;             ///< takes over the other stepper's state; the other is not used after it
  Stepper& operator=(Stepper&&) noexcept;  ///< see the move constructor
  Stepper(const Stepper&) = delete;
  Stepper& operator=(const Stepper&) = delete;

  /// Solves position, and velocity and acceleration as asked, at time t (finite), and returns the outcome (also in
  /// *summary when given). The first step assembles from the placement; a step to the current time re-delivers the
  /// current state without solving; any other predicts from the rows before, forgetting them where time turns
  /// back (a predictor's nodes must be distinct times). On kSuccess q(), qd(), qdd() and time() are the solution at
  /// t. On failure the stepper stays at its last good state (the placement, before the first success) and the
  /// message names t, the cause and the worst constraints: kOutsideTimeDomain for a t outside the drivers' domain
  /// (Model::time_domain_begin/end), the statuses of run_sweep for a step that fails at every subdivision.
  /// Throws phiq::Error for a t that is not finite, or so close to the current time without being equal (within
  /// 8 ulps of the larger) that the step would not move time.
  [[nodiscard]] SolveStatus step(double t, StepSummary* summary = nullptr);

  /// Forgets the history, as after a jump of the caller's clock: the next step assembles from `placement` (a rough
  /// position of num_coordinates() entries) at its own time. Before the first step it sets the placement. The
  /// summary keeps counting. Throws phiq::Error for a placement of another size.
  void restart(const Eigen::VectorXd& placement);

  /// Whether a step has succeeded since construction or the last restart(): the state below is a solution.
  bool started() const;
  /// The time of the current state; NaN before started().
  double time() const;
  /// Positions of the current state (the placement before started()).
  const Eigen::VectorXd& q() const;
  /// Velocities of the current state when solved (StepperOptions::velocities or accelerations), else empty; zero
  /// before started().
  const Eigen::VectorXd& qd() const;
  /// Accelerations of the current state when solved (StepperOptions::accelerations), else empty; zero before
  /// started().
  const Eigen::VectorXd& qdd() const;
  /// Motions of StepperOptions::points at the current state, in that order; null when none are listed or before
  /// started().
  const PointMotion* point_motions() const;
  /// Sensitivities of the current state to StepperOptions::sensitivities, laid out as SensitivityLayout{n} says
  /// (parameter j's ∂q/∂p at offset(j, 0), ∂q̇/∂p at offset(j, 1), ∂q̈/∂p at offset(j, 2); NaN for the derivatives
  /// not solved, and all at a singular position); null when none are asked for or before started().
  const double* sensitivities() const;
  /// Efforts, powers and reactions of StepperOptions::efforts at the current step, then with sensitivities each
  /// effort's ∂τ/∂p and each power's ∂P/∂p (effort_values() values, StepView::efforts; NaN at a singular position),
  /// or null when none are asked for or before the first step.
  const double* efforts() const;

  /// Everything the steps did since construction, as run_sweep's summary says it of a sweep: counters, subdivisions,
  /// singular positions, the smallest rcond, warnings (in the order raised; each slow_convergence stands alone,
  /// as the stepper has no grid to merge stretches on), accuracy per class of the delivered rows, steps_completed
  /// (the steps that moved and succeeded, the assemblies included), solve_seconds (the steps' own time) and the
  /// assembly of the last start. status, message, worst_rows, failed_step (steps_completed at the failure) and
  /// failed_time describe the last step that moved (kSuccess and empty after a success).
  const SweepSummary& summary() const;
  /// The workspace the steps solve in: its counters and the factorisation of Φq (its q, q̇, q̈ are the steps'
  /// scratch: read the state from q(), qd(), qdd()).
  const Workspace& workspace() const;
  const Model& model() const;             ///< the model stepped
  const StepperOptions& options() const;  ///< the options it was made with

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace phiq
