/// @file
/// Orientations of spatial bodies as people write and read them: an axis and an angle, the world directions of one
/// or two body axes, a named Euler-angle sequence, or Euler parameters (a unit quaternion [e0, e1, e2, e3], e0 the
/// scalar part, as Frame3 holds them). The scene reader turns the first three into Euler parameters (a body's
/// `orientation`, models/README.md); the outputs turn Euler parameters back into a rotation matrix, an axis and
/// angle, or a sequence's angles. Built on Eigen's Geometry module.
#pragma once

#include <array>
#include <optional>
#include <string>

namespace phiq {

/// Euler parameters [e0, e1, e2, e3]: e0 = cos(φ/2), (e1, e2, e3) = u sin(φ/2) for a rotation φ about the unit
/// axis u.
using EulerParameters = std::array<double, 4>;
/// A rotation matrix, row-major: R[3 i + j] = R_ij; a body vector s is R s in the world.
using RotationMatrix = std::array<double, 9>;

/// The rotation by `angle` (rad) about `axis` (any non-zero length; normalised). Throws phiq::Error for a zero or
/// non-finite axis or angle.
EulerParameters euler_parameters_from_axis_angle(const std::array<double, 3>& axis, double angle);

/// The rotation that takes body axis `first_axis` (0 = x, 1 = y, 2 = z) to the world direction `first`, and, when
/// `second` is given, body axis `second_axis` to the part of `second` perpendicular to `first` (a full frame); with
/// one direction only, the smallest such rotation. Directions of any non-zero length. Throws phiq::Error for zero
/// or non-finite directions, the same axis twice, or a second direction along the first.
EulerParameters euler_parameters_from_axes(int first_axis, const std::array<double, 3>& first,
                                           std::optional<std::pair<int, std::array<double, 3>>> second);

/// Whether `sequence` names an Euler-angle sequence: three of x, y, z with no two neighbours equal — the six
/// Tait–Bryan sequences (xyz, zyx, …) and the six proper Euler ones (zxz, zyz, …).
bool is_euler_sequence(const std::string& sequence);

/// The rotation R = R_a(α) R_b(β) R_c(γ) of the intrinsic sequence "abc" (each rotation about the axis as already
/// rotated: zyx is yaw α, pitch β, roll γ). Pre-condition: is_euler_sequence(sequence).
EulerParameters euler_parameters_from_sequence(const std::string& sequence, const std::array<double, 3>& angles);

/// The rotation matrix of Euler parameters `e` (normalised first, so a slightly off-norm e still gives a rotation).
RotationMatrix rotation_matrix(const EulerParameters& e);

/// The angles (α, β, γ) of the intrinsic sequence "abc" with R = R_a(α) R_b(β) R_c(γ): α, γ in (−π, π]; β in
/// [−π/2, π/2] for Tait–Bryan sequences, [0, π] for proper Euler ones. At the sequence's singular positions
/// (β = ±π/2, resp. 0 or π) α and γ are not separable: γ = 0 and α carries the whole turn about the common axis.
/// Pre-condition: is_euler_sequence(sequence).
std::array<double, 3> sequence_angles(const std::string& sequence, const RotationMatrix& r);

/// The axis (unit) and angle in [0, π] of Euler parameters `e`; the axis is (1, 0, 0) for no rotation.
std::pair<std::array<double, 3>, double> axis_angle(const EulerParameters& e);

}  // namespace phiq
