// Φq factorised at the workspace's position, for the position solve and the velocity and acceleration solves
// (declared in factorisation.hpp): the workspace check, the kept rows' values for a model with dropped rows, the
// factorisation with its messages, and the search for the entry of Φq that makes it fail when one does not exist.
#include "solve/factorisation.hpp"

#include "phiq/text.hpp"
#include "solve/kinematics_internal.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace phiq {

void detail::check_workspace(const Model& model, const Workspace& ws) {
  if (&ws.model() != &model) throw Error("workspace was made for another model");
  const Index n = model.num_coordinates();
  if (ws.q.size() != n || ws.qd.size() != n || ws.qdd.size() != n)
    throw Error("workspace state has the wrong size (q, qd, qdd must have " + std::to_string(n) + " entries)");
  // The scratch is public (the sweep and tests read it) and sized by the constructor: resized by a caller, the solves
  // wrote past its end (heap corruption, an abort in free()). Checked with the state, in O(1).
  const Index m = model.num_equations(), solve_rows = model.dropped_rows().empty() ? 0 : model.num_solve_rows();
  if (ws.phi.size() != m || ws.rhs.size() != m || ws.trial_phi.size() != m || ws.step.size() != n ||
      ws.trial.size() != n || static_cast<Index>(ws.jacobian_values.size()) != model.jacobian_pattern().nnz() ||
      ws.solve_values.size() != model.solve_entries().size() || ws.solve_rhs.size() != solve_rows)
    throw Error(
        "workspace scratch has the wrong size (phi, rhs, step, trial, trial_phi, jacobian_values, "
        "solve_values, solve_rhs keep the sizes the Workspace was made with)");
}

const double* detail::solve_values(const Model& model, Workspace& ws) {
  if (model.dropped_rows().empty()) return ws.jacobian_values.data();
  const std::vector<Index>& from = model.solve_entries();  // the kept rows only (Model::without_rows())
  for (std::size_t k = 0; k < from.size(); ++k)
    ws.solve_values[k] = ws.jacobian_values[static_cast<std::size_t>(from[k])];
  return ws.solve_values.data();
}

std::string detail::not_square_message(const Model& model) {
  std::string s = "the model has " + std::to_string(model.num_solve_rows()) + " equations for " +
                  std::to_string(model.num_coordinates()) + " coordinates";
  if (!model.dropped_rows().empty())
    s += " (after leaving out " + std::to_string(model.dropped_rows().size()) + " redundant rows)";
  return s + "; the driven system must be square (assemble() and analyse_rank() handle other models)";
}

namespace {

// The first non-finite entry of Φq's values (in the solve pattern: `values` as factorised), or "".
std::string non_finite_jacobian(const Model& model, const double* values) {
  const CscPattern& p = model.solve_pattern();
  for (Index j = 0; j < p.cols; ++j)
    for (Index k = p.col_ptr[static_cast<std::size_t>(j)]; k < p.col_ptr[static_cast<std::size_t>(j) + 1]; ++k)
      if (!std::isfinite(values[k])) {
        const Index r = p.row_idx[static_cast<std::size_t>(k)];
        const Index row = model.dropped_rows().empty() ? r : model.solve_rows()[static_cast<std::size_t>(r)];
        return std::string(detail::kNonFiniteJacobian) + "∂'" + model.row_name(row) + "'/∂'" +
               model.coordinate_names()[static_cast<std::size_t>(j)] + "' = " + significant(values[k], 3) +
               detail::kNoDerivative;
      }
  return "";
}

}  // namespace

std::string detail::non_finite_jacobian_at(const Model& model, const double* q, double t) {
  std::vector<double> values(static_cast<std::size_t>(model.jacobian_pattern().nnz()));
  model.jacobian(q, t, values.data());
  if (model.dropped_rows().empty()) return non_finite_jacobian(model, values.data());
  std::vector<double> kept(model.solve_entries().size());
  for (std::size_t k = 0; k < kept.size(); ++k) kept[k] = values[static_cast<std::size_t>(model.solve_entries()[k])];
  return non_finite_jacobian(model, kept.data());
}

SolveStatus detail::factorize_at_q(const Model& model, double t, Workspace& ws, double* rcond, std::string* message,
                                   bool values_at_q) {
  ws.has_factorization = false;
  ws.factorized_solves_to = std::numeric_limits<double>::quiet_NaN();
  if (!values_at_q) {
    model.jacobian(ws.q.data(), t, ws.jacobian_values.data());
    ++ws.counters.jacobian_evaluations;
  }
  ws.has_jacobian = false;
  const double* values = detail::solve_values(model, ws);
  const std::int64_t pivoting_before = ws.lu->pivoting_factorizations();
  FactorStatus fs = ws.lu->factorize(values);
  ++ws.counters.factorizations;
  if (ws.lu->pivoting_factorizations() != pivoting_before) ++ws.counters.pivoting_factorizations;
  *rcond = ws.lu->rcond();
  if (fs != FactorStatus::kOk || !(*rcond > 0.0)) {  // a non-finite entry makes the factors fail or rcond 0
    std::string why = non_finite_jacobian(model, values);
    if (!why.empty()) {
      *message = std::move(why);
      return SolveStatus::kNonFinite;
    }
  }
  if (fs == FactorStatus::kFailed) {
    *message = "sparse LU failed: " + ws.lu->last_message();
    return SolveStatus::kLinearSolverFailed;
  }
  if (fs == FactorStatus::kSingular) {
    *message = "Jacobian is singular (a zero pivot): singular position, or redundant or missing constraints";
    return SolveStatus::kSingularJacobian;
  }
  ws.factorized_t = t;
  ws.has_factorization = true;
  return SolveStatus::kSuccess;
}

bool detail::pin_pivot_order_at(const Model& model, Workspace& ws, const Eigen::VectorXd& q, double t) {
  check_workspace(model, ws);
  if (!ws.lu) return false;
  const WorkCounters kept = ws.counters;
  Eigen::VectorXd held = q;
  ws.q.swap(held);
  ws.lu->unpin_pivot_order();
  ws.start_afresh();
  double rcond = 0.0;
  std::string message;
  const bool pinned = factorize_at_q(model, t, ws, &rcond, &message, false) == SolveStatus::kSuccess &&
                      ws.lu->memory_bytes() <= kMaxPinnedBytes && ws.lu->pin_pivot_order();
  ws.q.swap(held);
  ws.counters = kept;
  ws.start_afresh();
  return pinned;
}

SolveStatus detail::ensure_factorized(const Model& model, double t, Workspace& ws, double* rcond, std::string* message,
                                      bool values_at_q) {
  if (!ws.lu) {
    *message = not_square_message(model);
    return SolveStatus::kNotSquare;
  }
  if (factors_at_q(ws, t)) {
    *rcond = ws.lu->rcond();
    return SolveStatus::kSuccess;
  }
  // Φq may have been evaluated with Φ at this very point by the Newton loop (NewtonOptions::jacobian_with_residual):
  // known to the loop itself, or left by the last solve_position for the velocity solve that follows it
  values_at_q = values_at_q || jacobian_values_at_q(ws, t);
  const SolveStatus st = factorize_at_q(model, t, ws, rcond, message, values_at_q);
  if (st == SolveStatus::kSuccess) ws.factorized_q = ws.q;
  return st;
}

}  // namespace phiq
