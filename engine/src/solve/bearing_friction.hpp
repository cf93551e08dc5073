// Internal: the bearings' frictions (TorsionalSpring::bearing, phiq/applied_loads.hpp) in the efforts' solve.
//
// A bearing's moment m = μ (r |F_r| + r_a |F_a|) (a slide's force μ |F_r|) reads its joint's reaction, which the
// multipliers give, while the multipliers solve Φqᵀ λ = Q + Q_f(m), Q_f = −Σ m_i sign(θ̇_i) ∇θ_i: a fixed point. With λ0
// the multipliers of Q alone, λ = λ0 + Φq⁻ᵀ Q_f(m) is linear in the moments, so each pass of the iteration m ← m(λ0 +
// Φq⁻ᵀ Q_f(m)) is one transposed solve with the row's own factors and the bearings' reactions (JointReactions on their
// joints only, their geometry kept for the row: JointReactions::keep_geometry()). The pass contracts by about μ r /
// (the mechanism's lever arms): a few passes for real bearings. Where it does not settle, the friction feeds its own
// load faster than it gives it: the mechanism jams (self-locking), told at the row rather than written as a number. The
// friction's direction is θ̇'s, fixed at the row, so the moments alone iterate. Not with redundant rows (the reactions
// it reads are not unique) nor with gear meshes (their teeth's push on a bearing is not in its joint's multipliers:
// OutputEfforts::meshes).
#pragma once

#include <Eigen/Core>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "phiq/applied_loads.hpp"
#include "phiq/joint_reactions.hpp"

namespace phiq {
class Model;
class SparseLuNumeric;
}  // namespace phiq

namespace phiq::detail {

class BearingFrictions {
 public:
  // The bearings of `loads`' torsional springs. Throws phiq::Error naming one whose joint is unknown or cannot be a
  // bearing (carries()), or one whose kind of friction its joint's is not, or a model they cannot be solved in
  // (above).
  BearingFrictions(const Model& model, const AppliedLoads& loads);
  // The constraint spring `s`'s bearing is; throws phiq::Error, naming `s`, where it is none or cannot be one.
  static Index check(const Model& model, const TorsionalSpring& s);
  // Throws phiq::Error, naming `s`, where `model` cannot solve a bearing's friction (above).
  static void check_model(const Model& model, const TorsionalSpring& s);
  // Whether a constraint of kind `kind` can be a bearing: a pin (turning about the plane's normal), a revolute or a
  // cylindrical joint (about its joint frame's z), a prismatic pair (a slide: along its x in the plane, its z in
  // space; a cylindrical one along its z too), whose joint axes put the load it carries across in x, y.
  static bool carries(std::string_view kind);
  // Whether `loads` has a bearing.
  static bool any(const AppliedLoads* loads);

  // At (q, q̇, t) with the row's factors: `lambda` in, the multipliers of `Q` (the parts' and loads'); out, those
  // with the bearings' friction, which is added to Q. False where a solve fails (failed_solve()) or the moments do
  // not settle in kMaxPasses (lock_message()); λ and Q then hold the last pass's.
  bool solve(const Model& model, SparseLuNumeric& lu, const double* q, const double* qd, double t, Eigen::VectorXd& Q,
             Eigen::VectorXd& lambda, Eigen::VectorXd& kept);
  int solves() const { return solves_; }               // transposed solves of the last solve()
  bool failed_solve() const { return failed_solve_; }  // the last solve() failed in a linear solve
  std::string lock_message() const;                    // the bearing that did not settle, and why

  static constexpr int kMaxPasses = 200;

 private:
  struct Bearing {
    const TorsionalSpring* spring = nullptr;
    std::size_t at = 0;  // its reaction's first value in the reactions' row
    bool spatial = false;
  };
  // m_i from the reactions at λ
  void moments_at(const double* q, double t, const Eigen::VectorXd& lambda, std::vector<double>& m);

  std::vector<Bearing> bearings_;
  std::optional<JointReactions> reactions_;
  std::vector<double> values_, moments_, next_, rates_;
  std::vector<std::vector<double>> gradients_;
  Eigen::VectorXd lambda0_, q_f_, d_lambda_;
  int solves_ = 0, passes_ = 0;
  bool failed_solve_ = false;
  std::size_t worst_ = 0;  // the bearing whose moment changed most at the last pass
  double worst_change_ = 0.0;
  double ratio_ = 0.0;  // the last pass's change over the one before
};

}  // namespace phiq::detail
