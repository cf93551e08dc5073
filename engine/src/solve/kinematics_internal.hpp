// Internal to the engine: what the sweep needs of the kinematic solves (kinematics.cpp, factorisation.cpp,
// derivatives.cpp) beyond the public functions.
#pragma once

#include "phiq/kinematics.hpp"

namespace phiq::detail {

// A stop at the rounding level with q known to within this many tolerances is no slow convergence (no warning);
// a sweep's row known to more is counted at the rounding level (SweepAccuracy).
constexpr double kQuietRoundingLevel = 2.0;

/// How the message of a kNonFinite from a derivative that does not exist at the position begins ("Φq is not
/// finite: ∂'c'/∂'x' = -inf, …"): the sweep then names no other cause.
inline constexpr const char* kNonFiniteJacobian = "Φq is not finite: ";

/// Below this reciprocal condition estimate of Φq, a position Newton reached only linearly is examined as a
/// singular one by the sweep (a dead point: Sweeper::derivatives()); solve_position ends no solve within
/// NewtonOptions::known_to there, so that such a position keeps its mark of linear convergence.
inline constexpr double kLinearSingularRcond = 1e-4;

/// The values of ws.jacobian_values that the LU factorises: all of them, or the kept rows' (in ws.solve_values)
/// for a model with dropped rows (Model::without_rows()).
const double* solve_values(const Model& model, Workspace& ws);

/// Throws phiq::Error naming the first field of `opt` no solve can honour, after `what` (solve_position's check,
/// also made by a sweep before it starts, so that bad drive settings are refused before the assembly, not on a
/// worker thread).
void check_newton_options(const NewtonOptions& opt, const char* what = "NewtonOptions");

/// solve_velocity and, with `accelerations`, solve_acceleration at the position solve_position has just converged
/// to at t. Pre-condition (the sweep's own sequence, not checked): ws.q has not changed since that solve returned
/// kSuccess. The factorisation or the Jacobian values that solve reported valid at its solution are taken as they
/// are, without the public functions' comparison of points (two O(n) passes, and a copy of q, per drive step);
/// a factorisation made here does not record its point (factorized_t is NaN), so that a later public call, or the
/// end of the next solve_position at this t, factorises again. Same
/// statuses and summary as the public functions (the summary of the last solve made).
SolveStatus derivatives_at_solution(const Model& model, double t, Workspace& ws, bool accelerations,
                                    LinearSummary* summary);

// How well q is known, in a coordinate's own unit, at a solve whose error estimate is `estimate` tolerances at its
// worst coordinate `j` (position_report.cpp): *where and *size, PositionSummary::error_coordinate and error_size.
// Uses ws.trial_phi and ws.rhs as scratch. Pre-condition: 0 ≤ j < n; ws.q the solution.
void locate_error(const Model& model, double tol, double estimate, Index j, Workspace& ws, Index* where, double* size);

// A solve that left rows at the rounding of their own terms out of its steps (rounding_rows.hpp), `row` the worst
// of them, and whose error locate_error() has just placed: q is known to that, in tolerances at least, and above
// the quiet level it is said as a stop at the rounding level is (slow_convergence, rounding_level, message).
void report_rounding_rows(const Model& model, double tol, Index row, const Eigen::VectorXd& q, PositionSummary& sum);

}  // namespace phiq::detail
