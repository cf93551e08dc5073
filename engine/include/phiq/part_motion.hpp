/// @file
/// A part's motion from the coordinates' (phiq/parts.hpp): the velocity and acceleration of its frame's origin, its
/// angular velocity and acceleration, and the Jacobian that maps δq to the frame's displacement and rotation, exact
/// in every coordinate family (a reference-point body, natural points and vectors, expressions of q and t). What the
/// forces on a part (inverse dynamics) and the speed of its points (clearance between rows) are computed from.
///
/// Each is the pose differentiated along q(s) = q + s q̇ + s²/2 q̈, t(s) = t + s, in truncated Taylor arithmetic
/// (value, first and second derivative), so that a frame built from points by normalisations and cross products is
/// differentiated exactly; an expression's derivatives come from its own gradient, ∂/∂t and γ.
#pragma once

#include <vector>

#include "phiq/parts.hpp"

namespace phiq {

/// A frame's motion at (q, q̇, q̈, t): all vectors in world axes.
struct PartMotion {
  Pose pose;              ///< part_pose() at (q, t)
  kin3::V3 velocity;      ///< of the frame's origin (m/s)
  kin3::V3 omega;         ///< angular velocity (rad/s); planar frames: along z
  kin3::V3 acceleration;  ///< of the frame's origin (m/s²)
  kin3::V3 alpha;         ///< angular acceleration (rad/s²)
  /// Velocity and acceleration of the body point s (in the frame's axes): v + ω × R s, a + α × R s + ω × (ω × R s).
  std::pair<kin3::V3, kin3::V3> point(kin3::V3 s) const;
};

/// The motion of `frame` at (q, q̇, q̈, t); `qdd` may be null (accelerations then 0). Pre-condition as part_pose().
PartMotion part_motion(const PartFrame& frame, const double* q, const double* qd, const double* qdd, double t);

/// ∂/∂q of a frame at (q, t), one column per coordinate it reads: the origin's derivative and the rotation's (δθ
/// with δR = [δθ]× R, world axes). A body point s moves by Σ_k (d_origin_k + d_angle_k × R s) δq_k.
struct PartJacobian {
  std::vector<Index> coordinates;  ///< the coordinates the frame reads, increasing
  std::vector<kin3::V3> d_origin;  ///< ∂origin/∂q_k, one per coordinate
  std::vector<kin3::V3> d_angle;   ///< ∂θ/∂q_k, one per coordinate
};

/// The Jacobian of `frame` at (q, t).
PartJacobian part_jacobian(const PartFrame& frame, const double* q, double t);
/// The same into `out`, its vectors' capacity reused (no allocation once they have held a frame's columns: what
/// inverse dynamics calls at every row).
void part_jacobian(const PartFrame& frame, const double* q, double t, PartJacobian& out);

}  // namespace phiq
