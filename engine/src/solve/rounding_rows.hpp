// Internal: the rows of Φ that are at the rounding of their own terms, which the position solve leaves out of its
// Newton steps and its merit (kinematics.cpp). Not installed.
//
// Why: a row's value cannot be resolved below the rounding of the terms it adds. On a four-bar of a 10⁶ m ground and
// coupler over a 10⁻⁶ m crank in reference-point coordinates, the rocker's pin row x4 − L4/2 cos ψ4 − L1 is a
// multiple of an ulp of 10⁶ m (1.2·10⁻¹⁰ m) whatever ψ4 is, 10⁻⁴ of the rocker's 7.5·10⁻⁷ m arm. A Newton step that
// "corrects" it turns ψ4 by up to 10⁻⁴ rad at random, which leaves the rocker's other pin row 10⁻⁹ of its scale
// off (second order in that turn): it never meets the tolerance, and Newton runs out of iterations. Left out, the
// row keeps its rounding (the step holds its linearisation), and the other rows converge as Newton does.
//
// A row i is at its rounding when 0 < |Φ_i| ≤ ε Σ_j |∂Φ_i/∂q_j| |q_j|, one ulp of every term the row reads (every
// constraint kind derives it from its own Jacobian; Model::row_rounding_floor() is 64 of them), and the Newton step
// to the iterate did not halve it: that bound counts terms that cancel exactly (a natural point's xB − L1 near
// 10⁶ m is exact, its row resolved through yB far below it), and such a row still falls quadratically. Such rows
// are left out only where some row's rounding exceeds its tolerance, tol · scale_i: then a row below its own tolerance
// may still be noise that turns a short link (a coupler pin's 2·10⁻¹¹ m, far within tol · 5·10⁵ m, turned the rocker by
// 2·10⁻⁵ rad). On a well-scaled model (terms within 10⁵ of the rows' scales at the default tolerance) no row is left
// out, and the solve is the same to the bit.
#pragma once

#include "phiq/model.hpp"

#include <vector>

namespace phiq::detail {

// |Φ_i| ≤ ε Σ_j |∂Φ_i/∂q_j| |q_j| at (q, t): the row's value is the rounding of its terms (false on NaN).
bool row_at_rounding(const Model& model, Index row, double phi, const Eigen::VectorXd& q, double t);

// The rows at their rounding at one iterate of a position solve, and the scratch to leave them out.
class RoundingRows {
 public:
  bool empty() const { return rows_.empty(); }
  // Some iterate of this solve was badly scaled (find()): how well q is known is then the rows' rounding carried
  // through Φq⁻¹, whether or not a row was left out.
  bool seen() const { return seen_; }
  // The worst of them (by |Φ_i| / scale_i) where they were last found, −1 before.
  Index named() const { return named_; }
  // Finds them at q from Φ there and Φq's values as last evaluated (`jacobian_values`, near q), where the model is
  // badly scaled at q (some row's rounding exceeds its tolerance; otherwise none: the solve is the same to the bit),
  // and that the step to this iterate (`iteration`, counted by the solve) did not halve.
  // `terms`: m doubles of scratch. Returns whether the kept rows' measures must be taken again (the set is or was
  // not empty).
  bool find(const Model& model, const Eigen::VectorXd& phi, const std::vector<double>& jacobian_values,
            const Eigen::VectorXd& q, double tol, double* terms, int iteration);
  // `phi` with the rows set to 0 (in scratch owned here). Pre-condition: !empty().
  const Eigen::VectorXd& without(const Eigen::VectorXd& phi);
  // Whether the merit of `trial_phi` (at `trial_q`) is at most `factor` times that of `phi`, both without the rows
  // at their rounding here or at the trial: a step that corrects the other rows moves such a row by an ulp of its
  // terms, 10⁴ times their merit. False where no row is at its rounding (the plain test said it all).
  bool decrease_apart_from_rounding(const Model& model, const Eigen::VectorXd& phi, const Eigen::VectorXd& trial_phi,
                                    const Eigen::VectorXd& trial_q, double tol, double t, double factor);
  // The merit ½ Σ (Φ_i / scale_i)² and max |Φ_i| / scale_i over the other rows (all rows when empty()).
  void kept_measures(const Model& model, const Eigen::VectorXd& phi, double* merit, double* worst) const;

 private:
  std::vector<Index> rows_;
  std::vector<char> is_row_;  // one flag per row, sized once a row is found
  Eigen::VectorXd kept_;
  Eigen::VectorXd previous_;  // Φ at the iterate before, where the model was badly scaled there
  bool has_previous_ = false;
  int iteration_ = -1;
  std::vector<Index> trial_rows_;  // decrease_apart_from_rounding()'s rows at their rounding at the trial
  bool seen_ = false;
  Index named_ = -1;
};

}  // namespace phiq::detail
