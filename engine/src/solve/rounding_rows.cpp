// The rows at the rounding of their own terms (rounding_rows.hpp).
#include "solve/rounding_rows.hpp"

#include "phiq/kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace phiq::detail {

bool row_at_rounding(const Model& model, Index row, double phi, const Eigen::VectorXd& q, double t) {
  // row_rounding_floor() is kUlpFloor (64 ulps) times the terms' sum: one ulp of each is ε times it
  constexpr double kOneUlp = std::numeric_limits<double>::epsilon() / ToleranceScales::kUlpFloor;
  return std::fabs(phi) <= kOneUlp * model.row_rounding_floor(row, q.data(), t);
}

bool RoundingRows::find(const Model& model, const Eigen::VectorXd& phi, const std::vector<double>& jacobian_values,
                        const Eigen::VectorXd& q, double tol, double* terms, int iteration) {
  if (iteration == iteration_) return false;  // the same iterate again (a reused matrix refreshed): the same rows
  iteration_ = iteration;
  const bool had = !rows_.empty();
  for (Index i : rows_) is_row_[static_cast<std::size_t>(i)] = 0;
  rows_.clear();
  const Index m = phi.size();
  if (m == 0) return had;
  // terms_i = ε Σ_j |∂Φ_i/∂q_j| |q_j|, with Φq as last evaluated (near q: its magnitudes are what counts)
  const CscPattern& p = model.jacobian_pattern();
  std::fill(terms, terms + m, 0.0);
  for (Index c = 0; c < p.cols; ++c)
    for (Index k = p.col_ptr[c]; k < p.col_ptr[c + 1]; ++k)
      terms[p.row_idx[k]] += std::fabs(jacobian_values[static_cast<std::size_t>(k)]) * std::fabs(q(c));
  constexpr double eps = std::numeric_limits<double>::epsilon();
  const Eigen::VectorXd& rs = model.tolerance_scales().row_scale;
  // Some row's rounding exceeds its tolerance, and the default one: the model is badly scaled at q. (Below the
  // default, a tolerance asks for less than the rounding of a well-scaled model, whose rows all still fall with
  // Newton's steps: a 2000-stage scissor lift at 10⁻¹⁶; the stop at the rounding level deals with that.)
  const double level = std::max(tol, NewtonOptions{}.tolerance);
  bool prone = false;
  for (Index i = 0; i < m && !prone; ++i) prone = eps * terms[i] > level * rs(i);
  if (!prone) {
    has_previous_ = false;
    return had;
  }
  seen_ = true;
  Index top = -1;
  double top_scaled = -1.0;
  for (Index i = 0; i < m && has_previous_; ++i) {
    // within one ulp of its terms, and not halved by the step that led here (a row with a real error falls
    // quadratically; one at its rounding stays there, or jumps by an ulp of its terms)
    const double a = std::fabs(phi(i));
    if (!(a > 0.0 && a <= eps * terms[i] && a >= 0.5 * std::fabs(previous_(i)))) continue;
    rows_.push_back(i);
    if (a / rs(i) > top_scaled) top_scaled = a / rs(i), top = i;
  }
  previous_ = phi;
  has_previous_ = true;
  if (rows_.empty()) return had;
  if (is_row_.empty()) is_row_.assign(static_cast<std::size_t>(m), 0);
  for (Index i : rows_) is_row_[static_cast<std::size_t>(i)] = 1;
  named_ = top;
  return true;
}

const Eigen::VectorXd& RoundingRows::without(const Eigen::VectorXd& phi) {
  kept_ = phi;
  for (Index i : rows_) kept_(i) = 0.0;
  return kept_;
}

bool RoundingRows::decrease_apart_from_rounding(const Model& model, const Eigen::VectorXd& phi,
                                                const Eigen::VectorXd& trial_phi, const Eigen::VectorXd& trial_q,
                                                double tol, double t, double factor) {
  const Eigen::VectorXd& rs = model.tolerance_scales().row_scale;
  const Eigen::VectorXd& inv = model.tolerance_scales().inverse_row_scale;
  trial_rows_.clear();
  for (Index i = 0; i < trial_phi.size(); ++i)
    if (std::fabs(trial_phi(i)) > tol * rs(i) && row_at_rounding(model, i, trial_phi(i), trial_q, t))
      trial_rows_.push_back(i);
  if (trial_rows_.empty() && rows_.empty()) return false;
  double before = 0.0, after = 0.0;
  std::size_t next = 0;  // trial_rows_ ascend
  for (Index i = 0; i < phi.size(); ++i) {
    if (next < trial_rows_.size() && trial_rows_[next] == i) {
      ++next;
      continue;
    }
    if (!rows_.empty() && is_row_[static_cast<std::size_t>(i)]) continue;
    const double a = std::fabs(phi(i)) * inv(i), b = std::fabs(trial_phi(i)) * inv(i);
    before += a * a, after += b * b;
  }
  return after <= factor * before;
}

void RoundingRows::kept_measures(const Model& model, const Eigen::VectorXd& phi, double* merit, double* worst) const {
  const Eigen::VectorXd& inv = model.tolerance_scales().inverse_row_scale;
  double sum = 0.0, top = 0.0;
  for (Index i = 0; i < phi.size(); ++i) {
    if (!rows_.empty() && is_row_[static_cast<std::size_t>(i)]) continue;
    const double s = std::fabs(phi(i)) * inv(i);
    sum += s * s;
    top = top < s ? s : top;
  }
  *merit = 0.5 * sum;
  *worst = top;
}

}  // namespace phiq::detail
