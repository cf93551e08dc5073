// Clearance along the motion (phiq/clearance.hpp) on the notes' four-bar in reference-point coordinates (ground
// pivots O = (0, 0) and C = (L1, 0), crank L2 = 0.4 turned at 1 rad/s, coupler L3 = 1.2, rocker L4 = 1): distances
// against closed forms written here, minima refined between the rows to their closed-form times, interference
// intervals whose ends are known in closed form, the pairs `skip: adjacent` leaves out, and FCL's BVH meshes
// against its primitives on the same shapes.
#include <gtest/gtest.h>

#include <cmath>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// The four-bar scene with `extra` appended (its parts, its output).
Scene clearance_fourbar(const std::string& extra, int steps = 360) {
  const std::string text = test::model_file_text("seed/fourbar_reference_point.yaml", "\ntime:");
  return parse_scene(text + "\ntime: {start: 0, end: 2*pi, steps: " + std::to_string(steps) + "}\n" + extra,
                     "fourbar_clearance.yaml");
}

// A part on the planar body `body` (ground: fixed) of the four-bar carrying `shape`.
Part clearance_body_part(const Scene& s, const std::string& name, const std::string& body, Shape shape) {
  Part p;
  p.name = name;
  p.body = body;
  p.frame.kind = PartFrameKind::kPlanarBody;
  if (body != "ground") {
    const auto& names = s.model->body_names();
    p.frame.planar =
        s.planar_bodies[static_cast<std::size_t>(std::find(names.begin(), names.end(), body) - names.begin())];
  }
  p.fixed = body == "ground";
  p.shapes.push_back(std::move(shape));
  return p;
}

Shape clearance_sphere(double r, kin3::V3 at) {
  Shape s;
  s.kind = ShapeKind::kSphere;
  s.radius = r;
  s.at = at;
  return s;
}

Shape clearance_box(kin3::V3 size, kin3::V3 at) {
  Shape s;
  s.kind = ShapeKind::kBox;
  s.size = size;
  s.at = at;
  return s;
}

// The rows of the scene's sweep with q̇ and q̈.
ClearanceRows clearance_rows(const Scene& scene) {
  Workspace ws(*scene.model);
  SweepSummary summary;
  ClearanceRows rows = sweep_rows(*scene.model, scene.sweep, ws, &summary);
  EXPECT_EQ(summary.status, SolveStatus::kSuccess) << summary.message;
  return rows;
}

ClearancePlan clearance_one_pair(Index a, Index b, double threshold = 0.0) {
  ClearancePlan plan;
  plan.requested = true;
  plan.pairs = {{a, b}};
  plan.threshold = threshold;
  return plan;
}

// Crank tip A = L2 (cos t, sin t); rocker pin B from the rows' q (the rocker's end at +L4/2 on its x axis).
kin3::V3 clearance_crank_tip(double t) { return {0.4 * std::cos(t), 0.4 * std::sin(t), 0.0}; }

// Two spheres on moving points: one on the crank's tip A (radius 0.05), one on ground at C (radius 0.1). At every
// row the distance is |A − C| − 0.15 with the witness points on the line of centres; its minimum, at t = 0, and the
// speed bound holding between rows.
TEST(Clearance, TwoSpheresOnMovingPointsAreTheirCentresDistanceLessTheRadii) {
  Scene s = clearance_fourbar("");
  s.parts.push_back(clearance_body_part(s, "tip", "crank", clearance_sphere(0.05, {0.2, 0, 0})));
  s.parts.push_back(clearance_body_part(s, "stop", "ground", clearance_sphere(0.1, {1.0, 0, 0})));
  const ClearanceRows rows = clearance_rows(s);
  const ClearanceReport r = clearance_along(*s.model, s.parts, clearance_one_pair(0, 1), rows);
  ASSERT_EQ(r.pairs.size(), 1u);
  const PairClearance& p = r.pairs[0];
  const kin3::V3 c{1.0, 0, 0};
  for (std::size_t k = 0; k < rows.t.size(); ++k) {
    const kin3::V3 a = clearance_crank_tip(rows.t[k]);
    EXPECT_NEAR(p.row_distance[k], kin3::norm(a - c) - 0.15, 1e-9) << rows.t[k];
  }
  EXPECT_NEAR(p.worst.at.distance, 0.6 - 0.15, 1e-9);
  EXPECT_NEAR(p.worst.t, 0.0, 1e-9);
  EXPECT_NEAR(p.worst.at.point_a.x, 0.45, 1e-8);
  EXPECT_NEAR(p.worst.at.point_b.x, 0.9, 1e-8);
  EXPECT_NEAR(p.worst.at.normal.x, 1.0, 1e-8);
  EXPECT_TRUE(p.interference.empty());
  EXPECT_EQ(p.unproven_intervals, 0);
  EXPECT_FALSE(r.interferes());
}

// The ground pivot O against the rocker pin B over a crank turn: |OB| is least when the crank folds onto the
// coupler, |OB| = L3 − L2 = 0.8, B at the angle acos((0.8² + L1² − L4²) / (2 · 0.8 · L1)) = acos(0.4) and the
// crank opposite, t* = π + acos(0.4) (the rocker at its limit); greatest, L3 + L2, at t = acos(0.8). The minimum lies
// between rows (a step of 2π/90) and is refined there to its time and distance.
TEST(Clearance, FourBarPivotToRockerPinMinimumIsTheLawOfCosinesExtreme) {
  Scene s = clearance_fourbar("", 90);
  s.parts.push_back(clearance_body_part(s, "pivot", "ground", clearance_sphere(0.02, {0, 0, 0})));
  s.parts.push_back(clearance_body_part(s, "pin", "rocker", clearance_sphere(0.03, {0.5, 0, 0})));
  const ClearanceRows rows = clearance_rows(s);
  const ClearanceReport r = clearance_along(*s.model, s.parts, clearance_one_pair(0, 1), rows);
  const PairClearance& p = r.pairs[0];
  const double t_min = M_PI + std::acos(0.4);
  EXPECT_TRUE(p.worst.refined);
  EXPECT_NEAR(p.worst.at.distance, 0.8 - 0.05, 1e-10);
  EXPECT_NEAR(p.worst.t, t_min, 1e-6);  // a minimum's time is known to √(distance's accuracy)
  double row_max = -1;
  for (double d : p.row_distance) row_max = std::max(row_max, d);
  EXPECT_LE(row_max, 1.6 - 0.05 + 1e-12);
  EXPECT_GT(row_max, 1.6 - 0.05 - 1e-3);
  // the rows' minimum is above the refined one: the rows miss it
  double row_min = 1e9;
  for (double d : p.row_distance) row_min = std::min(row_min, d);
  EXPECT_GT(row_min - p.worst.at.distance, 1e-6);
  EXPECT_EQ(p.unproven_intervals, 0);
}

// A sphere of radius 0.05 on the crank's tip against a fixed box whose top is at y = −0.35: d = 0.4 sin t + 0.3,
// negative for sin t < −0.75, from t = π + asin(0.75) to 2π − asin(0.75); its ends to 1e-9 of the step, its
// deepest point −0.1 at t = 3π/2.
TEST(Clearance, InterferenceIntervalEndsAreTheClosedFormsToTheStepTolerance) {
  Scene s = clearance_fourbar("", 90);
  s.parts.push_back(clearance_body_part(s, "tip", "crank", clearance_sphere(0.05, {0.2, 0, 0})));
  s.parts.push_back(clearance_body_part(s, "block", "ground", clearance_box({2, 0.2, 1}, {0, -0.45, 0})));
  const ClearanceRows rows = clearance_rows(s);
  const ClearanceReport r = clearance_along(*s.model, s.parts, clearance_one_pair(0, 1), rows);
  const PairClearance& p = r.pairs[0];
  const double h = 2 * M_PI / 90;
  ASSERT_EQ(p.interference.size(), 1u);
  EXPECT_NEAR(p.interference[0].entry, M_PI + std::asin(0.75), 1e-9 * h);
  EXPECT_NEAR(p.interference[0].exit, 2 * M_PI - std::asin(0.75), 1e-9 * h);
  EXPECT_NEAR(p.worst.at.distance, -0.1, 1e-9);
  EXPECT_NEAR(p.worst.t, 1.5 * M_PI, 1e-6);
  for (std::size_t k = 0; k < rows.t.size(); ++k)
    EXPECT_NEAR(p.row_distance[k], 0.4 * std::sin(rows.t[k]) + 0.3, 1e-9) << rows.t[k];
  EXPECT_TRUE(r.interferes());
}

// A capsule around the crank (radius 0.05, from O to A) against a fixed box whose top is at y = −0.5: the capsule's
// lowest point is min(0, 0.4 sin t) − 0.05, so d = 0.45 + min(0, 0.4 sin t), least (0.05) at t = 3π/2.
TEST(Clearance, CapsuleAroundACrankAgainstAFixedBox) {
  Scene s = clearance_fourbar("", 72);
  Shape capsule;
  capsule.kind = ShapeKind::kCapsule;
  capsule.radius = 0.05;
  capsule.length = 0.4;
  capsule.rotation = {0, 0, 1, 0, 1, 0, -1, 0, 0};  // its z axis along the crank's x
  s.parts.push_back(clearance_body_part(s, "crank", "crank", capsule));
  s.parts.push_back(clearance_body_part(s, "floor", "ground", clearance_box({3, 0.2, 1}, {0, -0.6, 0})));
  const ClearanceRows rows = clearance_rows(s);
  const ClearanceReport r = clearance_along(*s.model, s.parts, clearance_one_pair(0, 1, 0.01), rows);
  const PairClearance& p = r.pairs[0];
  for (std::size_t k = 0; k < rows.t.size(); ++k)
    EXPECT_NEAR(p.row_distance[k], 0.45 + std::min(0.0, 0.4 * std::sin(rows.t[k])), 1e-8) << rows.t[k];
  EXPECT_NEAR(p.worst.at.distance, 0.05, 1e-8);
  EXPECT_NEAR(p.worst.t, 1.5 * M_PI, 1e-4);
  EXPECT_TRUE(p.interference.empty());
  EXPECT_EQ(p.unproven_intervals, 0);
}

// The same two boxes as FCL primitives and as BVH meshes (extruded polygons of the same outline): the same
// distance at every row where they are apart, and the same interference.
TEST(Clearance, MeshesGiveThePrimitivesDistances) {
  Scene s = clearance_fourbar("", 60);
  Shape block = clearance_box({0.1, 0.1, 0.1}, {0.2, 0, 0});
  Shape floor = clearance_box({2, 0.2, 0.1}, {0.1, -0.3, 0});
  auto as_polygon = [](const Shape& b) {
    Shape p;
    p.kind = ShapeKind::kPolygon;
    p.at = b.at;
    p.length = b.size.z;
    const double x = b.size.x / 2, y = b.size.y / 2;
    p.outline = {{-x, -y}, {x, -y}, {x, y}, {-x, y}};
    return p;
  };
  s.parts.push_back(clearance_body_part(s, "block", "crank", block));
  s.parts.push_back(clearance_body_part(s, "floor", "ground", floor));
  s.parts.push_back(clearance_body_part(s, "block_mesh", "crank", as_polygon(block)));
  s.parts.push_back(clearance_body_part(s, "floor_mesh", "ground", as_polygon(floor)));
  const ClearanceRows rows = clearance_rows(s);
  ClearancePlan plan = clearance_one_pair(0, 1);
  plan.pairs.push_back({2, 3});
  const ClearanceReport r = clearance_along(*s.model, s.parts, plan, rows);
  ASSERT_EQ(r.pairs.size(), 2u);
  const PairClearance &prim = r.pairs[0], &mesh = r.pairs[1];
  int apart = 0;
  for (std::size_t k = 0; k < rows.t.size(); ++k) {
    if (prim.row_distance[k] <= 0) {
      EXPECT_LE(mesh.row_distance[k], 0.0) << rows.t[k];
      continue;
    }
    ++apart;
    EXPECT_NEAR(mesh.row_distance[k], prim.row_distance[k], 1e-9) << rows.t[k];
  }
  EXPECT_GT(apart, 30);
  ASSERT_EQ(prim.interference.size(), 1u);
  ASSERT_EQ(mesh.interference.size(), 1u);
  EXPECT_NEAR(mesh.interference[0].entry, prim.interference[0].entry, 1e-8);
  EXPECT_NEAR(mesh.interference[0].exit, prim.interference[0].exit, 1e-8);
}

}  // namespace
}  // namespace phiq
