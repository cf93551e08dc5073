// The spatial higher pairs: the screw joint (kinds/screw.hpp), gears between shafts at an angle
// (kinds/spatial_gear.hpp) and the spatial mixed coordinates (kinds/spatial_mixed.hpp). Their derivatives against
// finite differences at random states (random, unnormalised Euler parameters, random axes and points), the scenes
// of models/transmissions/ against their closed forms to 1e-9 (a screw's z = p θ / 2π through several turns, a
// bevel pair's half-speed output, a spatial crank-slider in mixed coordinates), and the data they refuse.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <random>
#include <string>

#include "constraint_check.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

using kin3::V3;

// Coordinates of the random states: body 0 at 0..6, body 1 at 7..13, natural points at 14..16 and 17..19, angle
// coordinates at 20 and 21.
constexpr int kCoords = 22;
V3 Random(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return V3{u(rng), u(rng), u(rng)};
}
JointSide3 Side(const Frame3& f, std::mt19937& rng) {
  return JointSide3::body(f, Random(rng), Random(rng), Random(rng));
}

TEST(SpatialTransmissions, ScrewDerivatives) {
  std::mt19937 rng(2721);
  // Long pitches: at random states (unnormalised Euler parameters) the helical row moves fast, and with 2π/p large
  // the difference stencils of γ straddle its wrap at ±π (a jump of 2π). The k·d terms are still checked well above
  // the tolerance; screw_jack's closed form checks γ at a 4 mm pitch through its accelerations.
  for (double pitch : {50.0, -80.0}) {
    ScrewSpec s;
    s.a = Side(Body(0), rng), s.b = Side(Body(7), rng), s.pitch = pitch;
    s.setup();
    CheckSpec(s, kCoords, Opts(2722));
    s.a = Side(Frame3::ground(), rng);
    s.setup();
    CheckSpec(s, kCoords, Opts(2723));
  }
}

// `s` with every attachment's data moving at random rates (r̂, p̂ read where the slots are constants, ŝ).
template <class Spec>
Spec WithRandomAttachmentRates(const Spec& s, std::mt19937& rng) {
  Spec r = s;
  RandomizeAttachmentRates(r.att, rng);
  return r;
}

TEST(SpatialTransmissions, ScrewAlongItsData) {
  // the sides' attachments (points, axes, reference directions, a ground's place) and the pitch move
  std::mt19937 rng(2725);
  auto rate_of = [&](const ScrewSpec& s) {
    ScrewSpec r = WithRandomAttachmentRates(s, rng);
    r.pitch = 7.0 * std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
    return r;
  };
  for (double pitch : {50.0, -80.0}) {
    ScrewSpec s;
    s.a = Side(Body(0), rng), s.b = Side(Body(7), rng), s.pitch = pitch;
    s.setup();
    CheckDataDerivative(s, rate_of(s), kCoords, 2726, 3);
    s.a = Side(Frame3::ground(), rng);
    s.setup();
    CheckDataDerivative(s, rate_of(s), kCoords, 2727, 3);
  }
}

TEST(SpatialTransmissions, SpatialGearDerivatives) {
  std::mt19937 rng(2731);
  SpatialGearSpec g;  // shaft 1 in ground, shaft 2 in a housing on body 0 that moves (a carrier)
  g.a1 = Side(Frame3::ground(), rng), g.b1 = Side(Body(0), rng);
  g.a2 = Side(Body(0), rng), g.b2 = Side(Body(7), rng);
  g.theta1 = S(20), g.theta2 = S(21), g.z1 = 15, g.z2 = 40, g.phase = 0.3;
  g.setup();
  CheckSpec(g, kCoords, Opts(2732));
  g.reversed = true;
  CheckSpec(g, kCoords, Opts(2733));
}

TEST(SpatialTransmissions, SpatialGearAlongItsData) {
  // the shafts' attachments (housings, a ground's place and axes), the tooth counts and the phase
  std::mt19937 rng(2734);
  SpatialGearSpec g;
  g.a1 = Side(Frame3::ground(), rng), g.b1 = Side(Body(0), rng);
  g.a2 = Side(Body(0), rng), g.b2 = Side(Body(7), rng);
  g.theta1 = S(20), g.theta2 = S(21), g.z1 = 15, g.z2 = 40, g.phase = 0.3;
  g.setup();
  for (bool reversed : {false, true}) {
    g.reversed = reversed;
    SpatialGearSpec rate = g;
    RandomizeAttachmentRates(rate.att1, rng);
    RandomizeAttachmentRates(rate.att2, rng);
    rate.z1 = 2.0, rate.z2 = -3.0, rate.phase = 0.8;
    CheckDataDerivative(g, rate, kCoords, reversed ? 2736 : 2735);
  }
}

TEST(SpatialTransmissions, MixedCoordinateDerivatives) {
  std::mt19937 rng(2741);
  SpatialPolarSpec p;
  p.center = Side(Body(0), rng), p.point = Nat(14), p.radius = 0.6, p.theta = S(20);
  p.setup();
  CheckSpec(p, kCoords, Opts(2742));
  p.center = Side(Frame3::ground(), rng), p.radius = -1.3;
  p.setup();
  CheckSpec(p, kCoords, Opts(2743));

  SpatialAngleSpec r;  // a body's turn about another's axis
  r.a = Side(Body(0), rng), r.b = Side(Body(7), rng), r.theta = S(20);
  r.setup();
  CheckSpec(r, kCoords, Opts(2744));
  SpatialAngleSpec seg;  // a segment of natural points about a moving axis
  seg.segment = true, seg.a = Side(Body(7), rng), seg.from = Nat(14), seg.to = Nat(17), seg.theta = S(21);
  seg.setup();
  CheckSpec(seg, kCoords, Opts(2745));
}

TEST(SpatialTransmissions, MixedCoordinatesAlongTheirData) {
  std::mt19937 rng(2751);
  // the 3D polar: the centre's side through its attachments, the radius; then a constant θ that turns
  SpatialPolarSpec p;
  p.center = Side(Body(0), rng), p.point = Nat(14), p.radius = 0.6, p.theta = S(20);
  p.setup();
  SpatialPolarSpec rate = WithRandomAttachmentRates(p, rng);
  rate.radius = -0.4, rate.theta = Slot::constant(0.0);
  CheckDataDerivative(p, rate, kCoords, 2752);
  p.center = Side(Frame3::ground(), rng), p.radius = -1.3, p.theta = Slot::constant(0.7);
  p.setup();
  rate = WithRandomAttachmentRates(p, rng);
  rate.radius = 0.9, rate.theta = Slot::constant(1.2);
  CheckDataDerivative(p, rate, kCoords, 2753);
  // the rotation and segment angles, through their attachments
  SpatialAngleSpec r;
  r.a = Side(Body(0), rng), r.b = Side(Body(7), rng), r.theta = S(20);
  r.setup();
  CheckDataDerivative(r, WithRandomAttachmentRates(r, rng), kCoords, 2754);
  SpatialAngleSpec seg;
  seg.segment = true, seg.a = Side(Frame3::ground(), rng), seg.from = Nat(14), seg.to = Nat(17), seg.theta = S(21);
  seg.setup();
  CheckDataDerivative(seg, WithRandomAttachmentRates(seg, rng), kCoords, 2755);
}

TEST(SpatialTransmissions, ScrewRisesOnePitchPerTurn) {
  const test::SweptScene run = test::sweep_scene("transmissions/screw_jack.yaml");
  const Model& m = *run.scene.model;
  ASSERT_EQ(run.status, SolveStatus::kSuccess) << run.summary.message;
  const test::Trace& tr = run.trace;
  EXPECT_EQ(m.grubler(), std::optional<Index>(1));
  const Index z = m.coordinate_index("nut_z"), e0 = m.coordinate_index("nut_e0"), e3 = m.coordinate_index("nut_e3");
  ASSERT_EQ(tr.t.size(), 91u);
  const double p = 0.004, k = p / (2 * M_PI);
  for (std::size_t i = 0; i < tr.t.size(); ++i) {
    const double t = tr.t[i], th = 3 * M_PI * std::sin(t), w = 3 * M_PI * std::cos(t), a = -th;
    EXPECT_NEAR(tr.q[i](z), k * th, 1e-9);
    EXPECT_NEAR(tr.qd[i](z), k * w, 1e-9);
    EXPECT_NEAR(tr.qdd[i](z), k * a, 1e-9);
    EXPECT_NEAR(tr.q[i](e0), std::cos(th / 2), 1e-9);
    EXPECT_NEAR(tr.q[i](e3), std::sin(th / 2), 1e-9);
    EXPECT_NEAR(tr.qd[i](e3), std::cos(th / 2) * w / 2, 1e-9);
    EXPECT_NEAR(tr.qdd[i](e3), std::cos(th / 2) * a / 2 - std::sin(th / 2) * w * w / 4, 1e-9);
  }
}

TEST(SpatialTransmissions, BevelPairTurnsItsOutputAtHalfSpeedTheOtherWay) {
  const test::SweptScene run = test::sweep_scene("transmissions/bevel_gears.yaml");
  const Model& m = *run.scene.model;
  ASSERT_EQ(run.status, SolveStatus::kSuccess) << run.summary.message;
  const test::Trace& tr = run.trace;
  EXPECT_EQ(m.grubler(), std::optional<Index>(1));
  CheckModel(m, 2734);  // the whole model's Jacobian, Φt and γ through its CSC pattern
  const Index th2 = m.coordinate_index("theta2"), e0 = m.coordinate_index("s2_e0"), e2 = m.coordinate_index("s2_e2");
  const Index f0 = m.coordinate_index("s1_e0"), f1 = m.coordinate_index("s1_e1");
  ASSERT_EQ(tr.t.size(), 61u);
  for (std::size_t i = 0; i < tr.t.size(); ++i) {
    const double t = tr.t[i], a1 = 2 * t + 0.5 * t * t, w1 = 2 + t;  // θ1 reaches 10.5 rad: over a turn and a half
    const double a2 = -a1 / 2, w2 = -w1 / 2, acc2 = -0.5;
    EXPECT_NEAR(tr.q[i](th2), a2, 1e-9);
    EXPECT_NEAR(tr.qd[i](th2), w2, 1e-9);
    EXPECT_NEAR(tr.qdd[i](th2), acc2, 1e-9);
    // the bodies: the input turned by θ1 about x, the output by θ2 about y
    EXPECT_NEAR(tr.q[i](f0), std::cos(a1 / 2), 1e-9);
    EXPECT_NEAR(tr.q[i](f1), std::sin(a1 / 2), 1e-9);
    EXPECT_NEAR(tr.q[i](e0), std::cos(a2 / 2), 1e-9);
    EXPECT_NEAR(tr.q[i](e2), std::sin(a2 / 2), 1e-9);
    EXPECT_NEAR(tr.qd[i](e2), std::cos(a2 / 2) * w2 / 2, 1e-9);
    EXPECT_NEAR(tr.qdd[i](e2), std::cos(a2 / 2) * acc2 / 2 - std::sin(a2 / 2) * w2 * w2 / 4, 1e-9);
  }
}

TEST(SpatialTransmissions, SpatialCrankSliderInMixedCoordinates) {
  const test::SweptScene run = test::sweep_scene("transmissions/spatial_crank_mixed.yaml");
  const Model& m = *run.scene.model;
  ASSERT_EQ(run.status, SolveStatus::kSuccess) << run.summary.message;
  const test::Trace& tr = run.trace;
  const Index xa = m.coordinate_index("xA"), ya = m.coordinate_index("yA"), za = m.coordinate_index("zA"),
              xb = m.coordinate_index("xB"), phi = m.coordinate_index("phi");
  ASSERT_EQ(tr.t.size(), 73u);
  const double s2 = std::sqrt(2.0);
  const V3 x{4 / (3 * s2), -1 / (3 * s2), -1 / (3 * s2)}, y{0, 1 / s2, -1 / s2};
  for (std::size_t i = 0; i < tr.t.size(); ++i) {
    const double th = tr.t[i], c = std::cos(th), s = std::sin(th);  // θ = t: d/dt = d/dθ
    const V3 A = 0.3 * (c * x + s * y), Ad = 0.3 * (-s * x + c * y), Add = -1.0 * A;
    const double g = 1 - (0.2 - A.y) * (0.2 - A.y) - (0.1 - A.z) * (0.1 - A.z);
    const double gd = 2 * (0.2 - A.y) * Ad.y + 2 * (0.1 - A.z) * Ad.z;
    const double gdd = 2 * (-Ad.y * Ad.y + (0.2 - A.y) * Add.y) + 2 * (-Ad.z * Ad.z + (0.1 - A.z) * Add.z);
    const double X = std::sqrt(g), Xd = gd / (2 * X), Xdd = gdd / (2 * X) - gd * gd / (4 * g * X);
    const double Y = 0.2 - A.y, Yd = -Ad.y, Ydd = -Add.y;
    const double r2 = X * X + Y * Y, num = X * Yd - Y * Xd;
    EXPECT_NEAR(tr.q[i](xa), A.x, 1e-9);
    EXPECT_NEAR(tr.q[i](ya), A.y, 1e-9);
    EXPECT_NEAR(tr.q[i](za), A.z, 1e-9);
    EXPECT_NEAR(tr.qd[i](za), Ad.z, 1e-9);
    EXPECT_NEAR(tr.qdd[i](xa), Add.x, 1e-9);
    EXPECT_NEAR(tr.q[i](xb), A.x + X, 1e-9);
    EXPECT_NEAR(tr.qd[i](xb), Ad.x + Xd, 1e-9);
    EXPECT_NEAR(tr.qdd[i](xb), Add.x + Xdd, 1e-9);
    EXPECT_NEAR(tr.q[i](phi), std::atan2(Y, X), 1e-9);
    EXPECT_NEAR(tr.qd[i](phi), num / r2, 1e-9);
    EXPECT_NEAR(tr.qdd[i](phi), ((X * Ydd - Y * Xdd) * r2 - num * 2 * (X * Xd + Y * Yd)) / (r2 * r2), 1e-9);
  }
}

TEST(SpatialTransmissions, RefusesBadDataNamingTheConstraint) {
  const std::string head =
      "phiq: 1\ndimension: 3\ncoordinates: {x: 0, y: 0, z: 0, e0: 1, e1: 0, e2: 0, e3: 0, u: 0, v: 0, w: 0, "
      "a: 0, b: 0}\nbodies: {s: [x, y, z, e0, e1, e2, e3]}\npoints: {P: [u, v, w]}\n"
      "time: {start: 0, end: 1, steps: 1}\nconstraints:\n"
      "  - {name: h1, type: revolute, between: [{body: ground, axis: [1, 0, 0]}, {body: s, axis: [1, 0, 0]}]}\n"
      "  - {name: h2, type: revolute, between: [{body: ground, axis: [2, 0, 0]}, {body: s, axis: [1, 0, 0]}]}\n"
      "  - {name: sl, type: prismatic, between: [{body: ground}, {body: s}]}\n";
  EXPECT_EQ(test::scene_error(head + "  - {name: sc, type: screw, between: [{body: ground}, {body: s}], pitch: 0}\n"),
            "bad.yaml:11:5: constraints[3]: constraint 'sc': screw: the pitch must not be zero (a screw of no "
            "pitch is a revolute joint)");
  // parallel shafts mesh (spur and helical gears: tests/test_helical_meshes.cpp); a helix or a mesh offset is theirs
  EXPECT_EQ(test::scene_error(head + "  - {name: g, type: spatial_gear, shafts: [h1, h2], angles: [a, b], teeth: [9, "
                                     "9], helix_angle: 1.6}\n"),
            "bad.yaml:11:5: constraints[3]: constraint 'g': spatial_gear: helix_angle must be in (-pi/2, pi/2) rad");
  EXPECT_EQ(test::scene_error(
                test::replace_first(head, "{body: ground, axis: [2, 0, 0]}", "{body: ground, axis: [0, 2, 0]}") +
                "  - {name: g, type: spatial_gear, shafts: [h1, h2], angles: [a, b], teeth: [9, 9], "
                "mesh_offset: 0.1}\n"),
            "bad.yaml:11:5: constraints[3]: constraint 'g': spatial_gear: helix_angle and mesh_offset are for parallel "
            "shafts (these are not at the placement)");
  EXPECT_EQ(
      test::scene_error(head + "  - {name: g, type: spatial_gear, shafts: [h1, h1], angles: [a, b], teeth: [9, 9]}\n"),
      "bad.yaml:11:43: constraints[3].shafts: the two shafts must be different joints");
  EXPECT_EQ(
      test::scene_error(head + "  - {name: g, type: spatial_gear, shafts: [h1, sl], angles: [a, b], teeth: [9, 9]}\n"),
      "bad.yaml:11:48: constraints[3].shafts[1]: joint 'sl' is a prismatic joint: a shaft turns in a revolute, "
      "cylindrical or screw joint");
  EXPECT_EQ(test::scene_error(head + "  - {name: c, type: polar, point: P, radius: 0, angle: a}\n"),
            "bad.yaml:11:5: constraints[3]: constraint 'c': polar: the radius is zero (the angle would be "
            "undetermined)");
  EXPECT_EQ(test::scene_error(head + "  - {name: c, type: segment_angle, segment: [P, P], angle: a}\n"),
            "bad.yaml:11:5: constraints[3]: constraint 'c': segment_angle: the segment's two ends are the same point");
  EXPECT_EQ(test::scene_error(head + "  - {name: c, type: gear, between: [s, a], teeth: [9, 9]}\n"),
            "bad.yaml:11:37: constraints[3].between[0]: 's' is a body: in dimension 3 a transmission relates angle "
            "coordinates (define the body's rotation about its axis with a rotation_angle constraint)");
  EXPECT_EQ(test::scene_error(head + "  - {name: c, type: rotation_angle, joint: sl, angle: a}\n"),
            "bad.yaml:11:44: constraints[3].joint: joint 'sl' is a prismatic joint: a shaft turns in a revolute, "
            "cylindrical or screw joint");
  EXPECT_EQ(test::scene_error(head + "  - {name: c, type: rotation_angle, angle: a}\n"),
            "bad.yaml:11:5: constraints[3]: give either 'between: [S1, S2]' or 'joint: NAME' (a revolute, "
            "cylindrical or screw joint)");
}

}  // namespace
}  // namespace phiq
