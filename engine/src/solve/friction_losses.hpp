// Internal: the losses that read the multipliers they change, in the efforts' solve: bearings' friction
// (TorsionalSpring::bearing) and transmissions' meshing losses (GearLoss), phiq/applied_loads.hpp.
//
// A bearing's moment m = μ (r |F_r| + r_a |F_a|) (a slide's force μ |F_r|) reads its joint's reaction, a mesh's loss
// m = (1 − η) |e_d| the effort e_d its row's multiplier exerts on the member it drives; the multipliers solve
// Φqᵀ λ = Q + Q_f(m), Q_f = −Σ m_i sign(θ̇_i) ∇θ_i: a fixed point. With λ0 the multipliers of Q alone,
// λ = λ0 + Φq⁻ᵀ Q_f(m) is linear in the moments, so each pass of the iteration m ← m(λ0 + Φq⁻ᵀ Q_f(m)) is one
// transposed solve with the row's own factors, the bearings' reactions (JointReactions on their joints only, their
// geometry kept for the row: JointReactions::keep_geometry()) and the meshes' multipliers. The pass contracts by about
// μ r / (the mechanism's lever arms), or 1 − η: a few passes for real bearings and gears. Where it does not settle,
// the loss feeds its own load faster than it gives it: the mechanism jams (self-locking), told at the row rather than
// written as a number. A bearing's direction is θ̇'s, fixed at the row; a mesh's driven member is the one its
// multiplier does positive work on (relative to the carrier), found at each pass. Not with redundant rows (the
// reactions and the meshes' shares are not unique); bearings not with gear meshes (their teeth's push on a bearing
// is not in its joint's multipliers: OutputEfforts::meshes).
#pragma once

#include <Eigen/Core>

#include <memory>
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

// What presses bearing `b` (its friction over μ: BearingFriction's moment or, on a slide, force) at its joint's
// reaction `f` in joint axes (Fx, Fy, Mz in the plane; Fx … Mz in space, z the joint's axis).
double bearing_load(const BearingFriction& b, const double* f, bool spatial);

class FrictionLosses {
 public:
  // The bearings of `loads`' torsional springs and its gear losses. Throws phiq::Error naming one whose joint or
  // transmission is unknown or cannot carry it (carries(), transmits()), or a model they cannot be solved in (above).
  FrictionLosses(const Model& model, const AppliedLoads& loads);
  // The losses `other` solves, its set-up (the bearings, the meshes, the bearings' joints) shared rather than found
  // again in the model, with scratch of its own: a sweep's chunks each solve on their own thread. Safe while `other`
  // solves on another thread (its set-up is not written after construction).
  static FrictionLosses with_set_up_of(const FrictionLosses& other) { return FrictionLosses(other, SetUpOnly{}); }
  // The constraint spring `s`'s bearing is; throws phiq::Error, naming `s`, where it is none or cannot be one.
  static Index check(const Model& model, const TorsionalSpring& s);
  // Throws phiq::Error, naming `who`, where `model` cannot solve a loss that reads its multipliers (redundant rows;
  // with `bearing`, gear meshes too).
  static void check_model(const Model& model, const std::string& who, bool bearing);
  // Whether a constraint of kind `kind` can be a bearing: a pin (turning about the plane's normal), a revolute or a
  // cylindrical joint (about its joint frame's z), a prismatic pair (a slide: along its x in the plane, its z in
  // space; a cylindrical one along its z too), whose joint axes put the load it carries across in x, y.
  static bool carries(std::string_view kind);
  // Whether a constraint of kind `kind` is a transmission with meshing losses (GearLoss).
  static bool transmits(std::string_view kind);
  // Why the efforts' ∂τ/∂p are refused with these losses (the scene's reader and the sweep say it alike).
  static constexpr const char* kNoSensitivities =
      "the efforts' sensitivities ∂τ/∂p are not computed with a bearing's friction or a gear's losses (they read the "
      "multipliers they change): ask them without those";
  // Whether `loads` has a bearing or a gear loss.
  static bool any(const AppliedLoads* loads);

  // At (q, q̇, t) with the row's factors: `lambda` in, the multipliers of `Q` (the parts' and loads'); out, those
  // with the losses, which are added to Q. False where a solve fails (failed_solve()) or the moments do not settle
  // in kMaxPasses (lock_message()); λ and Q then hold the last pass's.
  bool solve(const Model& model, SparseLuNumeric& lu, const double* q, const double* qd, double t, Eigen::VectorXd& Q,
             Eigen::VectorXd& lambda, Eigen::VectorXd& kept);
  // Loss i's values at the last solve() that settled, i in the scene's order (the torsional springs with a bearing,
  // then the gear losses: OutputLoss::index): the moment (a slide's force, a mesh's effort on its driven member) it
  // exerted against the motion, and the power it dissipated; both ≥ 0, zero at rest.
  double exerted(std::size_t i) const;
  double dissipated(std::size_t i) const;
  int solves() const { return solves_; }               // transposed solves of the last solve()
  bool failed_solve() const { return failed_solve_; }  // the last solve() failed in a linear solve
  std::string lock_message() const;                    // the loss that did not settle, and why

  static constexpr int kMaxPasses = 200;

 private:
  struct Bearing {
    const TorsionalSpring* spring = nullptr;
    std::size_t at = 0;  // its reaction's first value in the reactions' row
    bool spatial = false;
  };
  // A mesh: its row θ1 + k θ2 − (1 + k) θc − φ (the last of its constraint's), the loss 1 − η
  struct Mesh {
    const GearLoss* loss = nullptr;
    Slot member[2], carrier;
    double k = 1.0;
    Index row = 0;
    double eta[2] = {1.0, 1.0};  // the efficiency where member 0 (reverse), member 1 (forward) is driven
  };
  // A mesh at the row: each member's rate relative to the carrier, and the member driven at the last pass (−1:
  // none, no power through the mesh)
  struct MeshState {
    double rate[2] = {0.0, 0.0};
    int driven = -1;
  };
  // What construction finds, never written after it: shared by with_set_up_of()'s copies.
  struct SetUp {
    std::vector<Bearing> bearings;
    std::vector<Mesh> meshes;
  };
  struct SetUpOnly {};
  FrictionLosses(const FrictionLosses& other, SetUpOnly);
  void size_scratch();
  // m_i from the reactions and the meshes' multipliers at λ (bearings first, then meshes)
  void moments_at(const double* q, double t, const Eigen::VectorXd& lambda, std::vector<double>& m);
  std::string name(std::size_t i) const;  // loss i's, for a message

  std::shared_ptr<const SetUp> set_;
  std::optional<JointReactions> reactions_;  // the bearings' joints (none without bearings)
  std::vector<MeshState> mesh_states_;
  std::vector<double> values_, moments_, next_, rates_;
  std::vector<std::vector<double>> gradients_;
  Eigen::VectorXd lambda0_, q_f_, d_lambda_;
  int solves_ = 0, passes_ = 0;
  bool failed_solve_ = false;
  std::size_t worst_ = 0;  // the loss whose moment changed most at the last pass
  double worst_change_ = 0.0;
  double ratio_ = 0.0;  // the last pass's change over the one before
};

}  // namespace phiq::detail
