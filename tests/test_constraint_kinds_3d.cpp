// Derivative checks of every spatial kind in constraint_kinds_3d.hpp (as test_constraint_kinds.cpp does for the
// planar ones, with the same machinery: constraint_check.hpp): Jacobian entries, Φt and γ against finite
// differences at random states (random, unnormalised Euler parameters, random local points, axes and reference
// directions), the entry sequence independent of the values. Then what the rows mean at exact configurations
// (a revolute about its axis, an angle over several turns), the errors of bad sides, a whole Model through its CSC
// pattern, and the Grübler–Kutzbach count of Model::grubler().
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "constraint_check.hpp"
#include "phiq/constraint_kinds.hpp"
#include "phiq/constraint_kinds_3d.hpp"
#include "phiq/model.hpp"
#include "phiq/motion_law.hpp"
#include "phiq/sweep.hpp"

namespace {

using phiq::Frame3;
using phiq::JointSide3;
using phiq::Point3;
using phiq::kin3::V3;

// Coordinates of the random states: body 0 at 0..6, body 1 at 7..13 (x, y, z, e0..e3), a natural point at 14..16,
// a natural vector at 17..19, a second natural point at 20..22.
constexpr int kN = 23;

// Local data of a side, fixed per test from its own seed: points in [-1, 1]³, axes and references random.
V3 RandomVector(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return V3{u(rng), u(rng), u(rng)};
}
JointSide3 BodySide(Index first, std::mt19937& rng) {
  return JointSide3::body(Body(first), RandomVector(rng), RandomVector(rng), RandomVector(rng));
}
JointSide3 GroundSide(std::mt19937& rng) {
  return JointSide3::body(Frame3::ground(), RandomVector(rng), RandomVector(rng), RandomVector(rng));
}

template <class Spec>
Spec Joint(const JointSide3& a, const JointSide3& b) {
  Spec s;
  s.a = a, s.b = b;
  s.setup();
  return s;
}

// A joint's derivatives along its data (CheckDataDerivative), every attachment moving at random rates.
template <class Spec>
void CheckJointAlongItsData(const Spec& joint, std::mt19937& rng, std::uint32_t seed) {
  Spec rate = joint;
  RandomizeAttachmentRates(rate.att, rng);
  CheckDataDerivative(joint, rate, kN, seed, 3);
}

// Every joint type between two moving bodies, and with ground on either side; with its derivatives along its data.
template <class Spec>
void CheckJoint(std::uint32_t seed) {
  std::mt19937 rng(seed);
  {
    SCOPED_TRACE("body - body");
    const Spec j = Joint<Spec>(BodySide(0, rng), BodySide(7, rng));
    CheckSpec(j, kN, Opts(seed));
    CheckJointAlongItsData(j, rng, seed + 5);
  }
  {
    SCOPED_TRACE("ground - body");
    const Spec j = Joint<Spec>(GroundSide(rng), BodySide(7, rng));
    CheckSpec(j, kN, Opts(seed + 1));
    CheckJointAlongItsData(j, rng, seed + 6);
  }
  {
    SCOPED_TRACE("body - ground");
    const Spec j = Joint<Spec>(BodySide(0, rng), GroundSide(rng));
    CheckSpec(j, kN, Opts(seed + 2));
    CheckJointAlongItsData(j, rng, seed + 7);
  }
}

// ---- normalisations ---------------------------------------------------------------------------------------------

TEST(ConstraintKinds3d, EulerParameters) {
  CheckSpec(phiq::EulerParametersSpec{{S(3), S(4), S(5), S(6)}}, 7, Opts(301));
  // the row is (|p|² − 1) / 2: zero on the unit sphere, whatever the orientation
  const phiq::EulerParametersSpec e{{S(0), S(1), S(2), S(3)}};
  const double q[4] = {0.5, -0.5, 0.5, 0.5}, q2[4] = {2, 0, 0, 0};
  double phi = 1.0;
  e.residual(q, 0.0, &phi);
  EXPECT_EQ(phi, 0.0);
  e.residual(q2, 0.0, &phi);
  EXPECT_EQ(phi, 1.5);
}

TEST(ConstraintKinds3d, UnitVector) { CheckSpec(phiq::UnitVectorSpec{Nat(17)}, kN, Opts(302)); }

// ---- joints -----------------------------------------------------------------------------------------------------

TEST(ConstraintKinds3d, Spherical) { CheckJoint<phiq::SphericalSpec>(310); }
TEST(ConstraintKinds3d, Revolute) { CheckJoint<phiq::SpatialRevoluteSpec>(320); }
TEST(ConstraintKinds3d, Prismatic) { CheckJoint<phiq::SpatialPrismaticSpec>(330); }
TEST(ConstraintKinds3d, Cylindrical) { CheckJoint<phiq::CylindricalSpec>(340); }
TEST(ConstraintKinds3d, Universal) { CheckJoint<phiq::UniversalSpec>(350); }
TEST(ConstraintKinds3d, Planar) { CheckJoint<phiq::PlanarSpec>(360); }
TEST(ConstraintKinds3d, Rigid) { CheckJoint<phiq::RigidSpec>(370); }
TEST(ConstraintKinds3d, PointOnLine) { CheckJoint<phiq::SpatialPointOnLineSpec>(380); }
TEST(ConstraintKinds3d, PointOnPlane) { CheckJoint<phiq::PointOnPlaneSpec>(390); }

// A fixed frame turned by 60° about (1, 2, 2)/3, away from the origin: its attachments are constants, which setup
// folds into their values (Attachment3::fold_constant). Against Rodrigues' formula, bit for bit against the
// unfolded evaluation, and through the derivative checks as one side of every joint.
TEST(ConstraintKinds3d, ConstantAttachmentsFoldToTheirValue) {
  const double half = M_PI / 6.0;
  const V3 u{1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0};
  const Frame3 fixed{C(0.3),
                     C(-1.2),
                     C(2.0),
                     C(std::cos(half)),
                     C(std::sin(half) * u.x),
                     C(std::sin(half) * u.y),
                     C(std::sin(half) * u.z)};
  const V3 at{0.4, -0.7, 1.1};
  const phiq::Attachment3 point = phiq::Attachment3::body_point(fixed, at);
  phiq::Attachment3 folded = point;
  folded.fold_constant();
  EXPECT_TRUE(point.rotates());
  EXPECT_FALSE(folded.rotates());
  const V3 x = point.value(nullptr), y = folded.value(nullptr);
  EXPECT_EQ(x.x, y.x);  // the same arithmetic, once: equal to the last bit
  EXPECT_EQ(x.y, y.y);
  EXPECT_EQ(x.z, y.z);
  // Rodrigues: R at = cos φ at + sin φ (u × at) + (1 − cos φ)(u · at) u, φ = 60°
  const double c = std::cos(2 * half), n = std::sin(2 * half);
  const V3 rodrigues =
      phiq::kin3::V3{0.3, -1.2, 2.0} + c * at + n * phiq::kin3::cross(u, at) + ((1.0 - c) * phiq::kin3::dot(u, at)) * u;
  EXPECT_NEAR(y.x, rodrigues.x, 1e-15);
  EXPECT_NEAR(y.y, rodrigues.y, 1e-15);
  EXPECT_NEAR(y.z, rodrigues.z, 1e-15);
  const double q[kN] = {}, qd[kN] = {};
  const V3 v = folded.rate(q, qd), b = folded.bias(qd);
  for (double e : {v.x, v.y, v.z, b.x, b.y, b.z}) EXPECT_EQ(e, 0.0);
  // an attachment that reads coordinates is left as it is
  std::mt19937 rng(400);
  const phiq::Attachment3 moving = phiq::Attachment3::body_point(Body(0), at);
  phiq::Attachment3 kept = moving;
  kept.fold_constant();
  std::vector<double> state(kN);
  for (double& e : state) e = std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
  EXPECT_TRUE(kept.rotates());
  EXPECT_EQ(kept.value(state.data()).x, moving.value(state.data()).x);
  EXPECT_EQ(kept.r[0].coord(), 0);
  EXPECT_EQ(kept.p[3].coord(), 6);
  // every joint with the rotated fixed frame on one side: derivatives against finite differences
  const JointSide3 side = JointSide3::body(fixed, at, RandomVector(rng), RandomVector(rng));
  CheckSpec(Joint<phiq::SpatialRevoluteSpec>(side, BodySide(7, rng)), kN, Opts(401));
  CheckSpec(Joint<phiq::PointOnPlaneSpec>(BodySide(0, rng), side), kN, Opts(402));
  CheckSpec(Joint<phiq::UniversalSpec>(side, JointSide3::natural_point(Nat(14), Nat(17))), kN, Opts(403));
}

// A joint stores only the attachments its rows read (SpatialJointSpec::kCompact): the distinct ones of its row
// table, in index order, and every renumbered term names the attachment it named before.
template <class Traits>
void CheckCompactRows() {
  using Spec = phiq::SpatialJointSpec<Traits>;
  constexpr auto c = Spec::kCompact;
  std::set<int> named;
  for (const auto& d : Traits::kRowDefs)
    for (const phiq::detail3::Term& t : {d.x, d.y}) {
      if (t.plus >= 0) named.insert(t.plus);
      if (t.minus >= 0) named.insert(t.minus);
    }
  ASSERT_EQ(c.count, static_cast<int>(named.size())) << Traits::kKind;
  EXPECT_EQ(std::tuple_size<decltype(Spec::att)>::value, named.size()) << Traits::kKind;
  EXPECT_TRUE(std::equal(named.begin(), named.end(), c.index, c.index + c.count)) << Traits::kKind;
  auto back = [&](int compact) { return compact < 0 ? compact : static_cast<int>(c.index[compact]); };
  for (int r = 0; r < Traits::kRows; ++r) {
    const auto &full = Traits::kRowDefs[r], &mine = c.rows[r];
    EXPECT_EQ(mine.unit, full.unit);
    for (const auto& [f, m] : {std::pair{full.x, mine.x}, std::pair{full.y, mine.y}}) {
      EXPECT_EQ(m.axis, f.axis) << Traits::kKind << " row " << r;
      EXPECT_EQ(back(m.plus), f.plus) << Traits::kKind << " row " << r;
      EXPECT_EQ(back(m.minus), f.minus) << Traits::kKind << " row " << r;
    }
  }
}

TEST(ConstraintKinds3d, JointsStoreOnlyTheAttachmentsTheirRowsRead) {
  namespace j = phiq::joint3;
  CheckCompactRows<j::Spherical>(), CheckCompactRows<j::Revolute>(), CheckCompactRows<j::Cylindrical>();
  CheckCompactRows<j::Prismatic>(), CheckCompactRows<j::Universal>(), CheckCompactRows<j::Planar>();
  CheckCompactRows<j::Rigid>(), CheckCompactRows<j::PointOnLine>(), CheckCompactRows<j::PointOnPlane>();
  // the two of the large generated scenes, by hand: a ball joint reads P_a and P_b, a point on a plane also z_a
  EXPECT_EQ(phiq::SphericalSpec::kCompact.count, 2);
  EXPECT_EQ(phiq::PointOnPlaneSpec::kCompact.count, 3);
  EXPECT_EQ(sizeof(phiq::PointOnPlaneSpec), 2 * sizeof(JointSide3) + 3 * sizeof(phiq::Attachment3));
}

TEST(ConstraintKinds3d, JointsWithNaturalSides) {
  std::mt19937 rng(400);
  // a body point pinned to a natural point (mixed coordinates)
  CheckSpec(Joint<phiq::SphericalSpec>(BodySide(0, rng), JointSide3::natural_point(Nat(14))), kN, Opts(401));
  // two natural points
  CheckSpec(Joint<phiq::SphericalSpec>(JointSide3::natural_point(Nat(20)), JointSide3::natural_point(Nat(14))), kN,
            Opts(402));
  // a revolute whose side b is a natural point and vector
  CheckSpec(Joint<phiq::SpatialRevoluteSpec>(BodySide(0, rng), JointSide3::natural_point(Nat(14), Nat(17))), kN,
            Opts(403));
  // a universal joint between two natural vectors' ends (the cross: u · v = 0)
  CheckSpec(Joint<phiq::UniversalSpec>(JointSide3::natural_point(Nat(20), Nat(17)), BodySide(7, rng)), kN, Opts(404));
  // a natural point on a body's plane, on a body's line
  CheckSpec(Joint<phiq::PointOnPlaneSpec>(BodySide(0, rng), JointSide3::natural_point(Nat(14))), kN, Opts(405));
  CheckSpec(Joint<phiq::SpatialPointOnLineSpec>(BodySide(7, rng), JointSide3::natural_point(Nat(20))), kN, Opts(406));
}

// ---- natural-coordinate rigid-body conditions ---------------------------------------------------------------------

TEST(ConstraintKinds3d, Distance) {
  phiq::SpatialDistanceSpec between_points{
      {phiq::Attachment3::natural(Nat(14)), phiq::Attachment3::natural(Point3{S(20), C(0.3), S(22)})}, 1.7};
  CheckSpec(between_points, kN, Opts(410));
  // a bar with ball joints at two body points
  phiq::SpatialDistanceSpec between_bodies{{phiq::Attachment3::body_point(Body(0), V3{0.3, -0.2, 0.5}),
                                            phiq::Attachment3::body_point(Body(7), V3{-1, 0.4, 0})},
                                           0.45};
  CheckSpec(between_bodies, kN, Opts(411));
  // derivatives along the length and the ends: the natural point's constant y, the bodies' local points
  std::mt19937 rng(414);
  phiq::SpatialDistanceSpec rate = between_points, body_rate = between_bodies;
  rate.length = -0.6, body_rate.length = 1.3;
  RandomizeAttachmentRates(rate.ends, rng);
  RandomizeAttachmentRates(body_rate.ends, rng);
  CheckDataDerivative(between_points, rate, kN, 412);
  CheckDataDerivative(between_bodies, body_rate, kN, 413);
  // a bar from a ground point that moves (folded into constants) to a body
  phiq::SpatialDistanceSpec grounded{{phiq::Attachment3::body_point(Frame3::ground(), V3{0.5, 0.2, -0.3}),
                                      phiq::Attachment3::body_point(Body(7), V3{-1, 0.4, 0})},
                                     1.1};
  grounded.prepare(nullptr);
  phiq::SpatialDistanceSpec ground_rate = grounded;
  RandomizeAttachmentRates(ground_rate.ends, rng);
  ground_rate.length = 0.0;
  CheckDataDerivative(grounded, ground_rate, kN, 415);
}

TEST(ConstraintKinds3d, DotOfVectorsAndSegments) {
  using phiq::Attachment3;
  phiq::DotSpec vv;  // u · v = cos α between two natural vectors
  vv.ends[0] = Attachment3::natural(Nat(17)), vv.ends[1] = Attachment3::zero();
  vv.ends[2] = Attachment3::natural(Nat(14)), vv.ends[3] = Attachment3::zero();
  vv.end_units[0] = vv.end_units[1] = phiq::Unit::kNone;
  vv.value = 0.3;
  CheckSpec(vv, kN, Opts(420));
  phiq::DotSpec vs;  // u · (B − A), with a ref as the builder sets it
  vs.ends[0] = Attachment3::natural(Nat(17)), vs.ends[1] = Attachment3::zero();
  vs.ends[2] = Attachment3::natural(Nat(20)), vs.ends[3] = Attachment3::natural(Nat(14));
  vs.end_units[0] = phiq::Unit::kNone;
  vs.value = -0.8, vs.ref = 1.3;
  CheckSpec(vs, kN, Opts(421));
  // along its data: c, ref, and the ends' data (the natural ends' none; a body's axis and a ground point)
  std::mt19937 rng(422);
  phiq::DotSpec rate = vs;
  RandomizeAttachmentRates(rate.ends, rng);
  rate.value = 0.7, rate.ref = -0.4;
  CheckDataDerivative(vs, rate, kN, 423);
  phiq::DotSpec bodies;  // a body's axis across a segment from a ground point to a body's point
  bodies.ends[0] = Attachment3::body_vector(Body(0), V3{0.3, -0.6, 0.2}), bodies.ends[1] = Attachment3::zero();
  bodies.ends[2] = Attachment3::body_point(Body(7), V3{0.5, 0.1, -0.4});
  bodies.ends[3] = Attachment3::body_point(Frame3::ground(), V3{-0.2, 0.9, 0.3});
  bodies.end_units[0] = phiq::Unit::kNone;
  bodies.value = 0.1, bodies.ref = 0.9;
  CheckSpec(bodies, kN, Opts(424));
  rate = bodies;
  RandomizeAttachmentRates(rate.ends, rng);
  rate.value = -0.3, rate.ref = 0.2;
  CheckDataDerivative(bodies, rate, kN, 425);
}

// ---- drivers ------------------------------------------------------------------------------------------------------

TEST(ConstraintKinds3d, JointAngleDriver) {
  std::mt19937 rng(430);
  phiq::JointAngleDriverSpec d;
  d.a = BodySide(0, rng), d.b = BodySide(7, rng);
  d.law = phiq::MotionLaw::harmonic(0.4, 2.5, 1.3, 0.2);
  d.setup();
  CheckSpec(d, kN, Opts(431, true));
  // along its data: the law, then the attachments (the reference directions) too
  phiq::JointAngleDriverSpec rate = d;
  rate.law = phiq::MotionLaw::polynomial({0.3, -1.2, 0.5});
  CheckDataDerivative(d, rate, kN, 451);
  RandomizeAttachmentRates(rate.att, rng);
  CheckDataDerivative(d, rate, kN, 454);
  d.a = GroundSide(rng);
  d.law = phiq::MotionLaw::polynomial({0.1, -3.0, 0.7});
  d.setup();
  CheckSpec(d, kN, Opts(432, true));
  rate = d;
  RandomizeAttachmentRates(rate.att, rng);
  CheckDataDerivative(d, rate, kN, 455);
}

TEST(ConstraintKinds3d, JointDistanceDriver) {
  std::mt19937 rng(440);
  phiq::JointDistanceDriverSpec d;
  d.a = BodySide(0, rng), d.b = BodySide(7, rng);
  d.law = phiq::MotionLaw::harmonic(0.1, 0.5, 2.0, 0.0);
  d.setup();
  CheckSpec(d, kN, Opts(441, true));
  // along its data: the law, then the attachments too, from ground
  d.b = GroundSide(rng);
  d.setup();
  phiq::JointDistanceDriverSpec rate = d;
  rate.law = phiq::MotionLaw::polynomial({0.2, 0.4});
  CheckDataDerivative(d, rate, kN, 452);
  RandomizeAttachmentRates(rate.att, rng);
  CheckDataDerivative(d, rate, kN, 453);
}

// ---- what the rows mean -------------------------------------------------------------------------------------------

// Euler parameters of a rotation by `angle` about the unit axis u.
std::vector<double> Quaternion(V3 u, double angle) {
  const double s = std::sin(angle / 2);
  return {std::cos(angle / 2), s * u.x, s * u.y, s * u.z};
}

TEST(ConstraintKinds3d, RevoluteHoldsAboutItsAxisAndTheDriverMeasuresFullTurns) {
  // body about the ground axis (1, 2, 2)/3 through (0.5, −1, 2); the body's local point is (0.5, −1, 2) − r
  const V3 axis{1.0 / 3, 2.0 / 3, 2.0 / 3}, pivot{0.5, -1.0, 2.0};
  for (double angle : {0.0, 1.0, 3.0, -3.0, 7.0, -12.5}) {
    SCOPED_TRACE("angle " + std::to_string(angle));
    // body frame: reference point r0 = pivot + R (−local), with local = (0.2, 0.1, −0.3) in the body
    const std::vector<double> p = Quaternion(axis, angle);
    const V3 local{0.2, 0.1, -0.3};
    const V3 r = pivot - phiq::kin3::rotate(p.data(), local);
    const std::vector<double> q = {r.x, r.y, r.z, p[0], p[1], p[2], p[3]};
    JointSide3 g = JointSide3::body(Frame3::ground(), pivot, axis, V3{0, 1, -1});
    JointSide3 b = JointSide3::body(Body(0), local, axis, V3{0, 1, -1});
    auto rev = Joint<phiq::SpatialRevoluteSpec>(g, b);
    double phi[5];
    rev.residual(q.data(), 0.0, phi);
    for (double v : phi) EXPECT_NEAR(v, 0.0, 1e-14);
    // the angle driver with f = angle is zero; with f = angle + 0.25 it is −0.25 (wrapped differences are exact)
    phiq::JointAngleDriverSpec d;
    d.a = g, d.b = b, d.law = phiq::MotionLaw::linear(angle, 0.0);
    d.setup();
    double a = 1.0;
    d.residual(q.data(), 0.0, &a);
    EXPECT_NEAR(a, 0.0, 1e-13);
    d.law = phiq::MotionLaw::linear(angle + 0.25, 0.0);
    d.residual(q.data(), 0.0, &a);
    EXPECT_NEAR(a, -0.25, 1e-13);
    // a prismatic on the same axis is violated only by the rotation: y_a · x_b = sin(angle)
    auto pri = Joint<phiq::SpatialPrismaticSpec>(g, b);
    double pp[5];
    pri.residual(q.data(), 0.0, pp);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(pp[k], 0.0, 1e-14);
    EXPECT_NEAR(pp[4], std::sin(angle), 1e-14);
  }
}

TEST(ConstraintKinds3d, BadSidesAreErrors) {
  auto setup_error = [](auto spec) -> std::string {
    try {
      spec.setup();
    } catch (const phiq::Error& e) {
      return e.what();
    }
    return "";
  };
  phiq::SpatialRevoluteSpec r;
  r.a = JointSide3::body(Frame3::ground(), V3{}, V3{0, 0, 0});
  r.b = JointSide3::body(Body(0), V3{});
  EXPECT_NE(setup_error(r).find("revolute: side a: axis must not be zero"), std::string::npos) << setup_error(r);
  r.a = JointSide3::body(Frame3::ground(), V3{}, V3{0, 0, 1}, V3{0, 0, 2});
  EXPECT_NE(setup_error(r).find("ref must not be zero or along the axis"), std::string::npos);
  r.a = JointSide3::natural_point(Nat(14), Nat(17));
  EXPECT_NE(setup_error(r).find("side a: needs a body or ground"), std::string::npos);
  r.a = JointSide3::body(Frame3::ground(), V3{});
  r.b = JointSide3::natural_point(Nat(14));
  EXPECT_NE(setup_error(r).find("side b: needs an axis"), std::string::npos);
  r.b = JointSide3::body(Body(0), V3{std::nan(""), 0, 0});
  EXPECT_NE(setup_error(r).find("point is not finite"), std::string::npos);
}

// ---- Model plumbing and the Grübler–Kutzbach count -------------------------------------------------------------

phiq::Frame3 AddBody(phiq::ModelBuilder& b, const std::string& name) {
  Index i = b.add_coordinate(name + "_x", 0.1);
  for (const char* c : {"_y", "_z", "_e0", "_e1", "_e2", "_e3"}) b.add_coordinate(name + c, 0.2);
  const Frame3 f = Body(i);
  b.add_body(name, f);
  return f;
}

TEST(ConstraintKinds3d, ModelOfSpatialKindsThroughItsPattern) {
  phiq::ModelBuilder b;
  const Frame3 crank = AddBody(b, "crank"), rocker = AddBody(b, "rocker");
  b.add("hinge", phiq::SpatialRevoluteSpec{
                     JointSide3::body(Frame3::ground(), V3{0, 0, 0}), JointSide3::body(crank, V3{0, 0, 0}), {}});
  b.add("pivot", phiq::SpatialRevoluteSpec{JointSide3::body(Frame3::ground(), V3{1, 0.5, 0}, V3{1, 0, 0}),
                                           JointSide3::body(rocker, V3{0, 0, 0}, V3{1, 0, 0}),
                                           {}});
  b.add("coupler", phiq::SpatialDistanceSpec{{phiq::Attachment3::body_point(crank, V3{0.2, 0, 0}),
                                              phiq::Attachment3::body_point(rocker, V3{0, 0.6, 0})},
                                             0.9});
  phiq::JointAngleDriverSpec motor;
  motor.a = JointSide3::body(Frame3::ground(), V3{}), motor.b = JointSide3::body(crank, V3{});
  motor.law = phiq::MotionLaw::linear(0.0, 1.0);
  b.add("motor", motor);
  const phiq::Model m = std::move(b).build();
  EXPECT_EQ(m.num_coordinates(), 14);
  EXPECT_EQ(m.num_equations(), 14);  // 2 normalisations + 5 + 5 + 1 + driver
  EXPECT_EQ(m.constraints()[0].name, "crank.euler");
  EXPECT_EQ(m.constraints()[0].kind, "euler_parameters");
  EXPECT_EQ(m.row_unit(m.constraints()[2].first_row + 3), phiq::Unit::kAngle);  // hinge's x_a · z_b
  EXPECT_EQ(m.row_unit(m.constraints()[2].first_row), phiq::Unit::kLength);
  EXPECT_EQ(m.coordinate_unit(0), phiq::Unit::kLength);
  EXPECT_EQ(m.coordinate_unit(3), phiq::Unit::kNone);
  // RSSR: 6 · 2 − 5 − 5 − 1 = 1 (the driver is not counted)
  ASSERT_TRUE(m.grubler().has_value());
  EXPECT_EQ(*m.grubler(), 1);
  EXPECT_EQ(m.body_names(), (std::vector<std::string>{"crank", "rocker"}));
  CheckModel(m, 450);
}

// A spatial joint driver's law bounds the model's time domain as a coordinate driver's does: a table on a joint
// angle or distance driver was left out of it, so that a sweep past the table's end was not refused before solving
// (models/README.md, `table`) but ran up to it and failed there ("'motor' is not finite at t = 2.000390625").
TEST(ConstraintKinds3d, JointDriversLawsBoundTheTimeDomain) {
  for (bool angle : {true, false}) {
    phiq::ModelBuilder b;
    const Frame3 crank = AddBody(b, "crank");
    const JointSide3 a = JointSide3::body(Frame3::ground(), V3{}), c = JointSide3::body(crank, V3{});
    const phiq::MotionLaw table = phiq::MotionLaw::table({0.5, 1.0, 2.0}, {0.0, 0.1, 0.2});
    if (angle) {
      phiq::JointAngleDriverSpec motor;
      motor.a = a, motor.b = c, motor.law = table;
      b.add("motor", motor);
    } else {
      phiq::JointDistanceDriverSpec motor;
      motor.a = a, motor.b = c, motor.law = table;
      b.add("motor", motor);
    }
    const phiq::Model m = std::move(b).build();
    EXPECT_EQ(m.time_domain_begin(), 0.5);
    EXPECT_EQ(m.time_domain_end(), 2.0);
    EXPECT_EQ(m.time_domain_limiter(), "motor");
    phiq::Workspace ws(m);
    phiq::SweepOptions opt;
    opt.t_begin = 0.5, opt.t_end = 3.0, opt.steps = 10;
    phiq::SweepSummary sum;
    Index rows = 0;
    EXPECT_EQ(phiq::run_sweep(
                  m, opt, ws, [&](const phiq::StepView&) { return ++rows, true; }, &sum),
              phiq::SolveStatus::kOutsideTimeDomain);
    EXPECT_EQ(rows, 0);
    EXPECT_NE(sum.message.find("driver 'motor' is defined on [0.5, 2] only"), std::string::npos) << sum.message;
  }
}

// The accessors that take a row or coordinate index check it: they read out of bounds before (a crash, or a name
// made of whatever memory followed), where an embedding program's stale index deserves a phiq::Error.
TEST(ConstraintKinds3d, ModelAccessorsRefuseIndicesOutOfRange) {
  phiq::ModelBuilder b;
  const Frame3 crank = AddBody(b, "crank");
  b.add("hinge",
        phiq::SpatialRevoluteSpec{JointSide3::body(Frame3::ground(), V3{}), JointSide3::body(crank, V3{}), {}});
  EXPECT_EQ(b.coordinate_name(6), "crank_e3");
  auto refusal = [](auto&& call) -> std::string {
    try {
      call();
    } catch (const phiq::Error& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_EQ(refusal([&] { b.coordinate_name(7); }), "coordinate index 7 out of range (the model has 7 coordinates)");
  EXPECT_EQ(refusal([&] { b.coordinate_name(-1); }), "coordinate index -1 out of range (the model has 7 coordinates)");
  const phiq::Model m = std::move(b).build();
  ASSERT_EQ(m.num_equations(), 6);  // crank.euler and the hinge's 5 rows
  EXPECT_EQ(m.row_name(5), "hinge[4]");
  EXPECT_EQ(m.constraint_of_row(5), 1);
  EXPECT_EQ(refusal([&] { m.row_name(6); }), "row index 6 out of range (the model has 6 rows)");
  EXPECT_EQ(refusal([&] { m.constraint_of_row(1000000); }), "row index 1000000 out of range (the model has 6 rows)");
  EXPECT_EQ(refusal([&] { m.row_unit(-1); }), "row index -1 out of range (the model has 6 rows)");
  EXPECT_EQ(refusal([&] { m.coordinate_unit(7); }), "coordinate index 7 out of range (the model has 7 coordinates)");
}

TEST(Grubler, PlanarReferencePointFourBarIsOne) {
  phiq::ModelBuilder b;
  std::vector<phiq::Frame2> f;
  for (const char* n : {"crank", "coupler", "rocker"}) {
    Index i = b.add_coordinate(std::string(n) + "_x", 0.0);
    b.add_coordinate(std::string(n) + "_y", 0.0), b.add_coordinate(std::string(n) + "_psi", 0.0);
    f.push_back(phiq::Frame2{S(i), S(i + 1), S(i + 2)});
    b.add_body(n, f.back());
  }
  const phiq::Frame2 ground{C(0), C(0), C(0)};
  b.add("O", phiq::PinSpec{ground, f[0], {0, 0}, {-0.5, 0}});
  b.add("A", phiq::PinSpec{f[0], f[1], {0.5, 0}, {-1, 0}});
  b.add("B", phiq::PinSpec{f[1], f[2], {1, 0}, {0.5, 0}});
  b.add("C", phiq::PinSpec{f[2], ground, {-0.5, 0}, {2, 0}});
  b.add_driver("motor", 2, phiq::MotionLaw::linear(0, 1));
  const phiq::Model m = std::move(b).build();
  ASSERT_TRUE(m.grubler().has_value());
  EXPECT_EQ(*m.grubler(), 1);  // 3 · 3 − 4 · 2
}

TEST(Grubler, UndefinedWithoutBodiesOrWithNonJoints) {
  {  // natural coordinates: no bodies
    phiq::ModelBuilder b;
    b.add_coordinate("x", 1), b.add_coordinate("y", 0);
    b.add("bar", phiq::DistanceSpec{{C(0), C(0)}, {S(0), S(1)}, 1.0});
    b.add_driver("motor", 0, phiq::MotionLaw::linear(1, 0));
    EXPECT_FALSE(std::move(b).build().grubler().has_value());
  }
  {  // a body with a joint and a natural point joined to it: the pin to a natural point is not a joint
    phiq::ModelBuilder b;
    b.add_coordinate("x", 0), b.add_coordinate("y", 0), b.add_coordinate("psi", 0);
    b.add_coordinate("px", 1), b.add_coordinate("py", 0);
    const phiq::Frame2 f{S(0), S(1), S(2)};
    b.add_body("bar", f);
    b.add("O", phiq::PinSpec{phiq::Frame2{C(0), C(0), C(0)}, f, {0, 0}, {0, 0}});
    b.add("P", phiq::PinSpec{f, phiq::Frame2{S(3), S(4), C(0)}, {1, 0}, {0, 0}});
    EXPECT_FALSE(std::move(b).build().grubler().has_value());
  }
  {  // a spatial body and a planar joint mixed
    phiq::ModelBuilder b;
    const Frame3 f = AddBody(b, "door");
    b.add("hinge", phiq::SpatialRevoluteSpec{JointSide3::body(Frame3::ground(), V3{}), JointSide3::body(f, V3{}), {}});
    b.add("flat", phiq::PinSpec{phiq::Frame2{C(0), C(0), C(0)}, phiq::Frame2{S(0), S(1), S(4)}, {0, 0}, {0, 0}});
    EXPECT_FALSE(std::move(b).build().grubler().has_value());
  }
  {  // a spatial door on three hinges: 6 − 15
    phiq::ModelBuilder b;
    const Frame3 f = AddBody(b, "door");
    for (int k = 0; k < 3; ++k)
      b.add("hinge" + std::to_string(k),
            phiq::SpatialRevoluteSpec{
                JointSide3::body(Frame3::ground(), V3{0, 0, 1.0 * k}), JointSide3::body(f, V3{0, 0, 1.0 * k}), {}});
    const phiq::Model m = std::move(b).build();
    ASSERT_TRUE(m.grubler().has_value());
    EXPECT_EQ(*m.grubler(), -9);
  }
}

TEST(Grubler, DuplicateBodyNameIsAnError) {
  phiq::ModelBuilder b;
  AddBody(b, "door");
  EXPECT_THROW(b.add_body("door", phiq::Frame2{C(0), C(0), C(0)}), phiq::Error);
}

}  // namespace
