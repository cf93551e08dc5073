// The witness points of overlapping parts (phiq/clearance.hpp, PairDistance): each part's deepest point inside the
// other along the normal, on its own surface, the depth apart, against closed forms for two spheres, a sphere
// against a box and a capsule against a box (both orders); and the sensitivities of a penetrating pair's worst
// clearance against their closed forms and finite differences of the whole sweep.
#include <gtest/gtest.h>

#include <cmath>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

Part witness_fixed_part(Shape shape) {
  Part p;
  p.fixed = true;
  p.shapes.push_back(std::move(shape));
  return p;
}

Shape witness_sphere(double r, kin3::V3 at) {
  Shape s;
  s.kind = ShapeKind::kSphere;
  s.radius = r;
  s.at = at;
  return s;
}

Shape witness_box(kin3::V3 size, kin3::V3 at) {
  Shape s;
  s.kind = ShapeKind::kBox;
  s.size = size;
  s.at = at;
  return s;
}

// The distance of parts 0 and 1 of `parts`, each at the identity pose (their shapes placed in the world), in the
// order (a, b).
PairDistance witness_distance(const std::vector<Part>& parts, Index a, Index b) {
  const ClearanceGeometry g(parts);
  return g.distance(a, Pose{}, b, Pose{});
}

void witness_expect_near(kin3::V3 got, kin3::V3 want, double tol, const char* what) {
  EXPECT_NEAR(got.x, want.x, tol) << what;
  EXPECT_NEAR(got.y, want.y, tol) << what;
  EXPECT_NEAR(got.z, want.z, tol) << what;
}

// Spheres A (radius 0.3 at the origin) and B (radius 0.2 at c, |c| = 0.45): d = |c| − 0.5; n = c/|c| from A to B;
// A's deepest point inside B is rA n, B's inside A is c − rB n; each on its own sphere, the depth apart.
TEST(ClearanceWitness, OverlappingSpheresHaveTheirPointsOnBothSurfaces) {
  const kin3::V3 c{0.36, 0.24, -0.15};
  const double len = kin3::norm(c);
  const kin3::V3 n = (1.0 / len) * c;
  const std::vector<Part> parts{witness_fixed_part(witness_sphere(0.3, {0, 0, 0})),
                                witness_fixed_part(witness_sphere(0.2, c))};
  const PairDistance ab = witness_distance(parts, 0, 1);
  EXPECT_NEAR(ab.distance, len - 0.5, 1e-12);
  witness_expect_near(ab.point_a, 0.3 * n, 1e-9, "A's point");
  witness_expect_near(ab.point_b, c - 0.2 * n, 1e-9, "B's point");
  witness_expect_near(ab.normal, n, 1e-9, "normal");
  EXPECT_NEAR(kin3::norm(ab.point_a), 0.3, 1e-9);
  EXPECT_NEAR(kin3::norm(ab.point_b - c), 0.2, 1e-9);
  EXPECT_NEAR(kin3::norm(ab.point_b - ab.point_a), -ab.distance, 1e-9);
  const PairDistance ba = witness_distance(parts, 1, 0);
  EXPECT_NEAR(ba.distance, ab.distance, 1e-12);
  witness_expect_near(ba.point_a, ab.point_b, 1e-9, "reversed: B's point");
  witness_expect_near(ba.point_b, ab.point_a, 1e-9, "reversed: A's point");
  witness_expect_near(ba.normal, -1.0 * n, 1e-9, "reversed normal");
}

// A box (1 × 0.4 × 0.6 at the origin: its face y = 0.2) and a sphere of radius 0.1 at (0.1, 0.25, 0.05), its centre
// 0.05 outside the face: depth 0.05 along +y; the box's deepest point inside the sphere is the face's point under
// the centre, (0.1, 0.2, 0.05), the sphere's inside the box its lowest point, (0.1, 0.15, 0.05).
TEST(ClearanceWitness, SphereAgainstABoxHasTheFacePointAndTheSpheresDeepestPoint) {
  const std::vector<Part> parts{witness_fixed_part(witness_box({1, 0.4, 0.6}, {0, 0, 0})),
                                witness_fixed_part(witness_sphere(0.1, {0.1, 0.25, 0.05}))};
  const PairDistance ab = witness_distance(parts, 0, 1);
  EXPECT_NEAR(ab.distance, -0.05, 1e-12);
  witness_expect_near(ab.point_a, {0.1, 0.2, 0.05}, 1e-9, "box's point");
  witness_expect_near(ab.point_b, {0.1, 0.15, 0.05}, 1e-9, "sphere's point");
  witness_expect_near(ab.normal, {0, 1, 0}, 1e-9, "normal");
  const PairDistance ba = witness_distance(parts, 1, 0);
  EXPECT_NEAR(ba.distance, -0.05, 1e-12);
  witness_expect_near(ba.point_a, {0.1, 0.15, 0.05}, 1e-9, "reversed: sphere's point");
  witness_expect_near(ba.point_b, {0.1, 0.2, 0.05}, 1e-9, "reversed: box's point");
  witness_expect_near(ba.normal, {0, -1, 0}, 1e-9, "reversed normal");
}

// A capsule (radius 0.05) from P0 = (−0.2, 0.1) to P1 = (0.2, 0.02) dipping its lower end into a slab whose top is
// y = 0 (2 × 0.4 × 1): depth 0.03 along +y (any other way out is longer); the slab's deepest point inside the
// capsule is the top's point under P1, (0.2, 0, 0), the capsule's inside the slab its lowest, (0.2, −0.03, 0).
// FCL has no closed form for this pair (libccd's MPR gives its contact), and libccd's GJK, whose nearest points of
// the parted pair give the witness points, stops ~1e-7 m short on the capsule's round end: 1e-6 here.
TEST(ClearanceWitness, CapsuleAgainstABoxHasTheDeepestPointsOfTheDippingEnd) {
  const kin3::V3 p0{-0.2, 0.1, 0}, p1{0.2, 0.02, 0};
  const double length = kin3::norm(p1 - p0);
  const kin3::V3 u = (1.0 / length) * (p1 - p0);
  Shape capsule;
  capsule.kind = ShapeKind::kCapsule;
  capsule.radius = 0.05;
  capsule.length = length;
  capsule.at = 0.5 * (p0 + p1);
  capsule.rotation = {0, u.y, u.x, 0, -u.x, u.y, 1, 0, 0};  // axes x' = z, y' = u × z, z' = u
  const std::vector<Part> parts{witness_fixed_part(witness_box({2, 0.4, 1}, {0, -0.2, 0})),
                                witness_fixed_part(capsule)};
  for (const bool reversed : {false, true}) {
    const PairDistance d = witness_distance(parts, reversed ? 1 : 0, reversed ? 0 : 1);
    const kin3::V3 slab = reversed ? d.point_b : d.point_a, tip = reversed ? d.point_a : d.point_b;
    EXPECT_NEAR(d.distance, -0.03, 1e-6) << reversed;
    witness_expect_near(slab, {0.2, 0, 0}, 1e-6, reversed ? "reversed: slab's point" : "slab's point");
    witness_expect_near(tip, {0.2, -0.03, 0}, 1e-6, reversed ? "reversed: capsule's point" : "capsule's point");
    witness_expect_near(d.normal, {0, reversed ? -1.0 : 1.0, 0}, 1e-6, "normal");
    EXPECT_NEAR(kin3::norm(d.point_b - d.point_a), -d.distance, 1e-9) << reversed;
  }
}

// The four-bar (reference-point coordinates, C = (L1, 0)) with its rocker drawn as a box 1 × 0.06 along its axis
// and a ball (radius 0.1) fixed at C + 0.6 (cos 1.2, sin 1.2), beyond the rocker's limit ψ0 = acos(((L2 + L3)² −
// L1² − L4²) / (2 L1 L4)) = acos(0.28) (crank and coupler in line): the rocker's face dips into the ball most at
// its limit, d = 0.6 sin(ψ0 − 1.2) − 0.03 − 0.1 < 0 (the ball's centre outside the box).
std::string witness_rocker_scene_text() {
  return test::model_file_text("seed/fourbar_reference_point.yaml", "\ntime:") +
         "\ntime: {start: 0, end: 2*pi, steps: 90}\n"
         "parts:\n"
         "  rocker: {shapes: [{type: box, size: [1, 0.06, 0.02]}]}\n"
         "  ball: {body: ground, shapes: [{type: sphere, radius: 0.1, at: [1.217415, 0.559223]}]}\n"
         "output: {sensitivities: [L1, L2, L3, L4], clearance: {pairs: [[rocker, ball]], threshold: 0}}\n";
}

double witness_rocker_closed_form(const double l[4]) {
  const double limit = std::acos((std::pow(l[1] + l[2], 2) - l[0] * l[0] - l[3] * l[3]) / (2 * l[0] * l[3]));
  const kin3::V3 ball{1.217415 - l[0], 0.559223, 0};  // from C
  return ball.x * std::sin(limit) - ball.y * std::cos(limit) - 0.03 - 0.1;
}

TEST(ClearanceWitness, PenetratingPairSensitivitiesMatchClosedFormsAndFiniteDifferences) {
  const std::string text = witness_rocker_scene_text();
  const Scene s = parse_scene(text, "rocker.yaml");
  const ClearanceReport r = scene_clearance(s);
  ASSERT_EQ(r.pairs.size(), 1u);
  const ClearanceMinimum& w = r.pairs[0].worst;
  double l[4] = {1.0, 0.4, 1.2, 1.0};
  ASSERT_LT(witness_rocker_closed_form(l), -0.05);
  EXPECT_NEAR(w.at.distance, witness_rocker_closed_form(l), 1e-9);
  EXPECT_NEAR(kin3::norm(w.at.point_b - kin3::V3{1.217415, 0.559223, 0}), 0.1, 1e-9);  // on the ball
  EXPECT_NEAR(kin3::norm(w.at.point_b - w.at.point_a), -w.at.distance, 1e-9);
  const kin3::V3 axis{std::cos(std::acos(0.28)), std::sin(std::acos(0.28)), 0};  // the rocker at its limit
  const kin3::V3 ball_from_c{0.217415, 0.559223, 0};
  // A's point: the face's point under the ball's centre, on the face
  EXPECT_NEAR(kin3::dot(w.at.point_a - kin3::V3{1, 0, 0}, axis), kin3::dot(ball_from_c, axis), 1e-6);
  EXPECT_NEAR(kin3::norm(w.at.point_a - kin3::V3{1, 0, 0} - kin3::dot(w.at.point_a - kin3::V3{1, 0, 0}, axis) * axis),
              0.03, 1e-6);
  ASSERT_EQ(w.sensitivities.size(), 4u);
  const char* names[] = {"L1", "L2", "L3", "L4"};
  for (int j = 0; j < 4; ++j) {
    const double h = 1e-5;
    double closed[2], swept[2];
    for (int side = 0; side < 2; ++side) {
      double moved_l[4] = {l[0], l[1], l[2], l[3]};
      moved_l[j] += side ? h : -h;
      closed[side] = witness_rocker_closed_form(moved_l);
      SceneOverrides o;
      o.parameters = {{names[j], moved_l[j]}};
      o.sensitivity_models = false;
      Scene moved = parse_scene(text, "rocker.yaml", {}, o);
      moved.sweep.sensitivities.clear();
      swept[side] = scene_clearance(moved).pairs[0].worst.at.distance;
    }
    const double sensitivity = w.sensitivities[static_cast<std::size_t>(j)];
    EXPECT_NEAR((closed[1] - closed[0]) / (2 * h), sensitivity, 1e-6) << names[j];
    EXPECT_NEAR((swept[1] - swept[0]) / (2 * h), sensitivity, 1e-5) << names[j];
  }
}

}  // namespace
}  // namespace phiq
