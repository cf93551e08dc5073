// part_motion() and part_jacobian() (phiq/part_motion.hpp) against central differences of part_pose() along the
// path q + s q̇ + s²/2 q̈ and along each coordinate, for a part in every coordinate family (the notes' four-bar in
// relative, natural, reference-point and mixed coordinates; a spatial body; a spatial frame of natural points),
// at rows of each scene's own sweep; and the Jacobian times q̇ equal to the velocity.
#include <gtest/gtest.h>

#include <cmath>

#include "phiq/part_motion.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

using V = kin3::V3;
double norm_of(V a) { return kin3::norm(a); }

// vee((A − B) Rᵀ / k) for rotations given row-major.
V rate_vector(const RotationMatrix& a, const RotationMatrix& b, const RotationMatrix& r, double k) {
  double w[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = 0.0;
      for (int l = 0; l < 3; ++l) s += (a[3 * i + l] - b[3 * i + l]) * r[3 * j + l];
      w[3 * i + j] = s / k;
    }
  return {0.5 * (w[7] - w[5]), 0.5 * (w[2] - w[6]), 0.5 * (w[3] - w[1])};
}

struct Case {
  std::string scene, parts, part;
};

// The worst relative errors of one part over its scene's rows: velocity and ω, acceleration and α, Jacobian, J q̇.
struct Errors {
  double first = 0, second = 0, jacobian = 0, jq = 0;
};

Errors check(const Case& c) {
  Scene s = parse_scene(test::model_file_text(c.scene) + (c.parts.empty() ? "" : "\nparts:\n" + c.parts), c.scene);
  s.sweep.velocities = s.sweep.accelerations = true;
  test::Trace tr;
  EXPECT_EQ(test::sweep(*s.model, s.sweep, &tr), SolveStatus::kSuccess) << c.scene;
  const Part* part = nullptr;
  for (const Part& p : s.parts)
    if (p.name == c.part) part = &p;
  EXPECT_NE(part, nullptr);
  Errors e;
  if (!part || tr.t.empty()) return e;
  const std::size_t n = static_cast<std::size_t>(s.model->num_coordinates());
  for (std::size_t k = 0; k < tr.t.size(); k += std::max<std::size_t>(1, tr.t.size() / 7)) {
    const Eigen::VectorXd &q = tr.q[k], &qd = tr.qd[k], &qdd = tr.qdd[k];
    const double t = tr.t[k];
    const PartMotion m = part_motion(part->frame, q.data(), qd.data(), qdd.data(), t);
    auto along = [&](double h) {
      const Eigen::VectorXd qh = q + h * qd + 0.5 * h * h * qdd;
      return part_pose(part->frame, qh.data(), t + h);
    };
    const double h = 1e-4;
    const Pose p0 = part_pose(part->frame, q.data(), t), pp = along(h), pm = along(-h);
    const V v = (1.0 / (2 * h)) * (pp.at - pm.at), a = (1.0 / (h * h)) * (pp.at - 2.0 * p0.at + pm.at);
    const V w = rate_vector(pp.rotation, pm.rotation, p0.rotation, 2 * h);
    RotationMatrix second;
    for (int i = 0; i < 9; ++i) second[i] = pp.rotation[i] - 2 * p0.rotation[i] + pm.rotation[i];
    // R̈ Rᵀ − [ω]×²: the second's antisymmetric part is [α]× already ([ω]×² is symmetric)
    const V al = rate_vector(second, RotationMatrix{}, p0.rotation, h * h);
    const double scale1 = 1.0 + norm_of(m.velocity) + norm_of(m.omega);
    const double scale2 = 1.0 + norm_of(m.acceleration) + norm_of(m.alpha);
    e.first = std::max(e.first, (norm_of(m.velocity - v) + norm_of(m.omega - w)) / scale1);
    e.second = std::max(e.second, (norm_of(m.acceleration - a) + norm_of(m.alpha - al)) / scale2);
    // the Jacobian against differences in each coordinate, and J q̇ against the velocity (no frame here reads t)
    const PartJacobian j = part_jacobian(part->frame, q.data(), t);
    V jv{}, jw{};
    for (std::size_t i = 0; i < j.coordinates.size(); ++i) {
      const Index c = j.coordinates[i];
      EXPECT_LT(static_cast<std::size_t>(c), n);
      Eigen::VectorXd qp = q, qm = q;
      const double hc = 1e-6;
      qp(c) += hc, qm(c) -= hc;
      const Pose a1 = part_pose(part->frame, qp.data(), t), a0 = part_pose(part->frame, qm.data(), t);
      const V dor = (1.0 / (2 * hc)) * (a1.at - a0.at),
              dan = rate_vector(a1.rotation, a0.rotation, p0.rotation, 2 * hc);
      e.jacobian = std::max(e.jacobian, norm_of(j.d_origin[i] - dor) + norm_of(j.d_angle[i] - dan));
      jv = jv + qd(c) * j.d_origin[i], jw = jw + qd(c) * j.d_angle[i];
    }
    e.jq = std::max(e.jq, (norm_of(jv - m.velocity) + norm_of(jw - m.omega)) / scale1);
  }
  return e;
}

TEST(PartMotion, EveryFrameKindAgreesWithDifferencesOfItsPose) {
  const Case cases[] = {
      {"seed/fourbar_relative.yaml", "  c: {frame: {at: [L2*cos(psi2), L2*sin(psi2)], angle: psi2 + psi3}}\n", "c"},
      {"seed/fourbar_natural.yaml", "  c: {frame: {origin: A, x: B}}\n", "c"},
      {"seed/fourbar_reference_point.yaml", "  coupler: {}\n", "coupler"},
      {"seed/fourbar_mixed.yaml", "  coupler: {}\n", "coupler"},
      {"spatial/cardan.yaml", "", "output_shaft"},  // the scene's own part on s2
      {"spatial/rssr_natural.yaml", "  c: {frame: {origin: A, x: B, y: C}}\n", "c"},
  };
  for (const Case& c : cases) {
    const Errors e = check(c);
    EXPECT_LT(e.first, 1e-8) << c.scene;     // central differences, h = 1e-4: O(h²)
    EXPECT_LT(e.second, 1e-6) << c.scene;    // second differences: O(h²) and rounding ε/h²
    EXPECT_LT(e.jacobian, 1e-8) << c.scene;  // h = 1e-6
    EXPECT_LT(e.jq, 1e-14) << c.scene;       // one linear map, two ways
  }
}

// A reference-point body's motion is its coordinates' rates, exactly.
TEST(PartMotion, APlanarBodysRatesAreItsCoordinatesRates) {
  Scene s =
      parse_scene(test::model_file_text("seed/fourbar_reference_point.yaml") + "\nparts:\n  crank: {}\n", "fb.yaml");
  const Model& m = *s.model;
  Eigen::VectorXd q = m.initial_positions(), qd = Eigen::VectorXd::LinSpaced(q.size(), 0.1, 0.9),
                  qdd = Eigen::VectorXd::LinSpaced(q.size(), -1.0, 1.0);
  const PartMotion pm = part_motion(s.parts[0].frame, q.data(), qd.data(), qdd.data(), 0.0);
  const Index x = m.coordinate_index("x2"), y = m.coordinate_index("y2"), psi = m.coordinate_index("psi2");
  EXPECT_EQ(pm.velocity.x, qd(x));
  EXPECT_EQ(pm.velocity.y, qd(y));
  EXPECT_EQ(pm.acceleration.x, qdd(x));
  EXPECT_NEAR(pm.omega.z, qd(psi), 1e-15);
  EXPECT_NEAR(pm.alpha.z, qdd(psi), 1e-15);
  EXPECT_EQ(pm.omega.x, 0.0);
}

}  // namespace
}  // namespace phiq
