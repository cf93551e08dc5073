// The spatial scenes of models/: they load with the expected counts and Grübler number, their residuals vanish at
// configurations known in closed form and Φq q̇ + Φt = 0 holds with closed-form velocities; a dense SVD of Φq
// (independent of the engine's sparse solvers) shows the one degree of freedom of the redundant ones; the RSSR
// four-bar, not redundant, is swept end to end and agrees with its closed form.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <functional>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

Scene Load(const std::string& rel) { return load_scene(test::model_path(rel)); }

Eigen::MatrixXd DenseJacobian(const Model& m, const Eigen::VectorXd& q, double t) {
  const CscPattern& p = m.jacobian_pattern();
  std::vector<double> v(static_cast<std::size_t>(p.nnz()));
  m.jacobian(q.data(), t, v.data());
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(m.num_equations(), m.num_coordinates());
  for (Index j = 0; j < p.cols; ++j)
    for (Index k = p.col_ptr[j]; k < p.col_ptr[j + 1]; ++k) J(p.row_idx[k], j) = v[k];
  return J;
}

Eigen::VectorXd Residual(const Model& m, const Eigen::VectorXd& q, double t) {
  Eigen::VectorXd phi(m.num_equations());
  m.residual(q.data(), t, phi.data());
  return phi;
}

// Φq q̇ + Φt, which vanishes for the velocity of a motion that keeps Φ = 0.
Eigen::VectorXd VelocityResidual(const Model& m, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t) {
  Eigen::VectorXd pt(m.num_equations());
  m.phi_t(q.data(), t, pt.data());
  return DenseJacobian(m, q, t) * qd + pt;
}

// Numerical rank of the kinematic rows (all but the drivers, which are the last `drivers` rows) by dense SVD,
// relative tolerance 1e-9.
Index KinematicRank(const Model& m, const Eigen::VectorXd& q, Index drivers) {
  const Eigen::MatrixXd J = DenseJacobian(m, q, 0.0).topRows(m.num_equations() - drivers);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(J);
  const Eigen::VectorXd s = svd.singularValues();
  Index r = 0;
  for (Index i = 0; i < s.size(); ++i) r += s(i) > 1e-9 * s(0) ? 1 : 0;
  return r;
}

// Position, then Euler parameters of a rotation by `angle` about z, into q at `first`.
void PutBody(Eigen::VectorXd& q, Index first, double x, double y, double angle) {
  q.segment(first, 7) << x, y, 0.0, std::cos(angle / 2), 0.0, 0.0, std::sin(angle / 2);
}
// Their time derivatives for a body moving at (vx, vy) and turning at rate w about z.
void PutBodyRate(Eigen::VectorXd& qd, Index first, double vx, double vy, double angle, double w) {
  qd.segment(first, 7) << vx, vy, 0.0, -0.5 * w * std::sin(angle / 2), 0.0, 0.0, 0.5 * w * std::cos(angle / 2);
}

// ---- the notes' 3D crank-slider -------------------------------------------------------------------------------

TEST(SpatialScenes, CrankSlider3dIsTheClosedFormCrankSlider) {
  const Scene s = Load("redundant/crank_slider_3d.yaml");
  const Model& m = *s.model;
  EXPECT_EQ(m.num_coordinates(), 21);
  EXPECT_EQ(m.num_equations(), 24);  // 3 normalisations + 3 · 5 + 5 + the driver
  ASSERT_TRUE(m.grubler().has_value());
  EXPECT_EQ(*m.grubler(), -2);
  const double L2 = 0.3, L3 = 1.0, omega = 2.0;
  const Index crank = m.coordinate_index("crank_x"), rod = m.coordinate_index("rod_x"),
              slider = m.coordinate_index("slider_x");
  for (double t : {0.0, 0.35, 1.2, 2.0, 3.0}) {
    SCOPED_TRACE("t = " + std::to_string(t));
    // closed form: θ = 2t, A = L2 (cos θ, sin θ), rod angle β = −asin(L2 sin θ / L3), x_B = L2 cos θ + L3 cos β
    const double th = omega * t, c = std::cos(th), sn = std::sin(th);
    const double beta = -std::asin(L2 * sn / L3), xb = L2 * c + L3 * std::cos(beta);
    // velocities: β̇ = −L2 cos θ θ̇ / (L3 cos β), ẋ_B = −L2 sin θ θ̇ − L3 sin β β̇
    const double betad = -L2 * c * omega / (L3 * std::cos(beta)), xbd = -L2 * sn * omega - L3 * std::sin(beta) * betad;
    Eigen::VectorXd q = Eigen::VectorXd::Zero(21), qd = Eigen::VectorXd::Zero(21);
    PutBody(q, crank, 0, 0, th), PutBody(q, rod, L2 * c, L2 * sn, beta), PutBody(q, slider, xb, 0, 0);
    PutBodyRate(qd, crank, 0, 0, th, omega), PutBodyRate(qd, rod, -L2 * sn * omega, L2 * c * omega, beta, betad);
    PutBodyRate(qd, slider, xbd, 0, 0, 0);
    EXPECT_LT(Residual(m, q, t).lpNorm<Eigen::Infinity>(), 1e-12);
    EXPECT_LT(VelocityResidual(m, q, qd, t).lpNorm<Eigen::Infinity>(), 1e-12);
    // the wrong velocity is seen: the slider a little faster
    qd(slider) += 1e-3;
    EXPECT_GT(VelocityResidual(m, q, qd, t).lpNorm<Eigen::Infinity>(), 1e-4);
    // 23 kinematic rows of rank 20: 21 − 20 = 1 degree of freedom where Grübler says −2
    EXPECT_EQ(KinematicRank(m, q, 1), 20);
  }
}

// ---- the door -------------------------------------------------------------------------------------------------

TEST(SpatialScenes, DoorOnThreeHingesHoldsAtAnyAngle) {
  const Scene s = Load("redundant/door_three_hinges.yaml");
  const Model& m = *s.model;
  EXPECT_EQ(m.num_coordinates(), 7);
  EXPECT_EQ(m.num_equations(), 17);
  ASSERT_TRUE(m.grubler().has_value());
  EXPECT_EQ(*m.grubler(), -9);
  for (double t : {0.0, 0.8, 1.5}) {  // the driver: angle = t, rate 1
    Eigen::VectorXd q(7), qd(7);
    PutBody(q, 0, 0, 0, t), PutBodyRate(qd, 0, 0, 0, t, 1.0);
    EXPECT_LT(Residual(m, q, t).lpNorm<Eigen::Infinity>(), 1e-12) << t;
    EXPECT_LT(VelocityResidual(m, q, qd, t).lpNorm<Eigen::Infinity>(), 1e-12) << t;
    EXPECT_EQ(KinematicRank(m, q, 1), 6) << t;  // 16 rows, rank 6: dof 1, 10 redundant equations
  }
}

TEST(SpatialScenes, MisalignedDoorViolatesOnlyItsThirdHinge) {
  const Scene s = Load("redundant/door_misaligned.yaml");
  const Model& m = *s.model;
  EXPECT_EQ(m.num_coordinates(), 7);
  EXPECT_EQ(m.num_equations(), 17);
  EXPECT_EQ(*m.grubler(), -9);
  Eigen::VectorXd q(7);
  PutBody(q, 0, 0, 0, 0.4);
  const Eigen::VectorXd phi = Residual(m, q, 0.4);
  for (Index r = 0; r < m.num_equations(); ++r) {
    const std::string row = m.row_name(r);
    if (row == "hinge3[0]")
      EXPECT_NEAR(phi(r), 0.01, 1e-15);  // ground point 1 cm along x: Φ = P_a − P_b
    else
      EXPECT_LT(std::fabs(phi(r)), 1e-12) << row;
  }
}

// ---- Bricard --------------------------------------------------------------------------------------------------

TEST(SpatialScenes, BricardHoldsInItsSquareConfigurationAndFollowsItsDriver) {
  const Scene s = Load("benchmarks/bricard.yaml");
  const Model& m = *s.model;
  EXPECT_EQ(m.num_coordinates(), 35);
  EXPECT_EQ(m.num_equations(), 36);  // 5 normalisations + 6 · 5 + the driver
  ASSERT_TRUE(m.grubler().has_value());
  EXPECT_EQ(*m.grubler(), 0);
  Eigen::VectorXd q = m.initial_positions();  // the square configuration, exact
  EXPECT_LT(Residual(m, q, 0.0).lpNorm<Eigen::Infinity>(), 1e-15);
  EXPECT_EQ(KinematicRank(m, q, 1), 34);  // 35 rows, one redundant: dof 1 where Grübler says 0
  // Gauss–Newton with least-squares steps (dense, complete orthogonal decomposition) follows the driver through
  // a radian of J1: the loop does move, with every equation satisfied.
  for (int k = 1; k <= 10; ++k) {
    const double t = 0.1 * k;
    for (int it = 0; it < 20; ++it) {
      const Eigen::VectorXd phi = Residual(m, q, t);
      if (phi.lpNorm<Eigen::Infinity>() < 1e-13) break;
      q -= DenseJacobian(m, q, t).completeOrthogonalDecomposition().solve(phi);
    }
    EXPECT_LT(Residual(m, q, t).lpNorm<Eigen::Infinity>(), 1e-12) << "t = " << t;
  }
  // J1 turned by 1 rad: link1's Euler parameters are a rotation by 1 rad about y
  const Index l1 = m.coordinate_index("link1_e0");
  const double sign = q(l1) < 0 ? -1.0 : 1.0;  // p and −p are the same rotation
  EXPECT_NEAR(sign * q(l1), std::cos(0.5), 1e-12);
  EXPECT_NEAR(sign * q(l1 + 2), std::sin(0.5), 1e-12);
}

// ---- RSSR: swept by the square solver, against its closed form --------------------------------------------------

TEST(SpatialScenes, RssrSweepsAndAgreesWithItsClosedForm) {
  const Scene s = load_scene(test::model_path("spatial/rssr.yaml"));
  const Model& m = *s.model;
  EXPECT_EQ(m.num_coordinates(), 14);
  EXPECT_EQ(m.num_equations(), 14);
  ASSERT_TRUE(m.grubler().has_value());
  EXPECT_EQ(*m.grubler(), 1);
  test::Trace tr;
  SweepOptions opt = s.sweep;
  ASSERT_EQ(test::sweep(m, opt, &tr), SolveStatus::kSuccess);
  ASSERT_EQ(tr.t.size(), 73u);
  ASSERT_EQ(tr.qd.size(), 73u);
  const double a = 0.2, b = 0.5, d = 0.5, e = 0.6, L = 0.92;
  auto slots = [&](const std::string& body) {
    const Index i = m.coordinate_index(body + "_x");
    return Frame3{Slot::coordinate(i),     Slot::coordinate(i + 1), Slot::coordinate(i + 2), Slot::coordinate(i + 3),
                  Slot::coordinate(i + 4), Slot::coordinate(i + 5), Slot::coordinate(i + 6)};
  };
  const Attachment3 A = Attachment3::body_point(slots("crank"), kin3::V3{a, 0, 0});
  const Attachment3 B = Attachment3::body_point(slots("rocker"), kin3::V3{0, b, 0});
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    const double th = tr.t[k], c = std::cos(th), sn = std::sin(th);
    SCOPED_TRACE("t = " + std::to_string(th));
    // closed form of the rocker angle φ ∈ (0, π) and its rate (θ̇ = 1)
    const double N = L * L - (d - a * c) * (d - a * c) - (e - a * sn) * (e - a * sn) - b * b;
    const double D = 2 * b * (e - a * sn), Nd = -2 * a * sn * (d - a * c) + 2 * a * c * (e - a * sn),
                 Dd = -2 * b * a * c;
    const double phi = std::acos(N / D), phid = -((Nd * D - N * Dd) / (D * D)) / std::sin(phi);
    const kin3::V3 pa = A.value(tr.q[k].data()), pb = B.value(tr.q[k].data());
    EXPECT_NEAR(pa.x, a * c, 1e-9);
    EXPECT_NEAR(pa.y, a * sn, 1e-9);
    EXPECT_NEAR(pa.z, 0.0, 1e-9);
    EXPECT_NEAR(pb.x, d, 1e-9);
    EXPECT_NEAR(pb.y, e + b * std::cos(phi), 1e-9);
    EXPECT_NEAR(pb.z, b * std::sin(phi), 1e-9);
    const kin3::V3 vb = B.rate(tr.q[k].data(), tr.qd[k].data());
    EXPECT_NEAR(vb.x, 0.0, 1e-8);
    EXPECT_NEAR(vb.y, -b * std::sin(phi) * phid, 1e-8);
    EXPECT_NEAR(vb.z, b * std::cos(phi) * phid, 1e-8);
  }
}

// A Cardan joint's output fork against the closed form over a sweep: shafts β apart, input at rate w, the output
// shaft's frame first at coordinate `x2`. tan θ2 = tan θ1 / cos β, θ̇2 = ω cos β / D, D = cos²β cos²θ1 + sin²θ1.
void ExpectCardanClosedForm(const Model& m, const test::Trace& tr, double beta, double w, const std::string& x2) {
  const double cb = std::cos(beta);
  const Index i = m.coordinate_index(x2);
  const Frame3 s2{Slot::coordinate(i),     Slot::coordinate(i + 1), Slot::coordinate(i + 2), Slot::coordinate(i + 3),
                  Slot::coordinate(i + 4), Slot::coordinate(i + 5), Slot::coordinate(i + 6)};
  // The output fork (s2's y axis) at θ2 is −sin θ2 b + cos θ2 ŷ, with b = (cos β, 0, −sin β) ⊥ the output axis.
  const Attachment3 fork = Attachment3::body_vector(s2, kin3::V3{0, 1, 0});
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    SCOPED_TRACE("t = " + std::to_string(tr.t[k]));
    const double th1 = w * tr.t[k], c1 = std::cos(th1), s1 = std::sin(th1);
    const double th2 = std::atan2(s1, c1 * cb), D = cb * cb * c1 * c1 + s1 * s1, th2d = w * cb / D;
    const kin3::V3 f = fork.value(tr.q[k].data()), fd = fork.rate(tr.q[k].data(), tr.qd[k].data());
    const double b_f = f.x * cb - f.z * std::sin(beta);
    EXPECT_NEAR(std::remainder(std::atan2(-b_f, f.y) - th2, 2 * M_PI), 0.0, 1e-8);
    // d/dt of the fork: (−cos θ2 b − sin θ2 ŷ) θ̇2
    EXPECT_NEAR(fd.y, -std::sin(th2) * th2d, 1e-7 * std::max(1.0, th2d));
  }
}

TEST(SpatialScenes, CardanNearItsSingularAngleStaysOnItsBranch) {
  // Shafts 89° apart: near θ1 = π the output swings 78.7° in a 5° step, and the sweep landed on the other assembly
  // mode (θ2 + π) from there on, with a warning that it had "kept its branch": now det Φq's change of sign between
  // two regular positions makes it halve the step, which follows the branch.
  const Scene s = load_scene(test::model_path("spatial/cardan_near_singular.yaml"));
  const Model& m = *s.model;
  SweepSummary sum;
  test::Trace tr;
  ASSERT_EQ(test::sweep(m, s.sweep, &tr, &sum), SolveStatus::kSuccess) << sum.message;
  ASSERT_EQ(tr.t.size(), 73u);
  // The chunks' seeds, found over a chunk's whole span (16 steps, 80°), land on the other mode beyond the swing; the
  // seam check refuses that chunk and the rest runs in order, on every thread count alike: its one warning.
  for (const SweepWarning& w : sum.warnings)
    if (w.kind != "parallel_fallback") ADD_FAILURE() << w.kind << " at t = " << w.t << ": " << w.message;
  ExpectCardanClosedForm(m, tr, 89.0 * M_PI / 180.0, 1.5, "x2");
}

TEST(SpatialScenes, CardanWrittenWithOrientationsIsTheClosedForm) {
  // The same joint 30° apart, its bodies written as maps with their orientations (no Euler parameters, no
  // coordinates section): the placement is exact, so the first row needs no Newton correction of s2.
  const Scene s = load_scene(test::model_path("spatial/cardan.yaml"));
  const Model& m = *s.model;
  EXPECT_EQ(m.num_coordinates(), 14);
  EXPECT_EQ(m.coordinate_names()[7], "s2_x");
  EXPECT_EQ(*m.grubler(), 1);  // 2 · 6 − 5 − 4 − 2
  SweepSummary sum;
  test::Trace tr;
  ASSERT_EQ(test::sweep(m, s.sweep, &tr, &sum), SolveStatus::kSuccess) << sum.message;
  ASSERT_EQ(tr.t.size(), 73u);
  const double beta = M_PI / 6;
  EXPECT_NEAR(tr.q[0][m.coordinate_index("s2_e0")], std::cos(beta / 2), 1e-15);  // a turn of β about y
  EXPECT_NEAR(tr.q[0][m.coordinate_index("s2_e2")], std::sin(beta / 2), 1e-15);
  ExpectCardanClosedForm(m, tr, beta, 1.0, "s2_x");
}

TEST(SpatialScenes, RssrInReferencePointAndNaturalCoordinatesAgree) {
  const Scene rp = load_scene(test::model_path("spatial/rssr.yaml"));
  const Scene nat = load_scene(test::model_path("spatial/rssr_natural.yaml"));
  EXPECT_FALSE(nat.model->grubler().has_value());  // natural coordinates: not made of joints
  test::Trace a, n;
  ASSERT_EQ(test::sweep(*rp.model, rp.sweep, &a), SolveStatus::kSuccess);
  ASSERT_EQ(test::sweep(*nat.model, nat.sweep, &n), SolveStatus::kSuccess);
  ASSERT_EQ(a.t.size(), n.t.size());
  ASSERT_EQ(a.qdd.size(), a.t.size());
  ASSERT_EQ(n.qdd.size(), n.t.size());
  const Model& m = *rp.model;
  const Index r = m.coordinate_index("rocker_x");
  Frame3 f;
  Slot* slots[] = {&f.x, &f.y, &f.z, &f.e0, &f.e1, &f.e2, &f.e3};
  for (Index k = 0; k < 7; ++k) *slots[k] = Slot::coordinate(r + k);
  const Attachment3 B = Attachment3::body_point(f, kin3::V3{0, 0.5, 0});
  const Index yb = nat.model->coordinate_index("yB"), zb = nat.model->coordinate_index("zB");
  for (std::size_t k = 0; k < a.t.size(); ++k) {
    SCOPED_TRACE("t = " + std::to_string(a.t[k]));
    const kin3::V3 p = B.value(a.q[k].data()), v = B.rate(a.q[k].data(), a.qd[k].data());
    // B̈ = (the part linear in q̈) + (the q̈-free part)
    const kin3::V3 acc = B.rate(a.q[k].data(), a.qdd[k].data()) + B.bias(a.qd[k].data());
    EXPECT_NEAR(p.y, n.q[k](yb), 1e-9);
    EXPECT_NEAR(p.z, n.q[k](zb), 1e-9);
    EXPECT_NEAR(v.y, n.qd[k](yb), 1e-9);
    EXPECT_NEAR(v.z, n.qd[k](zb), 1e-9);
    EXPECT_NEAR(acc.y, n.qdd[k](yb), 1e-8);
    EXPECT_NEAR(acc.z, n.qdd[k](zb), 1e-8);
  }
}

TEST(SpatialScenes, NaturalSpatialCrankSliderIsTheClosedForm) {
  const Scene s = load_scene(test::model_path("spatial/crank_slider_natural.yaml"));
  const Model& m = *s.model;
  EXPECT_EQ(m.num_coordinates(), 6);
  EXPECT_EQ(m.num_equations(), 6);  // w.unit, crank, w_across_crank, w_in_plane, rod, motor
  EXPECT_FALSE(m.grubler().has_value());
  test::Trace tr;
  ASSERT_EQ(test::sweep(m, s.sweep, &tr), SolveStatus::kSuccess);
  ASSERT_EQ(tr.t.size(), 61u);
  ASSERT_EQ(tr.qdd.size(), 61u);
  const double a = 0.3, L = 1.0, h = 0.1, c = 0.2;
  // x_B(θ) = a cos θ + S, S = sqrt(L² − c² − (h − a sin θ)²); ẋ_B = −a sin θ + a cos θ (h − a sin θ) / S (θ̇ = 1)
  auto xb = [&](double th) { return a * std::cos(th) + std::sqrt(L * L - c * c - std::pow(h - a * std::sin(th), 2)); };
  auto xbd = [&](double th) {
    const double S = std::sqrt(L * L - c * c - std::pow(h - a * std::sin(th), 2));
    return -a * std::sin(th) + a * std::cos(th) * (h - a * std::sin(th)) / S;
  };
  const Index j = m.coordinate_index("xB");
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    const double th = tr.t[k], dh = 1e-5;
    EXPECT_NEAR(tr.q[k](j), xb(th), 1e-9) << th;
    EXPECT_NEAR(tr.qd[k](j), xbd(th), 1e-9) << th;
    EXPECT_NEAR(tr.qdd[k](j), (xbd(th + dh) - xbd(th - dh)) / (2 * dh), 1e-8) << th;
  }
}

}  // namespace
}  // namespace phiq

namespace phiq {
namespace {

// The planar redundant scene of models/redundant/: four reference-point bodies and six pins, 3 · 4 − 6 · 2 = 0,
// although the parallelogram moves with one degree of freedom.
TEST(RedundantScenes, ParallelogramWithFifthBarCountsZero) {
  const Scene s = load_scene(test::model_path("redundant/parallelogram_fifth_bar.yaml"));
  ASSERT_TRUE(s.model->grubler().has_value());
  EXPECT_EQ(*s.model->grubler(), 0);
}

// A body turning about a fixed axis at 0.25 + 1.7 t rad, 64 steps over 8 s: chunks of 16 steps, 3.4 rad each.
// A chunk's seed, found over that span at once, lands on −e (the same orientation), where the sweep in order
// follows e on continuously; the seed is turned to the sign its motion continues with before the chunk starts.
const char* kTurningBody = R"(phiq: 1
name: turning
dimension: 3
bodies:
  b: {at: [0, 0, 0]}
constraints:
  - {name: hinge, type: revolute,
     between: [{body: ground, axis: [0, 0, 1], ref: [1, 0, 0]}, {body: b, axis: [0, 0, 1], ref: [1, 0, 0]}]}
drivers:
  - {name: motor, joint: hinge, measure: angle, law: {type: linear, initial: 0.25, rate: 1.7}}
time: {start: 0, end: 8, steps: 64}
output: {velocities: true, accelerations: true}
)";

TEST(SpatialScenes, TurningBodyKeepsItsThreadsAcrossTheSignOfItsEulerParameters) {
  const Scene s = parse_scene(kTurningBody, "turning.yaml");
  const Model& m = *s.model;
  const Index e0 = m.coordinate_index("b_e0"), e3 = m.coordinate_index("b_e3");
  SweepOptions opt = s.sweep;
  test::Trace one, two, in_order;
  SweepSummary s1, s2, so;
  opt.threads = 1;
  ASSERT_EQ(test::sweep(m, opt, &one, &s1), SolveStatus::kSuccess) << s1.message;
  opt.threads = 2;
  ASSERT_EQ(test::sweep(m, opt, &two, &s2), SolveStatus::kSuccess) << s2.message;
  for (const SweepWarning& w : s2.warnings) ADD_FAILURE() << w.kind << " at t = " << w.t << ": " << w.message;
  EXPECT_EQ(s2.threads, 2);
  EXPECT_EQ(s2.parallel_chunks, 4);  // every chunk delivered as computed: none ran in order after a fallback
  ASSERT_EQ(two.t.size(), 65u);
  ASSERT_EQ(one.t.size(), 65u);
  opt.threads = 1, opt.chunk_steps = opt.steps;
  ASSERT_EQ(test::sweep(m, opt, &in_order, &so), SolveStatus::kSuccess) << so.message;
  for (std::size_t k = 0; k < two.t.size(); ++k) {
    SCOPED_TRACE("t = " + std::to_string(two.t[k]));
    // the same bits on one thread and two
    EXPECT_EQ(two.t[k], one.t[k]);
    EXPECT_TRUE(two.q[k] == one.q[k] && two.qd[k] == one.qd[k] && two.qdd[k] == one.qdd[k]);
    // e = (cos θ/2, 0, 0, sin θ/2), continuous from row 0: θ itself modulo 4π, not only the orientation (2π)
    const double theta = 0.25 + 1.7 * two.t[k];
    EXPECT_NEAR(std::remainder(2.0 * std::atan2(two.q[k][e3], two.q[k][e0]) - theta, 4.0 * M_PI), 0.0, 1e-10);
    EXPECT_NEAR(two.qd[k][e3], 0.85 * std::cos(theta / 2), 1e-10);
    EXPECT_NEAR((two.q[k] - in_order.q[k]).lpNorm<Eigen::Infinity>(), 0.0, 1e-10);
  }
}

// A sweep of `opt` with chunks of `chunk` rows on one thread and on two: no warning, every chunk delivered as
// computed, the same bits (q̇ and q̈ too with `rates`), and the body with Euler parameters `e0`…`e3` (indices)
// turned by theta(t) about its axis from row 0, continuously (θ modulo 4π: e, not −e).
void expect_chunks_keep_the_sign(const Model& m, SweepOptions opt, Index chunk, bool rates, Index e0, Index e3,
                                 const std::function<double(double)>& theta) {
  opt.chunk_steps = chunk;
  test::Trace one, two;
  SweepSummary s1, s2;
  opt.threads = 1;
  ASSERT_EQ(test::sweep(m, opt, &one, &s1), SolveStatus::kSuccess) << s1.message;
  opt.threads = 2;
  ASSERT_EQ(test::sweep(m, opt, &two, &s2), SolveStatus::kSuccess) << s2.message;
  for (const SweepWarning& w : s2.warnings) ADD_FAILURE() << w.kind << " at t = " << w.t << ": " << w.message;
  EXPECT_EQ(s2.parallel_chunks, (opt.steps + chunk - 1) / chunk);
  ASSERT_EQ(two.t.size(), static_cast<std::size_t>(opt.steps + 1));
  for (std::size_t k = 0; k < two.t.size(); ++k) {
    SCOPED_TRACE("t = " + std::to_string(two.t[k]));
    EXPECT_TRUE(two.q[k] == one.q[k]);
    if (rates) EXPECT_TRUE(two.qd[k] == one.qd[k] && two.qdd[k] == one.qdd[k]);
    EXPECT_NEAR(std::remainder(2.0 * std::atan2(two.q[k][e3], two.q[k][e0]) - theta(two.t[k]), 4.0 * M_PI), 0.0, 1e-9);
  }
}

// The same body spun up, θ = 0.25 + 10 t + 5 t² over 2 s in 40 steps, chunks of 10: 1 to 2.2 turns per chunk span;
// and, positions only, at 30 rad/s in 80 steps, chunks of 16: 1.9 turns. A constant rate from the two seeds before
// misses the turn by more than a half where the body speeds up, loses whole turns where it turns more than one, and
// a positions-only first seed, reached in sub-steps of 3 rad, may land on −e: a chunk's seed's sign was a guess and
// the chunk fell back to the sweep in order. Row 0's and each seed's ė and ë (solved by the seeding pass where the
// sweep does not) carry the turn to the next seed to second order: every chunk is delivered as computed, the same
// bits on one thread and two, and e continuous from row 0 (θ modulo 4π).
TEST(SpatialScenes, ASpunUpBodyKeepsItsThreadsAcrossTheSignOfItsEulerParameters) {
  struct Case {
    const char* law;
    const char* time;
    Index chunk;
    bool rates;
    double a1, a2;  // θ = 0.25 + a1 t + a2 t²
  };
  for (const Case& c : {Case{"[0.25, 10, 5]", "time: {start: 0, end: 2, steps: 40}", 10, true, 10, 5},
                        Case{"[0.25, 30, 0]", "time: {start: 0, end: 2, steps: 80}", 16, false, 30, 0}}) {
    SCOPED_TRACE(c.law);
    std::string text = kTurningBody;
    text = test::replace_first(text, "law: {type: linear, initial: 0.25, rate: 1.7}",
                               std::string("law: {type: polynomial, coefficients: ") + c.law + "}");
    text = test::replace_first(text, "time: {start: 0, end: 8, steps: 64}", c.time);
    if (!c.rates) text = test::replace_first(text, "output: {velocities: true, accelerations: true}\n", "");
    const Scene s = parse_scene(text, "spun_up.yaml");
    const Model& m = *s.model;
    expect_chunks_keep_the_sign(m, s.sweep, c.chunk, c.rates, m.coordinate_index("b_e0"), m.coordinate_index("b_e3"),
                                [&](double t) { return 0.25 + c.a1 * t + c.a2 * t * t; });
  }
}

// models/transmissions/screw_jack.yaml: the nut turned through θ = 3π sin t, three turns a second at the start and
// slowing. The second-order turn from a seed's rates misses the next seed by up to 2.4 rad there, too far for
// align() to be sure of the sign; the seeding pass now walks such a span in sub-steps of less than a quarter turn,
// following e as the sweep in order does: every chunk is delivered as computed, the same bits on one thread and two,
// e continuous from row 0 (θ modulo 4π).
TEST(SpatialScenes, AHarmonicScrewsNutKeepsItsThreads) {
  const Scene s = Load("transmissions/screw_jack.yaml");
  const Model& m = *s.model;
  expect_chunks_keep_the_sign(m, s.sweep, 15, true, m.coordinate_index("nut_e0"), m.coordinate_index("nut_e3"),
                              [](double t) { return 3 * M_PI * std::sin(t); });
}

TEST(SpatialScenes, CardanBranchSwitchFallsBackNamingTheBranch) {
  // The near-singular Cardan joint's chunk seeded on the other assembly mode (θ2 + π: another orientation, not
  // −e) is still refused at its seam, and the warning says it was another branch, not a failure or a sign: at the
  // coordinate farthest from the seam, how far in its own unit, and how closely two rows of one branch agree there
  // (the seam's 100 tolerances: 100 · 1e-10 · its scale), not "N tolerances".
  const Scene s = Load("spatial/cardan_near_singular.yaml");
  SweepOptions opt = s.sweep;
  opt.threads = 2;
  SweepSummary sum;
  test::Trace tr;
  ASSERT_EQ(test::sweep(*s.model, opt, &tr, &sum), SolveStatus::kSuccess) << sum.message;
  ASSERT_EQ(sum.warnings.size(), 1u);
  EXPECT_EQ(sum.warnings[0].kind, "parallel_fallback");
  const std::string& why = sum.warnings[0].message;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(why, m,
                                std::regex("did not continue the sweep in order: its first row is another branch: "
                                           "'([^']+)' is ([^ ]+)( m| rad)? from where the sweep in order arrives, "
                                           "where two rows of one branch agree to ±([^ ;]+)( m| rad)?; the "
                                           "remaining steps ran in order$")))
      << why;
  const Index j = s.model->coordinate_index(m[1].str());  // (throws on a name the model does not have)
  const std::string unit = unit_symbol(s.model->coordinate_unit(j));
  EXPECT_EQ(m[3].str(), unit.empty() ? "" : " " + unit) << why;
  EXPECT_EQ(m[5].str(), m[3].str()) << why;
  // another orientation: an Euler parameter, or an angle, a finite distance away (measured 'q0' is 1.01)
  const double far = std::stod(m[2].str()), agree = std::stod(m[4].str());
  EXPECT_GE(far, 0.1) << why;
  EXPECT_LE(far, unit == "m" ? 10.0 : 2 * M_PI) << why;
  const double seam = 100 * opt.newton.tolerance * s.model->tolerance_scales().coordinate_scale(j);
  EXPECT_NEAR(agree, seam, 0.05 * seam) << why;
  EXPECT_GT(far, agree) << why;
  ExpectCardanClosedForm(*s.model, tr, 89.0 * M_PI / 180.0, 1.5, "x2");
}

}  // namespace
}  // namespace phiq
