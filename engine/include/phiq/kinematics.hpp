/// @file
/// The three problems of the notes, as free functions over (Model, Workspace):
///   position      Φ(q, t) = 0                          Newton-Raphson (damped by a line search)
///   velocity      Φq q̇ = −Φt                            linear, same matrix
///   acceleration  Φq q̈ = γ = −(Φq q̇)q q̇ − 2Φqt q̇ − Φtt    linear, same matrix
/// Numerical outcomes are statuses the caller can act on; only violated pre-conditions (wrong sizes) throw.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "phiq/workspace.hpp"

namespace phiq {

/// Outcome of a solve: what the caller can act on. Only kSuccess leaves a valid solution in the workspace.
enum class [[nodiscard]] SolveStatus{
    kSuccess,             ///< solved to tolerance
    kNotConverged,        ///< Newton reached its iteration limit, or could not decrease the residual
    kSingularJacobian,    ///< Φq is singular here (singular position, redundant or missing constraints)
    kLinearSolverFailed,  ///< the sparse library failed (out of memory, invalid data)
    kNonFinite,           ///< NaN or Inf in Φ, Φq or a solution (e.g. a law outside its table, sqrt of a negative; a
                          ///< derivative that does not exist, sqrt at 0, with the constraint and coordinate named)
    kNotSquare,           ///< equations ≠ coordinates: not solvable by the square driven-system path
    kOutsideTimeDomain,   ///< a driver's law is not defined at the requested time
    kCancelled,           ///< the caller's step callback asked to stop
    kInconsistent,        ///< redundant constraints that cannot hold together (assembly.hpp names them)
    /// solve_velocity / solve_acceleration at a q that does not solve the position problem Φ(q, t) = 0 (to
    /// DerivativeOptions::tolerance): its q̇ or q̈ would mean nothing. The message names the worst constraint.
    kPositionNotSolved,
    /// a coordinate left the range where a constraint's equations are defined (a curve parameter past the end of an
    /// open curve, Model::outside_domain()): the message names the constraint, and the sweep's the time
    kOutsideDomain,
};
/// Lower-case words, e.g. "singular Jacobian".
const char* to_string(SolveStatus s);

/// Settings of the Newton-Raphson position solve.
/// Which matrix each Newton iteration solves with.
enum class JacobianUpdate {
  /// Full Newton: Φq is evaluated and factorised at every iterate (quadratic convergence).
  kEveryIteration,
  /// Modified (simplified) Newton: the factorisation already in the workspace is reused — across iterations and
  /// across drive steps, wherever it was made — while it contracts well (‖Δq_k‖ / ‖Δq_k−1‖ ≤ max_contraction);
  /// when it slows, diverges or stops decreasing the residual, Φq is refactorised at the current iterate and the
  /// solve continues as full Newton. Each iteration then costs a solve instead of a factorisation.
  kWhenSlow,
};
/// "every_iteration" or "when_slow".
const char* to_string(JacobianUpdate u);

/// Newton-Raphson settings for solve_position().
struct NewtonOptions {
  /// Convergence: every row |Φ_i| ≤ tol · scale_i, and the estimated error of q after the last step is within
  /// tol · scale_j for every coordinate j, where scale is the model's length_scale() for lengths and 1 for angles
  /// and unitless rows (plus a floor of a few ulps of |q|, so that the test stays reachable far from the origin).
  /// The error estimate is θ/(1−θ)·|Δq_j| with θ the observed contraction ‖Δq_k‖/‖Δq_k−1‖ (Deuflhard; Hairer &
  /// Wanner IV.8); where no contraction has been observed yet it is |Δq_j| itself (the step must be small).
  double tolerance = 1e-10;
  int max_iterations = 20;  ///< Newton iterations before giving up (kNotConverged)
  bool line_search = true;  ///< backtracking on ½‖Φ/scale‖² (always on for assembly from a rough placement)
  int max_backtracks = 12;  ///< halvings of the step before the line search gives up
  JacobianUpdate jacobian_update = JacobianUpdate::kEveryIteration;  ///< full or modified Newton
  /// Evaluate Φq together with Φ (one pass over the constraints instead of two) also at the trial expected to be
  /// the solution (its step already passes the tolerance), for a caller that factorises there next (velocities).
  /// Wherever the next iteration factorises at the trial (full Newton; modified Newton once it has refreshed) the
  /// loop does it anyway.
  bool jacobian_with_residual = false;
  /// Modified Newton: refactorise when the observed contraction exceeds this (0 < max_contraction < 1).
  double max_contraction = 0.25;
  /// How far the start point ws.q is estimated to be from the solution, in units of the tolerance test on a step
  /// (scaled_step(): ≤ 1 within the tolerance), from whoever chose it — a sweep's predictor gives the size of the
  /// next term of its extrapolation. The start is accepted without a Newton step only when its residual holds and
  /// this estimate is ≤ 1: a residual within tolerance alone does not bound the error of q where Φq is
  /// ill-conditioned (near a singular position, along a long chain). Infinity: always take a step. Negative (the
  /// default): unknown, and the start is accepted on its residual alone (the convergence test above, with no step
  /// to estimate).
  double start_error = -1.0;
  /// How well q can be known at all here, in units of the tolerance test, where the caller has measured it: a
  /// sweep passes the largest rounding level (PositionSummary::rounding_level) its rows stopped at since the last
  /// one that converged to the tolerance. Newton then also ends after a full step whose estimated error is within
  /// it, whose trial's residual holds and whose Φq is not ill-conditioned (rcond ≥ 1e-4: below it, linear
  /// convergence marks a singular position), as a stop at the rounding level would after more iterations that only
  /// measure the rounding again. On a 10⁵-stage scissor lift the top joints are known to some 10³ tolerances, and
  /// half the rows took a second Newton step, with a fresh factorisation, to find that out. The step's estimated
  /// error is reported as the rounding level, with the warning of such a stop above 2. Up to 1 (the default, 0):
  /// none. In SweepOptions::newton it is a floor under the level the sweep carries.
  double known_to = 0.0;
};

/// What solve_position did (Ceres-style summary).
struct PositionSummary {
  SolveStatus status = SolveStatus::kNotConverged;  ///< the outcome
  int iterations = 0;                               ///< Newton steps taken (linear solves)
  int factorizations = 0;                           ///< of them, steps with a fresh factorisation of Φq
  int backtracks = 0;                               ///< step halvings by the line search
  double residual = 0.0;                            ///< max_i |Φ_i| / scale_i at the end
  double rcond = 0.0;                               ///< of the last factorisation (0 if none)
  /// Success at the iteration limit with the residual within tolerance but steps still above it: the linear
  /// convergence of Newton at a singular position (a dead point, a bifurcation). The constraints hold to tolerance;
  /// the position itself is less accurate (about √tol). message says so.
  bool slow_convergence = false;
  /// Of slow_convergence: the steps converged only linearly with the residual within tolerance (at a singular
  /// position, q known to about √tol), not a stop at the rounding level (rounding_level > 0). A sweep takes such a
  /// row as singular below a stricter condition (rcond < 1e-4 instead of 1e-10).
  bool linear_convergence = false;
  /// At a stop at the rounding level: the last Newton step in units of the tolerance test (max_j |Δq_j| / (tol ·
  /// scale_j + floor_j)), i.e. how well q is known relative to the tolerance (at an end within
  /// NewtonOptions::known_to, the step's estimated error); 0 otherwise. Above 2 the stop is a
  /// slow_convergence with the message "…rounding level…"; up to 2 it is a plain success (known as well as the
  /// tolerance test's estimate promises).
  double rounding_level = 0.0;
  /// rounding_level was measured by a step from an iterate an earlier step of this solve had reached, so that it
  /// is the rounding alone, not also the start's own error (which a first step corrects): what a sweep carries to
  /// its next solves in NewtonOptions::known_to.
  bool rounding_measured = false;
  /// On success, the estimated error of q in units of the tolerance test (scaled_step(): ≤ 1 within the tolerance):
  /// the larger of θ/(1−θ)|Δq| of the last step (the step itself where no contraction was observed) and |Δq| times
  /// the factor by which that step reduced the residual (the size of the next step, were it taken: about |Δq| itself
  /// where the steps are rounding noise), the rounding level at a stop there, or NewtonOptions::start_error when
  /// the start was accepted without a step; negative when unknown (a start accepted on its residual alone).
  double error_estimate = -1.0;
  /// When error_estimate is above 2 tolerances (a stop at the rounding level, a linear convergence, an end within
  /// NewtonOptions::known_to): the coordinate j least well known in units of its tolerance test, from the last
  /// step (error_estimate at its worst coordinate) and from the rounding of q itself carried through Φ (Φq⁻¹ f,
  /// f_i = ε Σ_j |∂Φ_i/∂q_j| |q_j|: what the step misses where a coordinate near 10⁶ m, held to its ulp, moves a
  /// 10⁻⁶ m link's other end); −1 otherwise.
  Index error_coordinate = -1;
  /// How far q at error_coordinate may be from the solution, in its own unit (metres, radians): "yB known to
  /// ±2e-10 m" (known_to_text()); 0 when error_coordinate is −1.
  double error_size = 0.0;
  /// The worst rows at the end (row, |Φ_i| / scale_i), largest first, at most 3.
  std::vector<std::pair<Index, double>> worst_rows;
  std::string message;  ///< one line; empty on a clean success
  /// One line: status, iterations, residual, message.
  std::string BriefReport() const;
};

/// What solve_velocity or solve_acceleration did.
struct LinearSummary {
  SolveStatus status = SolveStatus::kSuccess;  ///< kSuccess, kSingularJacobian (not unique), kNotSquare, ...
  double rcond = 0.0;                          ///< reciprocal condition estimate of the factorisation used
  std::string message;                         ///< one line; empty on success
};

/// Solves Φ(q, t) = 0 starting from ws.q; on success ws.q holds the solution, otherwise the last iterate.
/// Pre-condition: ws was made for `model` and its vectors keep their sizes. Throws phiq::Error when a
/// pre-condition or `options` is violated; every numerical outcome is the returned status (also in `summary`).
/// Thread-safe for distinct workspaces.
SolveStatus solve_position(const Model& model, double t, const NewtonOptions& options, Workspace& ws,
                           PositionSummary* summary = nullptr);

/// Settings of solve_velocity() and solve_acceleration().
struct DerivativeOptions {
  /// ws.q must solve the position problem at t to this tolerance, by the residual test of solve_position (every
  /// row |Φ_i| ≤ tolerance · scale_i + floor_i: NewtonOptions::tolerance, whose default it shares); otherwise the
  /// solve returns kPositionNotSolved and leaves q̇ / q̈ as they were. Pass the tolerance q was solved with when
  /// that was looser. The test costs one evaluation of Φ (cheap beside the factorisation of Φq), and none where the
  /// workspace knows q is the solution solve_position reached at t (its factorisation or Jacobian values are at
  /// ws.q), or passed this test with the factors it holds (solve_acceleration after solve_velocity). Infinity: no
  /// test (the caller vouches for q). Must be > 0 (else phiq::Error).
  double tolerance = 1e-10;
};

/// Solves Φq q̇ = −Φt at ws.q into ws.qd. Pre-condition: ws.q solves the position problem at t, checked
/// (DerivativeOptions::tolerance): kPositionNotSolved, with the worst constraint named, when it does not. Reuses the
/// factorisation when it was made at time t at a point within the position tolerance of ws.q (the last Newton
/// step was below the tolerance; the difference is below the accuracy of q itself), and otherwise factorises Φq at
/// (ws.q, t). kSingularJacobian: the velocity is not unique there.
/// Throws phiq::Error only for violated pre-conditions (workspace of another model, wrong sizes, bad options).
SolveStatus solve_velocity(const Model& model, double t, const DerivativeOptions& options, Workspace& ws,
                           LinearSummary* summary = nullptr);
/// solve_velocity() with the default DerivativeOptions (q solved to 1e-10).
SolveStatus solve_velocity(const Model& model, double t, Workspace& ws, LinearSummary* summary = nullptr);

/// Solves Φq q̈ = γ(q, q̇, t) into ws.qdd. Pre-condition: ws.q and ws.qd solve position and velocity at t; the
/// position is checked as by solve_velocity() (kPositionNotSolved), the velocity is not: q̈ is the acceleration of
/// the motion through q with the velocity ws.qd, whichever it is (γ is defined for any q̇), and checking
/// Φq q̇ = −Φt would cost an evaluation of Φt and a product with Φq on every call, for a velocity that
/// solve_velocity has just computed in the usual sequence.
SolveStatus solve_acceleration(const Model& model, double t, const DerivativeOptions& options, Workspace& ws,
                               LinearSummary* summary = nullptr);
/// solve_acceleration() with the default DerivativeOptions (q solved to 1e-10).
SolveStatus solve_acceleration(const Model& model, double t, Workspace& ws, LinearSummary* summary = nullptr);

/// max_i |Φ_i| / scale_i, the measure the convergence test uses (0 for an empty model).
double scaled_residual(const Model& model, const Eigen::VectorXd& phi);

/// How well coordinate `j` is known, in its own unit, as messages say it: "'yB' known to ±2.1e-10 m" (`size`:
/// PositionSummary::error_size, RowClassAccuracy::worst_known_to). Pre-condition: 0 ≤ j < num_coordinates().
std::string known_to_text(const Model& model, Index j, double size);
/// known_to_text() of a coordinate named `name` measured in `unit`.
std::string known_to_text(const std::string& name, double size, Unit unit);

/// max_j |Δq_j| / (tol · scale_j + floor_j), the measure of a change of q that the convergence test uses: ≤ 1 when
/// `dq` is within the tolerance `tol` of the coordinates `q` (scale as in NewtonOptions::tolerance, floor a few ulps
/// of |q_j|); NaN counts as infinitely large. Pre-condition: dq and q have num_coordinates() entries.
double scaled_step(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& dq, const Eigen::VectorXd& q,
                   double tol);

}  // namespace phiq
