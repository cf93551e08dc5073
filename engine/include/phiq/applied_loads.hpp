/// @file
/// Applied loads on a mechanism's parts (the scene's `loads` besides gravity, models/README.md): forces at points
/// of parts and torques on parts, each a vector of expressions of t, the coordinates, their rates and the
/// parameters, or of motion laws of such an expression (a table of a measured force against t, a crank angle or a
/// speed), in world or part axes; linear spring-dampers between two points (of parts, or fixed in the world); torsional
/// spring-dampers on an angle (a coordinate, an expression of the coordinates such as a relative angle ψ3 − ψ2, a
/// spatial joint's).
///
/// Their generalized forces are their virtual work, Q_k = Σ ∂x/∂q_k · F + ∂θ/∂q_k · M, from each part's exact
/// Jacobian (part_jacobian(), phiq/part_motion.hpp), so they hold in every coordinate family; dampers read the
/// points' velocities from part_motion(). Expressions are compiled once, when the scene is read; evaluating them
/// reads the compiled tapes only. A force's or torque's component may read q̇ through der(u), the rate of an
/// expression u of the coordinates and t (`-c*der(xB)`, `-k*der(psi3 - psi2)*abs(der(psi3 - psi2))`).
#pragma once

#include <Eigen/Core>

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "phiq/motion_law.hpp"
#include "phiq/output_joints.hpp"
#include "phiq/parts.hpp"

namespace phiq {

/// The axes a force's or torque's components are given in.
enum class LoadAxes {
  kWorld,  ///< the world's
  kPart,   ///< the part's frame, turning with it
};

/// A load's scalar given in the scene: an expression of t, q, q̇ (der()) and the parameters, or a motion law of one
/// (`{law: LAW, of: EXPR}`); none: 0.
struct LoadValue {
  std::shared_ptr<const CompiledExpression> expr;  ///< the value, or the law's argument; null: none
  MotionLaw law;                                   ///< where it has a value: the value is law(expr)
  /// Its value at (q, q̇, t) (qd null: q̇ = 0); NaN where a law's argument is outside its table.
  double value(const double* q, const double* qd, double t) const;
};

/// A force at a point of a part.
struct AppliedForce {
  std::string name;                  ///< the scene's name for it
  std::string part;                  ///< the part (or body) it acts on
  PartFrame frame;                   ///< that part's frame
  kin3::V3 at;                       ///< the point it acts at, in the part's frame
  LoadAxes axes = LoadAxes::kWorld;  ///< the axes of its components
  /// Its components (N), each an expression of t, q, q̇ (der()) and the parameters or a law of one; none: 0 (z in
  /// the plane).
  std::array<LoadValue, 3> components;
};

/// A torque (a couple) on a part.
struct AppliedTorque {
  std::string name;                  ///< the scene's name for it
  std::string part;                  ///< the part (or body) it acts on
  PartFrame frame;                   ///< that part's frame
  LoadAxes axes = LoadAxes::kWorld;  ///< the axes of its components
  /// Its components (N·m) as for AppliedForce: in the plane only z.
  std::array<LoadValue, 3> components;
};

/// One end of a linear spring: a point of a part, or a point fixed in the world (a ground frame).
struct SpringEnd {
  std::string part;  ///< the part (or body) it is on; "ground" for a world point
  PartFrame frame;   ///< that part's frame (ground's for a world point)
  kin3::V3 at;       ///< the point, in that frame
};

/// A spring-damper between two points: the tension f = k (L − L0) + c L̇ + preload + T along the line between them,
/// pulling them together when positive; with a law, law(L − L0) in place of k (L − L0) (a gas strut's or a bump
/// stop's curve); T an actuator's tension given as an expression or a law (a cylinder's push, negative). Where L = 0
/// the line has no direction and it exerts nothing.
struct LinearSpring {
  std::string name;          ///< the scene's name for it
  SpringEnd a;               ///< its first end
  SpringEnd b;               ///< its second end
  double stiffness = 0.0;    ///< k (N/m), ≥ 0
  double free_length = 0.0;  ///< L0 (m), ≥ 0
  double damping = 0.0;      ///< c (N·s/m), ≥ 0
  double preload = 0.0;      ///< tension at L = L0 at rest (N)
  double friction = 0.0;     ///< f (N), ≥ 0: a dry friction's tension f sign(L̇) (none at rest)
  MotionLaw law;             ///< the elastic tension of L − L0 (N) in place of k (L − L0), where it has a value
  LoadValue tension;         ///< T (N): an actuator's tension along the line, if any
};

/// A bearing's dry friction, read off its joint's reaction (a journal's and a thrust collar's, Adams' joint friction
/// without stiction): the moment μ (r (|F_r| + |M_b| / a) + r_a |F_a|) against θ̇, F_r the reaction's force across the
/// joint's axis, F_a along it and M_b its moment across it (the bending a spatial journal carries; none in the plane),
/// which presses the journal as the force |M_b| / a, a the bending arm (0: not counted); on a slide (`slide`: a
/// prismatic pair, or a cylindrical one given no radius, θ its travel) the force μ (|F_r| + |M| / a) against θ̇, M the
/// moment the slide carries (its tilt: Mz in the plane, every component in space). Moments are about the point the
/// joint's reaction is written about (ReactionSite: a planar slide's slider point, a spatial joint's side-1 point, so
/// that side 1 is the member that holds the bearing). It depends on the multipliers it
/// changes, so the efforts solve for it (detail::FrictionLosses); add_applied_forces() and applied_power() leave it
/// out.
struct BearingFriction {
  std::string joint;  ///< the pin, revolute, cylindrical or prismatic joint (a constraint) whose reaction loads it
  double coefficient = 0.0;    ///< μ, ≥ 0
  double radius = 0.0;         ///< r (m), the journal's radius, ≥ 0 (not on a slide)
  double thrust_radius = 0.0;  ///< r_a (m), the thrust collar's mean radius, ≥ 0 (spatial joints)
  double moment_arm = 0.0;     ///< a (m), > 0: the moments across the joint press it as |M| / a; 0: not counted
  bool slide = false;          ///< a slide's friction: a force along its travel, not a journal's moment
  bool operator==(const BearingFriction&) const = default;  ///< datum by datum
};

/// A torsional spring-damper on an angle θ(q, t): the moment τ = k (θ − θ0) + c θ̇ + f sign(θ̇) + J θ̈ + M resisting
/// θ's increase; with a law, law(θ − θ0) in place of k (θ − θ0); f a dry friction's moment (none at rest), J a rotor's
/// inertia turning with θ (a geared motor's, MuJoCo's armature), M a rotary actuator's moment given as an expression
/// or a law; and a bearing's friction, if any, from its joint's reaction.
struct TorsionalSpring {
  std::string name;                                 ///< the scene's name for it
  std::shared_ptr<const CompiledExpression> angle;  ///< θ: a coordinate, or an expression of them; or null and:
  /// θ a spatial joint's angle (its kind's measure, phiq/output_joints.hpp), known only modulo a turn: θ − θ0 is
  /// taken in (−π, π].
  std::optional<OutputJoint> joint;
  std::vector<Index> joint_coordinates;  ///< the coordinates the joint's angle reads, increasing
  double stiffness = 0.0;                ///< k (N·m/rad), ≥ 0
  double free_angle = 0.0;               ///< θ0 (rad)
  double damping = 0.0;                  ///< c (N·m·s/rad), ≥ 0
  double friction = 0.0;                 ///< f (N·m), ≥ 0
  double inertia = 0.0;                  ///< J (kg·m²), ≥ 0
  MotionLaw law;                         ///< the elastic moment of θ − θ0 (N·m) in place of k (θ − θ0), if any
  LoadValue moment;                      ///< M (N·m): an actuator's moment against θ, if any
  std::optional<BearingFriction> bearing;  ///< a bearing's friction, if any
};

/// A transmission's meshing losses as efficiencies (a gear pair's, a rack and pinion's, a belt's, a spatial pair's, a
/// worm's): the member its teeth drive (the one the mesh does positive work on, relative to the carrier) receives η
/// of the ideal mesh's effort, the rest a friction-like loss (1 − η) |e| against its turn; η `efficiency` where the
/// first member drives the second, `reverse_efficiency` the other way. A reverse efficiency ≤ 0 is a self-locking
/// drive: its second member cannot drive the first, whose motor must push it even while the load goes its way. Of a
/// worm pair (a spatial_gear with pitch radii, its axes crossed at a right angle), `friction` μ gives both from its
/// lead angle λ (tan λ = r2 / (|k| r1)) and normal pressure angle φ: η = (cos φ − μ tan λ) / (cos φ + μ cot λ),
/// η_r = (cos φ − μ cot λ) / (cos φ + μ tan λ). Solved with the multipliers, as a bearing's friction
/// (detail::FrictionLosses).
struct GearLoss {
  std::string gear;                 ///< the transmission (a constraint: gear, rack_pinion, belt or spatial_gear)
  double efficiency = 1.0;          ///< η where the first member drives, in (0, 1]
  double reverse_efficiency = 1.0;  ///< η where the second member drives, ≤ 1 (the scene's default: η)
  double friction = 0.0;            ///< μ > 0 of a worm pair's teeth, in place of the efficiencies; 0: none
  bool operator==(const GearLoss&) const = default;  ///< datum by datum
};

/// The applied loads of a scene, read once and shared (Loads::applied holds them by pointer).
struct AppliedLoads {
  std::vector<AppliedForce> forces;                ///< `forces`
  std::vector<AppliedTorque> torques;              ///< `torques`
  std::vector<LinearSpring> springs;               ///< `springs`
  std::vector<TorsionalSpring> torsional_springs;  ///< `torsional_springs`
  std::vector<GearLoss> gear_losses;               ///< `gear_losses`
  /// True when there is none.
  bool empty() const {
    return forces.empty() && torques.empty() && springs.empty() && torsional_springs.empty() && gear_losses.empty();
  }
};

/// The sign a dry friction (LinearSpring::friction, TorsionalSpring::friction) takes of its rate: −1, 0 or 1, none
/// at rest (where static friction is not determined).
inline double friction_direction(double rate) { return rate > 0.0 ? 1.0 : rate < 0.0 ? -1.0 : 0.0; }

/// A torsional spring's angle rate θ̇ at (q, q̇, t) (0 with qd null: at rest), and ∂θ/∂q_k over
/// torsional_coordinates(s) into `gradient`.
double angle_rate(const TorsionalSpring& s, const double* q, const double* qd, double t, std::vector<double>& gradient);
/// The coordinates a torsional spring's angle reads, increasing.
const std::vector<Index>& torsional_coordinates(const TorsionalSpring& s);

/// A force's or torque's components at (q, q̇, t) in world axes (qd null: q̇ = 0).
kin3::V3 world_components(const std::array<LoadValue, 3>& components, LoadAxes axes, const Pose& pose, const double* q,
                          const double* qd, double t);

/// Adds to `Q` (one entry per coordinate) the generalized forces of `loads` at (q, q̇, q̈, t): their virtual work per
/// δq_k. `qd` may be null: at rest (the dampers exert nothing, der() is 0); `qdd` null: q̈ = 0 (a torsional
/// spring's rotor inertia exerts nothing). Pre-condition: Q has an entry for every coordinate the loads read.
/// Thread-safe.
void add_applied_forces(const AppliedLoads& loads, const double* q, const double* qd, const double* qdd, double t,
                        Eigen::VectorXd& Q);

/// The power of `loads` at (q, q̇, q̈, t) (W): Σ F · v of the forces at their points' velocities, M · ω of the
/// torques, −f L̇ of the springs, −τ θ̇ of the torsional ones. With frames that do not depend on t it is Q · q̇.
double applied_power(const AppliedLoads& loads, const double* q, const double* qd, const double* qdd, double t);

}  // namespace phiq
