// Orientations (phiq/orientation.hpp): conversions between the ways people write a body's orientation and the
// Euler parameters phiq's spatial bodies carry, on Eigen's quaternions.
#include "phiq/orientation.hpp"

#include <Eigen/Geometry>
#include <cmath>

#include "base/quaternion_between.hpp"
#include "phiq/types.hpp"

namespace phiq {

Eigen::Quaterniond detail::quaternion_between(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  return Eigen::Quaterniond::FromTwoVectors(from, to);
}

namespace {

Eigen::Vector3d vector(const std::array<double, 3>& v) { return {v[0], v[1], v[2]}; }

// The unit direction of v; throws for a zero or non-finite one (`what` names it).
Eigen::Vector3d unit(const std::array<double, 3>& v, const char* what) {
  const Eigen::Vector3d u = vector(v);
  const double n = u.norm();
  if (!std::isfinite(n) || n == 0.0) throw Error(std::string(what) + " must be a non-zero finite vector");
  return u / n;
}

EulerParameters parameters(Eigen::Quaterniond q) {
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // e0 ≥ 0: the representative a rough placement would write
  return {q.w(), q.x(), q.y(), q.z()};
}

int axis_index(char c) { return c - 'x'; }

}  // namespace

EulerParameters euler_parameters_from_axis_angle(const std::array<double, 3>& axis, double angle) {
  if (!std::isfinite(angle)) throw Error("the angle must be finite");
  return parameters(Eigen::Quaterniond(Eigen::AngleAxisd(angle, unit(axis, "the rotation axis"))));
}

EulerParameters euler_parameters_from_axes(int first_axis, const std::array<double, 3>& first,
                                           std::optional<std::pair<int, std::array<double, 3>>> second) {
  const Eigen::Vector3d a = unit(first, "a body axis's direction");
  if (!second) return parameters(detail::quaternion_between(Eigen::Vector3d::Unit(first_axis), a));
  const int k = second->first;
  if (k == first_axis) throw Error("the two directions are of the same body axis");
  const Eigen::Vector3d b_raw = unit(second->second, "a body axis's direction");
  Eigen::Vector3d b = b_raw - b_raw.dot(a) * a;  // its part perpendicular to the first
  if (b.norm() < 1e-6) throw Error("the second direction lies along the first: it fixes no rotation about it");
  b.normalize();
  // The third axis completes a right-handed frame: e_(i+1) = e_i × e_(i+2) cyclically.
  const int third = 3 - first_axis - k;
  const bool cyclic = (k - first_axis + 3) % 3 == 1;  // k follows first_axis in x → y → z → x
  Eigen::Matrix3d r;
  r.col(first_axis) = a, r.col(k) = b, r.col(third) = cyclic ? a.cross(b) : b.cross(a);
  return parameters(Eigen::Quaterniond(r));
}

bool is_euler_sequence(const std::string& s) {
  if (s.size() != 3) return false;
  for (char c : s)
    if (c != 'x' && c != 'y' && c != 'z') return false;
  return s[0] != s[1] && s[1] != s[2];
}

EulerParameters euler_parameters_from_sequence(const std::string& s, const std::array<double, 3>& angles) {
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(angles[static_cast<std::size_t>(i)])) throw Error("the angles must be finite");
    q = q * Eigen::Quaterniond(Eigen::AngleAxisd(angles[static_cast<std::size_t>(i)],
                                                 Eigen::Vector3d::Unit(axis_index(s[static_cast<std::size_t>(i)]))));
  }
  return parameters(q);
}

RotationMatrix rotation_matrix(const EulerParameters& e) {
  const Eigen::Matrix3d r = Eigen::Quaterniond(e[0], e[1], e[2], e[3]).normalized().toRotationMatrix();
  RotationMatrix out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[static_cast<std::size_t>(3 * i + j)] = r(i, j);
  return out;
}

// Closed forms of R = R_i(α) R_j(β) R_k(γ) (Tait–Bryan, i, j, k distinct) and R = R_i(α) R_j(β) R_i(γ) (proper,
// k the third axis), with s = +1 when (i, j, k) is a cyclic order of (x, y, z) and −1 otherwise:
//   Tait–Bryan  R_ik = s sin β,  α = atan2(−s R_jk, R_kk),  γ = atan2(−s R_ij, R_ii)
//   proper      R_ii = cos β,    α = atan2(R_ji, −s R_ki),  γ = atan2(R_ij, s R_ik)
// At the singular β (cos β = 0, resp. sin β = 0) the atan2 arguments vanish: γ = 0 and α is read from the
// rotation left, R = R_i(α ± γ) R_j(β).
std::array<double, 3> sequence_angles(const std::string& seq, const RotationMatrix& m) {
  auto R = [&](int a, int b) { return m[static_cast<std::size_t>(3 * a + b)]; };
  const int i = axis_index(seq[0]), j = axis_index(seq[1]);
  const bool proper = seq[0] == seq[2];
  const int k = proper ? 3 - i - j : axis_index(seq[2]);
  const double s = (j - i + 3) % 3 == 1 ? 1.0 : -1.0;
  constexpr double kSingular = 1e-12;  // |sin| or |cos| of β below which α and γ are not separable
  double alpha, beta, gamma;
  if (!proper) {
    beta = std::asin(std::clamp(s * R(i, k), -1.0, 1.0));
    const double c = std::hypot(R(i, i), R(i, j));
    if (c > kSingular) {
      alpha = std::atan2(-s * R(j, k), R(k, k)), gamma = std::atan2(-s * R(i, j), R(i, i));
    } else {  // R = R_i(α) R_j(±π/2) with γ = 0: its j column is (R_ij, R_jj, R_kj) = (0, cos α, s sin α)
      alpha = std::atan2(s * R(k, j), R(j, j)), gamma = 0.0;
    }
  } else {
    beta = std::acos(std::clamp(R(i, i), -1.0, 1.0));
    const double n = std::hypot(R(i, j), R(i, k));
    if (n > kSingular) {
      alpha = std::atan2(R(j, i), -s * R(k, i)), gamma = std::atan2(R(i, j), s * R(i, k));
    } else {  // R = R_i(α) R_j(0 or π) with γ = 0: its j column is (0, cos α, s sin α)
      alpha = std::atan2(s * R(k, j), R(j, j)), gamma = 0.0;
    }
  }
  return {alpha, beta, gamma};
}

std::pair<std::array<double, 3>, double> axis_angle(const EulerParameters& e) {
  Eigen::Quaterniond q(e[0], e[1], e[2], e[3]);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // the angle in [0, π]
  const Eigen::Vector3d v = q.vec();
  const double sn = v.norm();
  const double angle = 2.0 * std::atan2(sn, q.w());
  if (sn == 0.0) return {{1.0, 0.0, 0.0}, 0.0};
  return {{v.x() / sn, v.y() / sn, v.z() / sn}, angle};
}

}  // namespace phiq
