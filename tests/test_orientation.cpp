// Orientations (phiq/orientation.hpp): every conversion against rotation matrices written out by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "phiq/orientation.hpp"
#include "phiq/types.hpp"

namespace phiq {
namespace {

using M = std::array<std::array<double, 3>, 3>;

// The elementary rotation about axis k (0 = x) by a, written out.
M elementary(int k, double a) {
  const double c = std::cos(a), s = std::sin(a);
  if (k == 0) return M{{{1, 0, 0}, {0, c, -s}, {0, s, c}}};
  if (k == 1) return M{{{c, 0, s}, {0, 1, 0}, {-s, 0, c}}};
  return M{{{c, -s, 0}, {s, c, 0}, {0, 0, 1}}};
}
M product(const M& a, const M& b) {
  M r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) r[i][j] += a[i][k] * b[k][j];
  return r;
}
void expect_matrix(const RotationMatrix& got, const M& want, double tol, const std::string& what) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(got[3 * i + j], want[i][j], tol) << what << " R" << i << j;
}
M of(const RotationMatrix& r) {
  M m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m[i][j] = r[3 * i + j];
  return m;
}

const char* const kSequences[] = {"xyz", "xzy", "yxz", "yzx", "zxy", "zyx", "xyx", "xzx", "yxy", "yzy", "zxz", "zyz"};

TEST(Orientation, AxisAngleIsRodrigues) {
  // R = I cos φ + (1 − cos φ) u uᵀ + sin φ [u]×, for u = (1, 2, 2)/3 and φ = 0.7
  const double phi = 0.7, c = std::cos(phi), s = std::sin(phi);
  const double u[3] = {1.0 / 3, 2.0 / 3, 2.0 / 3};
  const M cross{{{0, -u[2], u[1]}, {u[2], 0, -u[0]}, {-u[1], u[0], 0}}};
  M want;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) want[i][j] = (i == j ? c : 0.0) + (1 - c) * u[i] * u[j] + s * cross[i][j];
  const EulerParameters e = euler_parameters_from_axis_angle({1, 2, 2}, phi);  // any length of axis
  EXPECT_NEAR(e[0], std::cos(phi / 2), 1e-15);
  EXPECT_NEAR(e[3], u[2] * std::sin(phi / 2), 1e-15);
  expect_matrix(rotation_matrix(e), want, 1e-15, "axis-angle");
  const auto [axis, angle] = axis_angle(e);
  EXPECT_NEAR(angle, phi, 1e-15);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(axis[i], u[i], 1e-15);
  // a turn beyond π comes back as the same rotation about −u by 2π − φ
  const auto [axis2, angle2] = axis_angle(euler_parameters_from_axis_angle({1, 2, 2}, 2 * M_PI - phi));
  EXPECT_NEAR(angle2, phi, 1e-14);
  EXPECT_NEAR(axis2[0], -u[0], 1e-14);
  EXPECT_EQ(axis_angle({1, 0, 0, 0}).second, 0.0);
}

TEST(Orientation, AxesGiveARightHandedFrame) {
  const std::array<double, 3> a{0, 0.6, 0.8}, b{1, 1, 0};
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) {
      if (i == k) continue;
      const M r = of(rotation_matrix(euler_parameters_from_axes(i, a, std::make_pair(k, b))));
      // column i is a; column k is the unit part of b perpendicular to a: (1, 0.64, −0.48)/|·|
      const double n = std::sqrt(1 + 0.64 * 0.64 + 0.48 * 0.48);
      const double bp[3] = {1 / n, 0.64 / n, -0.48 / n};
      for (int d = 0; d < 3; ++d) {
        EXPECT_NEAR(r[d][i], a[d], 1e-15) << i << k;
        EXPECT_NEAR(r[d][k], bp[d], 1e-15) << i << k;
      }
      const double det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) -
                         r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0]) +
                         r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
      EXPECT_NEAR(det, 1.0, 1e-15) << i << k;
    }
  // one direction: the smallest rotation, about z × a for body z to a, by the angle between them
  const EulerParameters e = euler_parameters_from_axes(2, a, std::nullopt);
  const auto [axis, angle] = axis_angle(e);
  EXPECT_NEAR(angle, std::acos(0.8), 1e-15);
  EXPECT_NEAR(axis[0], -1.0, 1e-15);  // z × (0, 0.6, 0.8) = (−0.6, 0, 0)
}

TEST(Orientation, SequencesAreProductsOfElementaryRotations) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> turn(-M_PI + 1e-3, M_PI - 1e-3), half(-M_PI / 2 + 1e-3, M_PI / 2 - 1e-3),
      positive(1e-3, M_PI - 1e-3);
  for (const char* seq : kSequences) {
    ASSERT_TRUE(is_euler_sequence(seq));
    const bool proper = seq[0] == seq[2];
    for (int trial = 0; trial < 50; ++trial) {
      const std::array<double, 3> angles{turn(rng), proper ? positive(rng) : half(rng), turn(rng)};
      const M want = product(product(elementary(seq[0] - 'x', angles[0]), elementary(seq[1] - 'x', angles[1])),
                             elementary(seq[2] - 'x', angles[2]));
      const RotationMatrix r = rotation_matrix(euler_parameters_from_sequence(seq, angles));
      expect_matrix(r, want, 1e-14, seq);
      const auto back = sequence_angles(seq, r);  // the angles themselves, inside their ranges
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(back[i], angles[i], 1e-9) << seq << " angle " << i;
    }
  }
  for (const char* bad : {"xxy", "xyy", "xy", "abc", "xyzx"}) EXPECT_FALSE(is_euler_sequence(bad)) << bad;
}

TEST(Orientation, SingularSequencesKeepTheRotation) {
  for (const char* seq : kSequences) {
    const bool proper = seq[0] == seq[2];
    for (double beta : proper ? std::vector<double>{0.0, M_PI} : std::vector<double>{M_PI / 2, -M_PI / 2}) {
      const RotationMatrix r = rotation_matrix(euler_parameters_from_sequence(seq, {0.4, beta, -0.9}));
      const auto a = sequence_angles(seq, r);
      EXPECT_EQ(a[2], 0.0) << seq;
      EXPECT_NEAR(a[1], beta, 1e-7) << seq;  // asin / acos lose half the digits at their ends
      expect_matrix(rotation_matrix(euler_parameters_from_sequence(seq, a)), of(r), 1e-7, seq);
    }
  }
}

TEST(Orientation, BadDirectionsAreRefused) {
  EXPECT_THROW(euler_parameters_from_axis_angle({0, 0, 0}, 1.0), Error);
  EXPECT_THROW(euler_parameters_from_axis_angle({0, 0, 1}, NAN), Error);
  EXPECT_THROW(euler_parameters_from_axes(0, {1, 0, 0}, std::make_pair(0, std::array<double, 3>{0, 1, 0})), Error);
  EXPECT_THROW(euler_parameters_from_axes(0, {1, 0, 0}, std::make_pair(1, std::array<double, 3>{2, 0, 0})), Error);
  EXPECT_THROW(euler_parameters_from_axes(0, {0, 0, 0}, std::nullopt), Error);
}

}  // namespace
}  // namespace phiq
