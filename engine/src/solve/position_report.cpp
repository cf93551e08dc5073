// What a position solve reports: the statuses' names, PositionSummary::BriefReport(), and how well q is known in
// each coordinate's own unit (detail::locate_error(), known_to_text(), detail::report_rounding_rows()); and the
// check of the NewtonOptions it is given.
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

void detail::check_newton_options(const NewtonOptions& opt, const char* what) {
  // An infinite tolerance accepts any point as the solution, a NaN start_error accepts the start unchecked (and
  // reports NaN as its error): settings no solve can honour, each named by its field.
  auto fail = [&](const std::string& why) { throw Error(std::string(what) + ": " + why); };
  if (!(opt.tolerance > 0.0 && std::isfinite(opt.tolerance))) fail("tolerance must be > 0 and finite");
  if (opt.max_iterations < 0) fail("max_iterations must be >= 0");
  if (opt.max_backtracks < 0) fail("max_backtracks must be >= 0");
  if (!(opt.max_contraction > 0.0 && opt.max_contraction < 1.0)) fail("max_contraction must be in (0, 1)");
  if (std::isnan(opt.start_error)) fail("start_error must not be NaN (negative: unknown)");
  if (!(opt.known_to >= 0.0 && std::isfinite(opt.known_to))) fail("known_to must be >= 0 and finite");
  if (opt.jacobian_update != JacobianUpdate::kEveryIteration && opt.jacobian_update != JacobianUpdate::kWhenSlow)
    fail("jacobian_update is not a JacobianUpdate");
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
  // Any one pattern of signs may cancel where a few rows carry a coordinate (a pin's rows of 1, 3 and 2 ulps of
  // 5·10⁵ m along a four-bar's 10⁶ m links): three patterns (fixed hashes of the row), and the worst of them.
  constexpr std::uint32_t kHashes[] = {0x9E3779B1u, 0x85EBCA77u, 0xC2B2AE3Du};
  double* x = ws.rhs.data();  // (scratch of the derivative solves: at least n entries where Φq is square)
  f *= std::numeric_limits<double>::epsilon();
  for (const std::uint32_t hash : kHashes) {
    for (Index i = 0; i < f.size(); ++i) {
      const bool minus = ((static_cast<std::uint32_t>(i) * hash) >> 16) & 1u;
      f(i) = minus ? -std::fabs(f(i)) : std::fabs(f(i));
    }
    if (!(ws.lu && f.allFinite() && ws.lu->solve(solve_rhs(model, ws, f), x))) break;
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

void detail::report_rounding_rows(const Model& model, double tol, Index row, const Eigen::VectorXd& q,
                                  PositionSummary& sum) {
  const Index j = sum.error_coordinate;
  const double allowed = tol * model.tolerance_scales().coordinate_scale(j) + kUlpFloor * std::fabs(q(j));
  sum.error_estimate = std::max(sum.error_estimate, sum.error_size / allowed);
  if (!(sum.error_estimate > kQuietRoundingLevel)) return;
  sum.rounding_level = std::max(sum.rounding_level, sum.error_estimate);
  if (sum.slow_convergence) return;  // (a linear convergence says so already)
  sum.slow_convergence = true;
  // appended piece by piece: GCC 12 warns (-Wrestrict, a false positive) on a literal + std::string here
  std::string& m = sum.message;
  const char* const left_out =
      "' is at the rounding of its own terms (one ulp of each), which no Newton step resolves, and was left out of "
      "the steps: ";
  if (row >= 0)
    m.assign(1, '\'').append(model.row_name(row)).append(left_out);
  else
    m.assign(
        "rows whose terms are far larger than their tolerance (a badly scaled model) are known to one ulp of "
        "those terms: ");
  m.append(known_to_text(model, j, sum.error_size)).append(", which is how well q is known there");
}

}  // namespace phiq
