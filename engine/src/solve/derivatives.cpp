// The velocity and acceleration solves: q̇ from Φq q̇ = −Φt and q̈ from Φq q̈ = γ, public (solve_velocity,
// solve_acceleration) and at the solution the sweep has just reached (detail::derivatives_at_solution). Separate
// from the Newton loop (kinematics.cpp): they share only Φq's factorisation (factorisation.hpp).
#include "phiq/kinematics.hpp"

#include "solve/factorisation.hpp"
#include "phiq/text.hpp"
#include "solve/kinematics_internal.hpp"
#include "solve/tolerance_tests.hpp"

#include <cmath>
#include <limits>
#include <string>

namespace phiq {

namespace {

using detail::check_workspace;
using detail::ensure_factorized;
using detail::factorize_at_q;
using detail::kNoDerivative;
using detail::non_finite_jacobian_at;
using detail::not_square_message;
using detail::solve_rhs;

// The first non-finite row of a right-hand side (Φt or γ, one entry per equation), or "".
std::string non_finite_row(const Model& model, const Eigen::VectorXd& rhs, const std::string& what, const char* why) {
  for (Index i = 0; i < rhs.size(); ++i)
    if (!std::isfinite(rhs(i))) return what + " of '" + model.row_name(i) + "' is not finite" + why;
  return "";
}

// q̇ from Φq q̇ = −Φt, and q̈ from Φq q̈ = γ, with the factors ws.lu holds (Φq at ws.q, t; the caller saw to
// it): the solves of solve_velocity / solve_acceleration and of the sweep's derivatives_at_solution.
SolveStatus velocity_from_factors(const Model& model, double t, Workspace& ws, LinearSummary& sum) {
  model.phi_t(ws.q.data(), t, ws.rhs.data());
  ++ws.counters.phi_t_evaluations;
  ws.rhs = -ws.rhs;
  if (!ws.lu->solve(solve_rhs(model, ws), ws.qd.data()))
    return sum.status = SolveStatus::kLinearSolverFailed, sum.message = ws.lu->last_message(), sum.status;
  ++ws.counters.velocity_solves;
  if (!ws.qd.allFinite()) {
    std::string why = non_finite_row(model, ws.rhs, "Φt", kNoDerivative);
    if (why.empty()) why = non_finite_jacobian_at(model, ws.q.data(), t);
    sum.message = "velocity is not finite" + (why.empty() ? "" : ": " + why);
    return sum.status = SolveStatus::kNonFinite;
  }
  return SolveStatus::kSuccess;
}
SolveStatus acceleration_from_factors(const Model& model, double t, Workspace& ws, LinearSummary& sum) {
  model.gamma(ws.q.data(), ws.qd.data(), t, ws.rhs.data());
  ++ws.counters.gamma_evaluations;
  if (!ws.lu->solve(solve_rhs(model, ws), ws.qdd.data()))
    return sum.status = SolveStatus::kLinearSolverFailed, sum.message = ws.lu->last_message(), sum.status;
  ++ws.counters.acceleration_solves;
  if (!ws.qdd.allFinite()) {
    std::string why = non_finite_row(model, ws.rhs, "γ",
                                     ", second derivatives that do not exist at this position (as those of u^p, "
                                     "p < 2, at u = 0)");
    if (why.empty()) why = non_finite_jacobian_at(model, ws.q.data(), t);
    sum.message = "acceleration is not finite" + (why.empty() ? "" : ": " + why);
    return sum.status = SolveStatus::kNonFinite;
  }
  return SolveStatus::kSuccess;
}

// Whether ws.q is known to solve the position problem at t without evaluating Φ: the factors or the Jacobian
// values solve_position left at its solution are at (ws.q, t), or the factors' point passed this test at `tol`.
bool known_solved(const Workspace& ws, double t, double tol) {
  if (detail::factors_at_q(ws, t)) return ws.factorized_at_solution || ws.factorized_solves_to <= tol;
  return detail::jacobian_values_at_q(ws, t);
}

// "" when ws.q solves Φ(q, t) = 0 to `tol` (solve_position's residual test), else why not, naming the worst row
// among those that fail. One evaluation of Φ into ws.phi.
std::string position_not_solved(const Model& model, double t, double tol, Workspace& ws) {
  model.residual(ws.q.data(), t, ws.phi.data());
  ++ws.counters.residual_evaluations;
  const Eigen::VectorXd& rs = model.tolerance_scales().row_scale;
  Index worst = -1;
  double worst_scaled = 0.0;
  for (Index i = 0; i < ws.phi.size(); ++i) {
    double scaled = std::fabs(ws.phi(i)) / rs(i);
    if (std::isnan(scaled)) scaled = std::numeric_limits<double>::infinity();
    if (scaled <= tol || (worst >= 0 && scaled <= worst_scaled)) continue;  // the floor only where it matters
    if (detail::row_within(model, i, scaled, tol, ws.q, t)) continue;
    worst = i, worst_scaled = scaled;
  }
  if (worst < 0) return "";
  return "q does not solve the position problem at t = " + format_time(t) + ": constraint '" + model.row_name(worst) +
         "' residual " + significant(worst_scaled, 3) + " > tolerance " + significant(tol, 3) +
         " (|Φ| / scale; solve_position first, or pass the tolerance q was solved to in " + "DerivativeOptions)";
}

// The public linear solves: q checked (DerivativeOptions::tolerance), Φq factorised at (ws.q, t) unless it is
// already, then `solve` (velocity_from_factors or acceleration_from_factors); `what` names the derivatives when
// Φq is singular there.
template <class Solve>
SolveStatus factorize_and_solve(const Model& model, double t, const DerivativeOptions& opt, Workspace& ws,
                                LinearSummary* summary, const char* what, Solve solve) {
  check_workspace(model, ws);
  if (!(opt.tolerance > 0.0))
    throw Error("DerivativeOptions.tolerance must be > 0 (infinity: no test of the position), not " +
                significant(opt.tolerance, 3));
  LinearSummary local;
  LinearSummary& sum = summary ? *summary : local;
  sum = LinearSummary{};
  const bool test = opt.tolerance != std::numeric_limits<double>::infinity() && !known_solved(ws, t, opt.tolerance);
  if (test) {
    std::string why = position_not_solved(model, t, opt.tolerance, ws);
    if (!why.empty()) return sum.status = SolveStatus::kPositionNotSolved, sum.message = std::move(why), sum.status;
  }
  std::string msg;
  SolveStatus st = ensure_factorized(model, t, ws, &sum.rcond, &msg);
  if (st == SolveStatus::kSingularJacobian) msg = std::string(what) + " are not unique here: " + msg;
  if (st != SolveStatus::kSuccess) return sum.status = st, sum.message = msg, st;
  // the factors' point passed the test, or is known to (Jacobian values left at solve_position's solution, now
  // factorised): the acceleration that follows need not test it again
  const bool tested = opt.tolerance != std::numeric_limits<double>::infinity();
  if (tested && !(ws.factorized_solves_to <= opt.tolerance)) ws.factorized_solves_to = opt.tolerance;
  return solve(model, t, ws, sum);
}

}  // namespace

SolveStatus solve_velocity(const Model& model, double t, const DerivativeOptions& options, Workspace& ws,
                           LinearSummary* summary) {
  return factorize_and_solve(model, t, options, ws, summary, "velocities", velocity_from_factors);
}
SolveStatus solve_velocity(const Model& model, double t, Workspace& ws, LinearSummary* summary) {
  return solve_velocity(model, t, DerivativeOptions{}, ws, summary);
}

SolveStatus solve_acceleration(const Model& model, double t, const DerivativeOptions& options, Workspace& ws,
                               LinearSummary* summary) {
  return factorize_and_solve(model, t, options, ws, summary, "accelerations", acceleration_from_factors);
}
SolveStatus solve_acceleration(const Model& model, double t, Workspace& ws, LinearSummary* summary) {
  return solve_acceleration(model, t, DerivativeOptions{}, ws, summary);
}

namespace detail {

SolveStatus derivatives_at_solution(const Model& model, double t, Workspace& ws, bool accelerations,
                                    LinearSummary* summary) {
  LinearSummary local;
  LinearSummary& sum = summary ? *summary : local;
  sum = LinearSummary{};
  auto fail = [&](SolveStatus st, std::string msg) {
    sum.status = st, sum.message = std::move(msg);
    return st;
  };
  if (!ws.lu) return fail(SolveStatus::kNotSquare, not_square_message(model));
  if (ws.has_factorization && ws.factorized_at_solution && ws.factorized_t == t) {
    sum.rcond = ws.lu->rcond();
  } else {
    std::string msg;
    const SolveStatus st = factorize_at_q(model, t, ws, &sum.rcond, &msg, ws.has_jacobian && ws.jacobian_t == t);
    if (st == SolveStatus::kSingularJacobian) return fail(st, "velocities are not unique here: " + msg);
    if (st != SolveStatus::kSuccess) return fail(st, msg);
    // the point is not recorded (factorized_q is another's): no (q, t) may match it, so that public solves and the
    // next solve_position's end factorise again rather than trust it
    ws.factorized_t = std::numeric_limits<double>::quiet_NaN();
  }
  const SolveStatus st = velocity_from_factors(model, t, ws, sum);
  if (st != SolveStatus::kSuccess || !accelerations) return st;
  return acceleration_from_factors(model, t, ws, sum);
}

}  // namespace detail

}  // namespace phiq
