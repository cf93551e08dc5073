// Internal: Φq factorised at the workspace's position, shared by the position solve (kinematics.cpp) and the
// velocity and acceleration solves (derivatives.cpp): the workspace check, whether the factors or the Jacobian values
// are at (ws.q, t), the factorisation itself, the right-hand side the LU solves with, and the messages naming a
// non-square model or a derivative that does not exist. Separate so that each solve's file holds its own algorithm.
// The tests the Newton loop makes every iteration are inline here, as they were in its own file.
#pragma once

#include "phiq/kinematics.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace phiq::detail {

// Throws phiq::Error when `ws` was made for another model or its state or scratch was resized.
void check_workspace(const Model& model, const Workspace& ws);

// Why a model without an LU (ws.lu null) cannot be solved: its driven system is not square.
std::string not_square_message(const Model& model);

// The workspace's factors, or its Jacobian values, are Φq at exactly (ws.q, t) (the points they recorded).
inline bool factors_at_q(const Workspace& ws, double t) {
  return ws.has_factorization && ws.factorized_t == t && ws.factorized_q.size() == ws.q.size() &&
         ws.factorized_q == ws.q;
}
inline bool jacobian_values_at_q(const Workspace& ws, double t) {
  return ws.has_jacobian && ws.jacobian_t == t && ws.jacobian_q.size() == ws.q.size() && ws.jacobian_q == ws.q;
}

// Derivatives that do not exist. An equation's or a law's derivative can be infinite or NaN where its value is
// finite (√u or u^0.5 at u = 0; γ of u^1.5 there): the LU then finds Φq singular, or a solve gives NaN, and the
// failure read as a singular position or as a bare "velocity is not finite". These name the first such entry —
// looked for only once a factorisation or a solve has failed — so that the message says what it is.
inline constexpr const char* kNoDerivative =
    ", a derivative that does not exist at this position (as that of sqrt(u) or u^p, p < 1, at u = 0)";
// The first non-finite entry of Φq evaluated at (q, t), or "": for a failure after the factorisation (whose values
// may be gone).
std::string non_finite_jacobian_at(const Model& model, const double* q, double t);

// Factorises Φq at (ws.q, t) from ws.jacobian_values (evaluating them first unless `values_at_q`), and records
// that the factors are at time t (ws.factorized_q is the caller's to record).
SolveStatus factorize_at_q(const Model& model, double t, Workspace& ws, double* rcond, std::string* message,
                           bool values_at_q);

// Factorises Φq at (ws.q, t) unless the current factorisation was made exactly there. `values_at_q`: the caller
// knows ws.jacobian_values hold Φq at (ws.q, t) already (the Newton loop's fused evaluation).
SolveStatus ensure_factorized(const Model& model, double t, Workspace& ws, double* rcond, std::string* message,
                              bool values_at_q = false);

// Pins ws.lu's pivot order (SparseLuNumeric::pin_pivot_order) at Φq(q, t): a pivot search there, whatever ws
// factorised before, so that workspaces pinned at the same (q, t) refactorise alike from then on. Set-up, not
// counted (ws.counters are kept); ws.q is kept and ws starts afresh (start_afresh() then returns to the pinned
// order). Pins nothing, returning false, where Φq(q, t) is singular, for a library that always pivots, and for
// factors over kMaxPinnedBytes (the pinned factors are kept beside those of a later pivot search: at most twice
// the factors' memory, which a large model's threads are fitted to).
inline constexpr std::size_t kMaxPinnedBytes = std::size_t{256} << 20;
bool pin_pivot_order_at(const Model& model, Workspace& ws, const Eigen::VectorXd& q, double t);

// The right-hand side the LU solves with: `b` (one entry per equation) itself, or its kept rows for a model with
// dropped rows.
inline const double* solve_rhs(const Model& model, Workspace& ws, const Eigen::VectorXd& b) {
  if (model.dropped_rows().empty()) return b.data();
  const std::vector<Index>& rows = model.solve_rows();
  for (std::size_t i = 0; i < rows.size(); ++i) ws.solve_rhs(static_cast<Index>(i)) = b(rows[i]);
  return ws.solve_rhs.data();
}
inline const double* solve_rhs(const Model& model, Workspace& ws) { return solve_rhs(model, ws, ws.rhs); }

}  // namespace phiq::detail
