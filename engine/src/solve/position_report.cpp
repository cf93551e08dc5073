// What a position solve reports: the statuses' names, PositionSummary::BriefReport(), and how well q is known in
// each coordinate's own unit (detail::locate_error(), known_to_text()).
#include "phiq/kinematics.hpp"
#include "phiq/text.hpp"

#include "solve/factorisation.hpp"
#include "solve/kinematics_internal.hpp"
#include "solve/tolerance_tests.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>

namespace phiq {

const char* to_string(JacobianUpdate u) {
  return u == JacobianUpdate::kEveryIteration ? "every_iteration" : "when_slow";
}

const char* to_string(SolveStatus s) {
  switch (s) {
    case SolveStatus::kSuccess:
      return "success";
    case SolveStatus::kNotConverged:
      return "not converged";
    case SolveStatus::kSingularJacobian:
      return "singular Jacobian";
    case SolveStatus::kLinearSolverFailed:
      return "linear solver failed";
    case SolveStatus::kNonFinite:
      return "non-finite value";
    case SolveStatus::kNotSquare:
      return "not square";
    case SolveStatus::kOutsideTimeDomain:
      return "outside time domain";
    case SolveStatus::kCancelled:
      return "cancelled";
    case SolveStatus::kInconsistent:
      return "inconsistent redundant constraints";
    case SolveStatus::kPositionNotSolved:
      return "position not solved";
    case SolveStatus::kOutsideDomain:
      return "outside a constraint's domain";
  }
  return "?";
}

std::string PositionSummary::BriefReport() const {
  std::ostringstream s;
  s << "position: " << to_string(status) << ", " << iterations << " iterations, scaled residual "
    << scientific(residual, 3);
  if (!message.empty()) s << " (" << message << ")";
  return s.str();
}

std::string known_to_text(const std::string& name, double size, Unit unit) {
  const char* symbol = unit_symbol(unit);
  return "'" + name + "' known to ±" + significant(size, 2) + (*symbol ? " " : "") + symbol;
}

std::string known_to_text(const Model& model, Index j, double size) {
  return known_to_text(model.coordinate_names()[static_cast<std::size_t>(j)], size, model.coordinate_unit(j));
}

// The larger, in units of the tolerance test, of the last step's worst coordinate `j` (`estimate` there) and of
// what the rounding of q itself does to every coordinate. The step misses the latter: on a 10⁶ m coupler over a
// 1.5·10⁻⁶ m rocker, xB is held to its ulp (1.2·10⁻¹⁰ m, within its own test), and the rocker turns yB by as much,
// while Newton's steps in yB, from the rounding of Φ at that xB, are 10⁻¹⁵ m. That part is estimated as Φq⁻¹ f,
// f_i = ±ε Σ_j |∂Φ_i/∂q_j| |q_j|: one ulp of every coordinate through each row, with the factors at hand and Φq as
// last evaluated (at a point near q). One pass over Φq and one solve, only for the rows a sweep reports as known
// to more than 2 tolerances.
void detail::locate_error(const Model& model, double tol, double estimate, Index j, Workspace& ws, Index* where,
                          double* size_out) {
  const ToleranceScales& sc = model.tolerance_scales();
  const auto allowed = [&](Index c) { return tol * sc.coordinate_scale(c) + kUlpFloor * std::fabs(ws.q(c)); };
  double size = estimate * allowed(j);
  const CscPattern& p = model.jacobian_pattern();
  Eigen::VectorXd& f = ws.trial_phi;  // (scratch: the trial is done with)
  f.setZero();
  for (Index c = 0; c < p.cols; ++c)
    for (Index k = p.col_ptr[c]; k < p.col_ptr[c + 1]; ++k)
      f(p.row_idx[k]) += std::fabs(ws.jacobian_values[static_cast<std::size_t>(k)]) * std::fabs(ws.q(c));
  // Each row's rounding is its own: with one sign for all, f would be ε |q_j| times a column of Φq where one
  // coordinate dominates, and Φq⁻¹ f that coordinate's own ulp alone (the 10⁶ m xB moves, the rocker's yB not).
  // Signs that vary from row to row (a fixed hash of the row: the same bits on every thread count) keep them apart.
  for (Index i = 0; i < f.size(); ++i) {
    const bool minus = ((static_cast<std::uint32_t>(i) * 0x9E3779B1u) >> 16) & 1u;
    f(i) *= minus ? -std::numeric_limits<double>::epsilon() : std::numeric_limits<double>::epsilon();
  }
  double* x = ws.rhs.data();  // (scratch of the derivative solves: at least n entries where Φq is square)
  if (ws.lu && f.allFinite() && ws.lu->solve(solve_rhs(model, ws, f), x)) {
    double worst = size / allowed(j);
    for (Index c = 0; c < ws.q.size(); ++c) {
      const double e = std::fabs(x[c]);
      if (c == j) size = std::max(size, e), worst = size / allowed(j);
      if (e / allowed(c) > worst) worst = e / allowed(c), j = c, size = e;
    }
  }
  *where = j;
  *size_out = size;
}

}  // namespace phiq
