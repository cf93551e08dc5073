// Why a drive step cannot be taken once its sub-steps have failed, besides a dead point (singular_positions.cpp):
// the time ahead is outside a law's or an equation's domain (undefined_at()), or redundant equations that held
// where the model was assembled part there (conflicting_redundancy()). Run only on that failure path
// (Sweeper::advance()), to name the cause in the message.
#include "sweep/sweeper.hpp"

#include "phiq/text.hpp"
#include "solve/factorisation.hpp"

namespace phiq::detail {

// Why the sweep cannot go on towards t1, when a driver's law or a rheonomic equation is not defined there
// (√(1 − t) beyond t = 1, exp(t) past the largest double): at the last converged position, whose rows were all
// finite, only rows that depend on t can turn non-finite at t1; the first is named. "" otherwise (ws.phi is
// scratch).
std::string Sweeper::undefined_at(double t1) {
  model_.residual(current_.q.data(), t1, ws_->phi.data());
  for (Index i = 0; i < ws_->phi.size(); ++i)
    if (!std::isfinite(ws_->phi(i))) {
      std::string why = "'";  // appended, not "'" + …: GCC 12 warns falsely on that here (-Wrestrict, PR 105329)
      why += model_.row_name(i);
      why += "' is not finite at t = ";
      why += format_time(t1);
      why += " (its law or equation is not defined there, or overflows)";
      return why;
    }
  return "";
}

// Why the sweep cannot go on towards t1, when it is redundant equations that stop holding: the model is solved on
// its independent rows (Model::without_rows), chosen where it was assembled, and the rows left out, consistent
// there, are checked at every step. Two drivers of one coordinate at different rates, or two joint drivers of
// one door, agree at the start and part at once. Newton on the independent rows alone, from the last state (full
// steps with the square LU, a few iterations), tells: where they hold and some left-out row does not, those rows
// are named. "" otherwise. A diagnosis after the sub-steps failed: it leaves ws.q, ws.qd as scratch.
std::string Sweeper::conflicting_redundancy(double t1) {
  const std::vector<Index>& dropped = model_.dropped_rows();
  if (dropped.empty() || !ws_->lu) return "";
  const double tol = opt_.newton.tolerance;
  const Eigen::VectorXd& rs = model_.tolerance_scales().row_scale;
  const std::vector<Index>& kept = model_.solve_rows();
  auto holds = [&](Index i) { return detail::row_within(model_, i, std::fabs(ws_->phi(i)) / rs(i), tol, ws_->q, t1); };
  ws_->q = current_.q;
  Eigen::VectorXd rhs(static_cast<Index>(kept.size())), step(model_.num_coordinates());
  bool kept_hold = false;
  for (int it = 0; it < 10 && !kept_hold; ++it) {
    model_.residual(ws_->q.data(), t1, ws_->phi.data());
    if (!ws_->phi.allFinite()) return "";
    kept_hold = std::all_of(kept.begin(), kept.end(), holds);
    if (kept_hold) break;
    double rcond = 0.0;  // the factorisation at ws.q (not a solved position: no velocity there)
    std::string why;
    if (detail::ensure_factorized(model_, t1, *ws_, &rcond, &why) != SolveStatus::kSuccess) return "";
    for (std::size_t k = 0; k < kept.size(); ++k) rhs(static_cast<Index>(k)) = ws_->phi(kept[k]);
    if (!ws_->lu->solve(rhs.data(), step.data()) || !step.allFinite()) return "";
    ws_->q -= step;
  }
  if (!kept_hold) return "";
  std::vector<std::string> names;
  for (Index i : dropped)
    if (!holds(i)) {
      const std::string name = model_.row_name(i);
      if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
    }
  if (names.empty()) return "";
  std::ostringstream m;
  m << "redundant equations, consistent where the model was assembled, stop holding where the others hold (";
  for (std::size_t k = 0; k < names.size() && k < 8; ++k) m << (k ? ", '" : "'") << names[k] << "'";
  if (names.size() > 8) m << " and " << names.size() - 8 << " more";
  m << "): the redundant constraints are inconsistent from here on";
  return m.str();
}

}  // namespace phiq::detail
