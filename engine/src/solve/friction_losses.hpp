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
// multiplier does positive work on (relative to the carrier), found at each pass. A bearing at a natural point (a
// planar point two bodies' frames share) reads the point's reaction, their balance there (phiq/natural_joints.hpp),
// evaluated whole at each pass; its angle must be of coordinates (segment angles), whose multipliers carry its
// moment to its bodies, not of the points. Not with redundant rows (the
// reactions and the meshes' shares are not unique); bearings not with gear meshes (their teeth's push on a bearing
// is not in its joint's multipliers: OutputEfforts::meshes).
#pragma once

#include <Eigen/Core>

#include <array>
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
// Its derivative along each of f's values, into d[0, 6) (zero where a magnitude it reads is zero).
void bearing_load_gradient(const BearingFriction& b, const double* f, bool spatial, double* d);

class FrictionLosses {
 public:
  // The bearings of `loads`' torsional springs and its gear losses. Throws phiq::Error naming one whose joint or
  // transmission is unknown or cannot carry it (carries(), transmits()), or a model they cannot be solved in (above).
  // `efforts`, when given, holds the natural joints a bearing may name (a point two bodies' frames share, planar: its
  // reaction is their balance at the point, phiq/natural_joints.hpp) with the parts and loads that balance reads.
  FrictionLosses(const Model& model, const AppliedLoads& loads, const OutputEfforts* efforts = nullptr);
  // Whether a bearing of `loads` names no constraint of `model` (a natural point: its reaction reads Q in the frames'
  // motion's form, which a sweep's Q must then take).
  static bool at_points(const Model& model, const AppliedLoads* loads);
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
  // Whether `loads` has a bearing or a gear loss.
  static bool any(const AppliedLoads* loads);

  // At (q, q̇, t) with the row's factors: `lambda` in, the multipliers of `Q` (the parts' and loads'); out, those
  // with the losses, which are added to Q. False where a solve fails (failed_solve()) or the moments do not settle
  // in kMaxPasses (lock_message()); λ and Q then hold the last pass's.
  // q̈ is read by a natural point's bearing only (its bodies' inertia), and may be null without one.
  bool solve(const Model& model, SparseLuNumeric& lu, const double* q, const double* qd, const double* qdd, double t,
             Eigen::VectorXd& Q, Eigen::VectorXd& lambda, Eigen::VectorXd& kept);
  // Loss i's values at the last solve() that settled, i in the scene's order (the torsional springs with a bearing,
  // then the gear losses: OutputLoss::index): the moment (a slide's force, a mesh's effort on its driven member) it
  // exerted against the motion, and the power it dissipated; both ≥ 0, zero at rest.
  double exerted(std::size_t i) const;
  double dissipated(std::size_t i) const;
  // The efforts' sensitivities with the losses (phiq/effort_sensitivity.hpp), at the last solve() that settled, its
  // directions and driven members held. λ solves R = Φqᵀ λ − Q − Q_f(λ, q, p) = 0, so dλ_r/dp = −w̃ᵀ dR/dp|λ with
  // (Φq − (∂Q_f/∂λ)ᵀ) w̃ = e_r: adjoint() turns w = Φq⁻¹ e_r into w̃ by the passes w̃ = w + Φq⁻¹ (∂Q_f/∂λ)ᵀ w̃, which
  // contract as solve()'s did (∂Q_f/∂λ = Σ_i u_i ∂m_i/∂λ, u_i the loss's direction in Q, m_i reading the reaction
  // of its joint, kept per unit multiplier, or at a natural point its body's balance, affine in its own constraints'
  // multipliers: JointReactions::natural_force_rows()). False where a solve fails or the passes do not settle.
  bool adjoint(SparseLuNumeric& lu, Eigen::VectorXd& w);
  // The bearings' joints in the four models along a design parameter (at p + kShift[k] h), where it reaches them:
  // at[k][i] bearing i's constraint there (its block null where p does not reach it or its load does not read it).
  // A mesh's data in a model along the parameter, where it reaches the mesh's constraint.
  struct MeshAlong {
    bool moved = false;
    double k = 1.0, tan_lead = 0.0, cos_pressure = 1.0;  // Mesh's
  };
  struct JointsAlong {
    const ParameterReach* reach = nullptr;                      // the parameter's (its identity)
    std::array<std::vector<JointReactions::BlockAt>, 4> at;     // empty: p reaches no bearing's joint
    std::array<std::vector<MeshAlong>, 4> meshes;               // empty: p reaches no mesh
    std::vector<std::shared_ptr<const ConstraintBlock>> owned;  // the constraints moved along their data's rates
    // natural points' bearings: their reactions as the models along p hold their bodies (their parts, loads and own
    // constraints there); null without natural bearings
    std::array<std::shared_ptr<JointReactions>, 4> natural;
    // what each model's reactions (natural[k], else the losses' own) read there instead of the model's constraints
    std::array<JointReactions::Along, 4> along;
  };
  // Parameter p's (its reach known), found once per parameter and kept; null where p reaches no bearing's joint and
  // no mesh.
  // Pre-condition: sensitivity_refusal() passed for p (else phiq::Error).
  const JointsAlong* joints_along(const Model& model, const OutputSensitivity& p);
  // dQ_f/dp at fixed λ into `out`: along the motion v by Q_f at q + kShift[k] e v, and along p by the losses' data in
  // `along` (the scene's loads at p + kShift[k] h, in order; null: the loads' own, or all null: none) and the
  // bearings' joints in `joints` (null: none reached) at q with the co-moving coordinates `moved` (same as q but
  // where p moves them), each by the fourth-order central difference.
  // `sd`, `sdd`: q̇'s and q̈'s rates along p (with v), which a natural point's reaction reads (may be null without).
  void force_rate(const double* q, double t, const Eigen::VectorXd& lambda, const Eigen::VectorXd& v, double e,
                  const std::array<const AppliedLoads*, 4>& along, const JointsAlong* joints,
                  const std::array<Eigen::VectorXd, 4>* moved, double h, Eigen::VectorXd& out,
                  const double* sd = nullptr, const double* sdd = nullptr);
  // Why the efforts' sensitivities to `p` (its reach known) are refused with these losses, else empty: p changes a
  // loss's constraint (or a natural point's bearing's bodies' own) where its copies along p are not kept and its
  // kind cannot move its data along their rates (ConstraintBlock::data_moved()), or the bodies a natural point's
  // bearing reads change with p.
  std::string sensitivity_refusal(const Model& model, const OutputSensitivity& p) const;
  // The status a solve() that returned false stands for, its message into `message` (when not null): the linear
  // solve's failure (`lu`'s) or the lock.
  SolveStatus failure(const SparseLuNumeric& lu, std::string* message) const;
  int solves() const { return solves_; }               // transposed solves of the last solve()
  bool failed_solve() const { return failed_solve_; }  // the last solve() failed in a linear solve
  std::string lock_message() const;                    // the loss that did not settle, and why

  static constexpr int kMaxPasses = 200;

 private:
  struct Bearing {
    const TorsionalSpring* spring = nullptr;
    Index constraint = 0;  // its joint's (−1: a natural point, `point` its name)
    std::string point;
    std::size_t at = 0;  // its reaction's first value in the reactions' row
    bool spatial = false;
    // its joint among those whose geometry adjoint() keeps: reactions_', or with a natural point's bearing
    // kept_reactions_' (the others')
    std::size_t kept = 0;
  };
  // A mesh: its row θ1 + k θ2 − (1 + k) θc − φ (the last of its constraint's), the loss 1 − η
  struct Mesh {
    const GearLoss* loss = nullptr;
    Slot member[2], carrier;
    double k = 1.0;
    Index row = 0;
    double eta[2] = {1.0, 1.0};                 // the efficiency where member 0 (reverse), member 1 (forward) is driven
    double tan_lead = 0.0, cos_pressure = 1.0;  // a worm's (GearLoss::friction > 0), whose η reads μ
  };
  // A mesh at the row: each member's rate relative to the carrier, and the member driven at the last pass (−1:
  // none, no power through the mesh)
  struct MeshState {
    double rate[2] = {0.0, 0.0};
    int driven = -1;
    double effort_sign = 0.0;  // the sign of the driven member's effort at the last pass
  };
  // What construction finds, never written after it: shared by with_set_up_of()'s copies.
  struct SetUp {
    std::vector<Bearing> bearings;
    std::vector<Mesh> meshes;
    OutputEfforts joints;  // the bearings' joints as reactions_ lists them (with natural ones, their bodies')
  };
  struct SetUpOnly {};
  FrictionLosses(const FrictionLosses& other, SetUpOnly);
  void size_scratch();
  // m_i from the reactions and the meshes' multipliers at λ (bearings first, then meshes)
  void moments_at(const double* q, double t, const Eigen::VectorXd& lambda, std::vector<double>& m);
  std::string name(std::size_t i) const;  // loss i's, for a message
  // Q_f at the motion (q, q̇, q̈) under λ with the last solve()'s directions and driven members, the losses' data of
  // `data` (null: the loads' own) and the bearings' joints and meshes of `joints` in model k along p (null: the
  // model's), into `out` (zeroed first)
  void frozen_forces(const double* q, const double* qd, const double* qdd, double t, const Eigen::VectorXd& lambda,
                     const AppliedLoads* data, const JointsAlong* joints, std::size_t k, Eigen::VectorXd& out);
  // JointsAlong::natural for p (natural bearings): the bodies' parts and loads along p, their own constraints too
  // (`build` false: checked, no reactions built)
  std::string natural_along(const Model& model, const OutputSensitivity& p, JointsAlong& out, bool build) const;
  // constraint c in the four models along p (its kept copies, its data moved along their rates, or the models'):
  // false where none stands for it
  bool constraint_along(const Model& model, const OutputSensitivity& p, Index c,
                        std::array<JointReactions::BlockAt, 4>& at, JointsAlong& out) const;
  // p's bearings' joints along it into `out` (JointsAlong), else the first loss p reaches that they cannot follow
  std::string find_joints_along(const Model& model, const OutputSensitivity& p, JointsAlong& out,
                                bool build = true) const;

  std::shared_ptr<const SetUp> set_;
  std::optional<JointReactions> reactions_;  // the bearings' joints (none without bearings)
  // with a natural point's bearing, the others' joints alone (in order), whose geometry adjoint() keeps, which
  // reactions_ cannot
  std::optional<JointReactions> kept_reactions_;
  bool natural_ = false;                         // a bearing at a natural point: reactions_ evaluated whole, each pass
  const double *qd_ = nullptr, *qdd_ = nullptr;  // solve()'s, which a natural point's reaction reads
  const double* q_ = nullptr;                    // solve()'s (adjoint() turns a natural point's force to its axes)
  double t_ = 0.0;
  std::vector<std::vector<std::pair<Index, double>>> natural_load_rows_;  // adjoint()'s, natural bearings'
  std::vector<Index> force_rows_;                                         // scratch of adjoint()
  std::vector<double> force_row_values_;
  Eigen::VectorXd qdk_, qddk_;  // force_rate()'s motion, a natural point's reaction reading q̇ and q̈
  std::vector<MeshState> mesh_states_;
  std::vector<double> values_, moments_, next_, rates_;
  std::vector<std::vector<double>> gradients_;
  std::vector<double> frozen_values_;
  std::vector<double> load_rows_;  // adjoint()'s ∂m_i/∂λ over bearing i's joint's rows (6 a bearing), once a row
  bool adjoint_ready_ = false;     // load_rows_ is the last solve()'s
  std::vector<double> frozen_gradient_;
  std::vector<JointsAlong> joints_along_;  // joints_along()'s, one per parameter asked
  Eigen::VectorXd w0_, adjoint_rhs_, adjoint_step_, qk_, forces_[4];
  Eigen::VectorXd lambda0_, q_f_, d_lambda_;
  int solves_ = 0, passes_ = 0;
  bool failed_solve_ = false;
  std::size_t worst_ = 0;  // the loss whose moment changed most at the last pass
  double worst_change_ = 0.0;
  double ratio_ = 0.0;  // the last pass's change over the one before
};

}  // namespace phiq::detail
