/// @file
/// Joint measures and body orientations that a sweep outputs, so that users of spatial scenes read a hinge's
/// angle, a slider's travel or a body's attitude instead of computing them from Euler parameters:
/// - a joint's angle (as its kind's JointTraits::measures say: revolute, cylindrical, screw): θ of x_b about z_a
///   measured from x_a, as the joint angle driver measures it (kinds/joint_drivers.hpp), unwrapped over turns along
///   the sweep; its distance (prismatic, cylindrical, screw): d = z_a · (P_b − P_a);
/// - a body's orientation as its rotation matrix, an axis and angle, or the angles of an Euler sequence
///   (orientation.hpp), with its angular velocity ω and acceleration α in the world frame.
/// Values, rates and accelerations are exact (from q, q̇, q̈ through Attachment3), not differences along the sweep.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "phiq/kinds/spatial_joints.hpp"
#include "phiq/orientation.hpp"

namespace phiq {

/// What of a joint is output.
enum class JointMeasure {
  kAngle,     ///< θ (rad), columns `J.angle`, `J.angle.v`, `J.angle.a`
  kDistance,  ///< d (m), columns `J.distance`, `J.distance.v`, `J.distance.a`
};

/// A joint measure output. Build with output_joint().
struct OutputJoint {
  std::string name;                             ///< the joint's name, the columns' prefix
  JointMeasure measure = JointMeasure::kAngle;  ///< what is measured
  /// The attachments read: the angle's x_a, y_a, x_b; the distance's P_a, P_b, z_a.
  std::array<Attachment3, 3> att{};
  /// The largest coordinate index it reads, −1 if none.
  Index max_coordinate() const;
};

/// The measure of joint `name` between sides a and b. Throws phiq::Error (naming the joint) for sides that define
/// no such measure (a natural side for an angle, a natural point without a vector for a distance).
OutputJoint output_joint(std::string name, JointMeasure measure, const JointSide3& a, const JointSide3& b);

/// A joint measure at a row: value (an angle wrapped to (−π, π] by evaluate_joint(); unwrapped by the sweep), rate
/// and acceleration (0 where not evaluated).
struct JointMotion {
  double value = 0.0;         ///< θ (rad) or d (m)
  double rate = 0.0;          ///< its time derivative
  double acceleration = 0.0;  ///< its second time derivative
};

/// The measure at (q, q̇, q̈): the value always, the rate when qd is given, the acceleration when qd and qdd are.
/// Pre-condition: the arrays have more than j.max_coordinate() entries. Thread-safe.
JointMotion evaluate_joint(const OutputJoint& j, const double* q, const double* qd, const double* qdd);

/// The value of an angle measured at the next row, unwrapped against the previous row's unwrapped value: the
/// 2π-multiple nearest to the previous value plus the rates' trapezoid over dt (so a joint turning up to nearly a
/// turn per row is followed when velocities are solved, half a turn without them).
double unwrap_angle(double wrapped, double previous, double predicted_change);

/// How a body's orientation is written.
struct OrientationForm {
  /// "matrix" (`B.R11` … `B.R33`, row-major), "axis_angle" (`B.ux`, `B.uy`, `B.uz`, `B.angle`, angle in [0, π]),
  /// or an Euler sequence (is_euler_sequence(): `B.zyx_1`, `B.zyx_2`, `B.zyx_3`).
  std::string form = "matrix";
  /// The columns of one body's orientation (9, 4 or 3).
  int size() const { return form == "matrix" ? 9 : form == "axis_angle" ? 4 : 3; }
  /// The column suffixes, in order.
  std::vector<std::string> suffixes() const;
};

/// A body whose orientation is output: its Euler-parameter slots. With velocities, columns `B.omega_x, B.omega_y,
/// B.omega_z` (rad/s); with accelerations, `B.alpha_x, B.alpha_y, B.alpha_z` (rad/s², world frame).
struct OutputOrientation {
  std::string name;       ///< the body's name
  std::array<Slot, 4> e;  ///< e0 … e3
};

/// A body's orientation, angular velocity and angular acceleration at a row.
struct OrientationMotion {
  std::array<double, 9> values{};  ///< the form's values (the first OrientationForm::size())
  std::array<double, 3> omega{};   ///< ω = 2 E(e) ė, world frame (rad/s)
  std::array<double, 3> alpha{};   ///< α = 2 E(e) ë (rad/s²): E(ė) ė = 0
};

/// The orientation of `o` at (q, q̇, q̈) written as `form`. Thread-safe.
OrientationMotion evaluate_orientation(const OutputOrientation& o, const OrientationForm& form, const double* q,
                                       const double* qd, const double* qdd);

}  // namespace phiq
