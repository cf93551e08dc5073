// Mass properties of shapes (phiq/shapes.hpp) against closed forms: every primitive's mass, centre and inertia,
// extruded polygons against boxes, placement, sums by hand, the parallel-axis theorem, and a mesh's by the
// divergence theorem against the exact solids it bounds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "phiq/orientation.hpp"
#include "phiq/shapes.hpp"
#include "phiq/types.hpp"

namespace phiq::mass_properties_test {

using kin3::V3;
using Inertia = std::array<double, 9>;
constexpr double kPi = std::numbers::pi;

Shape box(double a, double b, double c) {
  Shape s;
  s.kind = ShapeKind::kBox, s.size = {a, b, c};
  return s;
}
Shape solid(ShapeKind kind, double radius, double length = 0.0) {
  Shape s;
  s.kind = kind, s.radius = radius, s.length = length;
  return s;
}
Shape prism(std::vector<std::array<double, 2>> outline, double thickness) {
  Shape s;
  s.kind = ShapeKind::kPolygon, s.outline = std::move(outline), s.length = thickness;
  return s;
}
Inertia diagonal(double xx, double yy, double zz) { return {xx, 0, 0, 0, yy, 0, 0, 0, zz}; }

// Each entry within `rel` of the largest entry of `want` (off-diagonal zeros are held to the same scale).
void expect_inertia(const Inertia& got, const Inertia& want, double rel, const std::string& what) {
  double scale = 0.0;
  for (double v : want) scale = std::max(scale, std::abs(v));
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(got[k], want[k], rel * scale) << what << ": I[" << k / 3 << k % 3 << "]";
}
void expect_point(V3 got, V3 want, double tol, const std::string& what) {
  EXPECT_NEAR(got.x, want.x, tol) << what;
  EXPECT_NEAR(got.y, want.y, tol) << what;
  EXPECT_NEAR(got.z, want.z, tol) << what;
}
void expect_same(const MassProperties& got, const MassProperties& want, double rel, const std::string& what) {
  EXPECT_NEAR(got.mass, want.mass, rel * want.mass) << what;
  expect_point(got.center, want.center, rel, what);
  expect_inertia(got.inertia, want.inertia, rel, what);
}
// m (|d|² 1 − d dᵀ), written out.
Inertia shift(double m, V3 d) {
  const double dd = d.x * d.x + d.y * d.y + d.z * d.z;
  return {m * (dd - d.x * d.x), -m * d.x * d.y, -m * d.x * d.z, -m * d.y * d.x,      m * (dd - d.y * d.y),
          -m * d.y * d.z,       -m * d.z * d.x, -m * d.z * d.y, m * (dd - d.z * d.z)};
}
Inertia plus(Inertia a, const Inertia& b) {
  for (int k = 0; k < 9; ++k) a[k] += b[k];
  return a;
}
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(MassProperties, BoxHasATwelfthOfItsMassTimesTheOtherEdgesSquared) {
  const double a = 0.3, b = 0.5, c = 1.1, rho = 7800.0, m = rho * a * b * c;
  const MassProperties p = shape_mass_properties(box(a, b, c), rho);
  EXPECT_NEAR(p.mass, 1287.0, 1e-9);
  expect_point(p.center, {}, 0.0, "box centre");
  expect_inertia(p.inertia, diagonal(m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12),
                 1e-15, "box");
}

TEST(MassProperties, CylinderAboutADiameterAndAboutItsAxis) {
  const double r = 0.2, h = 1.5, rho = 2700.0, m = rho * kPi * r * r * h;
  const MassProperties p = shape_mass_properties(solid(ShapeKind::kCylinder, r, h), rho);
  EXPECT_NEAR(p.mass, m, 1e-12 * m);
  expect_point(p.center, {}, 0.0, "cylinder centre");
  const double diameter = m * (3 * r * r + h * h) / 12, axis = m * r * r / 2;
  expect_inertia(p.inertia, diagonal(diameter, diameter, axis), 1e-15, "cylinder");
}

TEST(MassProperties, SphereHasTwoFifthsOfMR2) {
  const double r = 0.35, rho = 1000.0, m = rho * 4.0 / 3.0 * kPi * r * r * r;
  const MassProperties p = shape_mass_properties(solid(ShapeKind::kSphere, r), rho);
  EXPECT_NEAR(p.mass, m, 1e-12 * m);
  expect_inertia(p.inertia, diagonal(0.4 * m * r * r, 0.4 * m * r * r, 0.4 * m * r * r), 1e-15, "sphere");
}

TEST(MassProperties, CapsuleIsItsCylinderAndTwoHemispheres) {
  const double r = 0.1, length = 0.6, rho = 1200.0;
  // hemisphere: mass half the sphere's, centroid 3r/8 from its flat face, about that centroid (2/5 − 9/64) mh r²
  // across and 2/5 mh r² along the axis; the cylinder's as above; summed with the parallel-axis theorem
  const double mc = rho * kPi * r * r * length, mh = rho * 2.0 / 3.0 * kPi * r * r * r;
  const double hemisphere_across = (0.4 - 9.0 / 64.0) * mh * r * r, d = length / 2 + 3 * r / 8;
  const double across = mc * (3 * r * r + length * length) / 12 + 2 * (hemisphere_across + mh * d * d);
  const double along = mc * r * r / 2 + 2 * 0.4 * mh * r * r;
  const MassProperties p = shape_mass_properties(solid(ShapeKind::kCapsule, r, length), rho);
  EXPECT_NEAR(p.mass, mc + 2 * mh, 1e-12 * p.mass);
  expect_point(p.center, {}, 1e-15, "capsule centre");
  expect_inertia(p.inertia, diagonal(across, across, along), 1e-14, "capsule");
  // r = 1, L = 2, ρ = 1 worked through by hand: 7π/6 + (4π/3)(2/5 + 1 + 3/4) across, π + 8π/15 along
  const MassProperties unit = shape_mass_properties(solid(ShapeKind::kCapsule, 1.0, 2.0), 1.0);
  EXPECT_NEAR(unit.mass, 2 * kPi + 4 * kPi / 3, 1e-14);
  expect_inertia(unit.inertia,
                 diagonal(7 * kPi / 6 + 4 * kPi / 3 * 2.15, 7 * kPi / 6 + 4 * kPi / 3 * 2.15, kPi + 8 * kPi / 15),
                 1e-14, "unit capsule");
}

TEST(MassProperties, ConeAboutItsCentroidAndAboutItsApex) {
  const double r = 0.25, h = 0.8, rho = 500.0, m = rho * kPi * r * r * h / 3;
  const MassProperties p = shape_mass_properties(solid(ShapeKind::kCone, r, h), rho);
  EXPECT_NEAR(p.mass, m, 1e-12 * m);
  expect_point(p.center, {0, 0, h / 4}, 1e-15, "cone centroid a quarter up");
  const double across = 3.0 / 80.0 * m * (4 * r * r + h * h), along = 0.3 * m * r * r;
  expect_inertia(p.inertia, diagonal(across, across, along), 1e-14, "cone about its centroid");
  const double apex_across = 3.0 / 5.0 * m * (r * r / 4 + h * h);
  expect_inertia(inertia_about(p, {0, 0, h}), diagonal(apex_across, apex_across, along), 1e-14, "cone about its apex");
}

TEST(MassProperties, RectanglePrismIsTheBoxInEitherOrientation) {
  const double rho = 640.0;
  Shape placed_box = box(0.4, 0.5, 0.7);
  placed_box.at = {1.2, 0.05, 0.0};
  const MassProperties want = shape_mass_properties(placed_box, rho);
  const std::vector<std::array<double, 2>> ccw{{1.0, -0.2}, {1.4, -0.2}, {1.4, 0.3}, {1.0, 0.3}};
  expect_same(shape_mass_properties(prism(ccw, 0.7), rho), want, 1e-12, "counter-clockwise rectangle");
  const std::vector<std::array<double, 2>> cw(ccw.rbegin(), ccw.rend());
  expect_same(shape_mass_properties(prism(cw, 0.7), rho), want, 1e-12, "clockwise rectangle");
}

TEST(MassProperties, LShapedPrismIsTheSumOfItsTwoBoxes) {
  // the L of [0, 2] × [0, 1] and [0, 1] × [1, 3], 0.5 thick: the off-diagonal xy term is not zero
  const double rho = 2.0, t = 0.5;
  const MassProperties p = shape_mass_properties(prism({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 3}, {0, 3}}, t), rho);
  const double m1 = rho * 2 * 1 * t, m2 = rho * 1 * 2 * t;  // both 2 kg
  const V3 c1{1.0, 0.5, 0.0}, c2{0.5, 2.0, 0.0}, c{0.75, 1.25, 0.0};
  EXPECT_DOUBLE_EQ(p.mass, 4.0);
  expect_point(p.center, c, 1e-15, "L centroid");
  const Inertia i1 = diagonal(m1 * (1 + t * t) / 12, m1 * (4 + t * t) / 12, m1 * (4 + 1) / 12);
  const Inertia i2 = diagonal(m2 * (4 + t * t) / 12, m2 * (1 + t * t) / 12, m2 * (1 + 4) / 12);
  const Inertia hand = plus(plus(i1, shift(m1, c1 - c)), plus(i2, shift(m2, c2 - c)));
  EXPECT_NEAR(hand[1], -m1 * 0.25 * -0.75 - m2 * -0.25 * 0.75, 1e-15);  // −Σ m dx dy = 0.75: a real product term
  expect_inertia(p.inertia, hand, 1e-14, "L prism");
  Shape upper = box(1, 2, t), lower = box(2, 1, t);
  upper.at = c2, lower.at = c1;
  expect_same(combine_mass_properties({shape_mass_properties(lower, rho), shape_mass_properties(upper, rho)}), p, 1e-14,
              "L as combined boxes");
}

TEST(MassProperties, PlacementTurnsTheInertiaAndMovesTheCentre) {
  const double rho = 3.0;
  // a quarter turn about z swaps the x and y moments, exactly as written out
  Shape turned = box(0.2, 0.6, 1.0);
  turned.rotation = {0, -1, 0, 1, 0, 0, 0, 0, 1};
  turned.at = {1, 2, 3};
  const double m = rho * 0.12;
  const MassProperties q = shape_mass_properties(turned, rho);
  expect_point(q.center, {1, 2, 3}, 0.0, "box placed at");
  expect_inertia(q.inertia, diagonal(m * (0.04 + 1) / 12, m * (0.36 + 1) / 12, m * (0.04 + 0.36) / 12), 1e-15,
                 "quarter turn");
  // any rotation: R I Rᵀ, and a cone's centroid moved to at + R (0, 0, h/4)
  Shape cone = solid(ShapeKind::kCone, 0.3, 0.9);
  const MassProperties local = shape_mass_properties(cone, rho);
  cone.rotation = rotation_matrix(euler_parameters_from_axis_angle({1, -2, 0.5}, 0.7));
  cone.at = {-0.4, 0.1, 2.0};
  const MassProperties placed = shape_mass_properties(cone, rho);
  const RotationMatrix& r = cone.rotation;
  const double hz = 0.9 / 4;
  expect_point(placed.center, {-0.4 + r[2] * hz, 0.1 + r[5] * hz, 2.0 + r[8] * hz}, 1e-15, "cone centroid placed");
  Inertia want{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) want[3 * i + j] += r[3 * i + k] * local.inertia[3 * k + k] * r[3 * j + k];
  expect_inertia(placed.inertia, want, 1e-14, "R I Rᵀ");
  EXPECT_GT(std::abs(placed.inertia[1]), 1e-3 * placed.inertia[0]);  // turned off its principal axes
}

TEST(MassProperties, CombineIsTheSumWorkedByHand) {
  MassProperties a, b;
  a.mass = 2, a.center = {1, 0, 0}, a.inertia = diagonal(1, 2, 3);
  b.mass = 3, b.center = {0, 2, 0}, b.inertia = {4, 0.5, 0, 0.5, 5, 0, 0, 0, 6};
  const MassProperties sum = combine_mass_properties({a, b});
  EXPECT_DOUBLE_EQ(sum.mass, 5);
  expect_point(sum.center, {0.4, 1.2, 0}, 1e-15, "combined centre");
  // d_a = (0.6, −1.2, 0): 2 (1.8 − dd); d_b = (−0.4, 0.8, 0): 3 (0.8 − dd)
  expect_inertia(
      sum.inertia,
      {1 + 4 + 2.88 + 1.92, 0.5 + 1.44 + 0.96, 0, 0.5 + 1.44 + 0.96, 2 + 5 + 0.72 + 0.48, 0, 0, 0, 3 + 6 + 3.6 + 2.4},
      1e-15, "combined inertia");
  EXPECT_EQ(combine_mass_properties({}).mass, 0.0);
  expect_inertia(combine_mass_properties({}).inertia, Inertia{}, 0.0, "nothing combined");
}

TEST(MassProperties, InertiaAboutAPointOnASphere) {
  const double r = 0.5, rho = 10.0;
  const MassProperties p = shape_mass_properties(solid(ShapeKind::kSphere, r), rho);
  const double mr2 = p.mass * r * r;
  expect_inertia(inertia_about(p, {r, 0, 0}), diagonal(0.4 * mr2, 1.4 * mr2, 1.4 * mr2), 1e-15, "about (r, 0, 0)");
  expect_inertia(inertia_about(p, p.center), p.inertia, 0.0, "about its own centre");
}

TEST(MassProperties, MeshOfABoxIsTheBoxTo1e12) {
  Shape b = box(0.3, 0.7, 1.3);
  b.at = {5.0, -2.0, 0.5};
  b.rotation = rotation_matrix(euler_parameters_from_axis_angle({0.3, 1, -0.2}, 1.1));
  const MassProperties want = shape_mass_properties(b, 1.0);
  const MassProperties got = mesh_mass_properties(shape_triangles(b));
  expect_same(got, want, 1e-12, "box mesh");
  Shape as_mesh;  // the same triangles as a mesh shape at the origin, density applied
  as_mesh.kind = ShapeKind::kMesh, as_mesh.name = "box";
  as_mesh.mesh = std::make_shared<TriangleMesh>(shape_triangles(b));
  const MassProperties dense = shape_mass_properties(as_mesh, 250.0);
  EXPECT_NEAR(dense.mass, 250.0 * 0.3 * 0.7 * 1.3, 1e-12 * dense.mass);
  expect_inertia(dense.inertia, shape_mass_properties(b, 250.0).inertia, 1e-12, "box mesh shape");
}

TEST(MassProperties, MeshOfACylinderIsTheRegularPolygonPrism) {
  // n segments draw the prism of the regular n-gon inscribed in the circle: both its exact forms agree
  for (int n : {8, 12, 40}) {
    Shape cylinder = solid(ShapeKind::kCylinder, 0.4, 1.2);
    cylinder.at = {0.5, 0.5, 0.5};
    std::vector<std::array<double, 2>> outline;
    for (int j = 0; j < n; ++j)
      outline.push_back({0.5 + 0.4 * std::cos(2 * kPi * j / n), 0.5 + 0.4 * std::sin(2 * kPi * j / n)});
    Shape ngon = prism(outline, 1.2);
    ngon.at = {0, 0, 0.5};
    const MassProperties want = shape_mass_properties(ngon, 1.0);
    EXPECT_NEAR(want.mass, n / 2.0 * 0.16 * std::sin(2 * kPi / n) * 1.2, 1e-14) << n;
    expect_same(mesh_mass_properties(shape_triangles(cylinder, n)), want, 1e-12, "n = " + std::to_string(n));
  }
}

TEST(MassProperties, InsideOutMeshHasANegativeVolumeAndIsRefused) {
  TriangleMesh turned = shape_triangles(box(1, 2, 3));
  for (auto& t : turned.triangles) std::swap(t[1], t[2]);
  const MassProperties p = mesh_mass_properties(turned);
  EXPECT_NEAR(p.mass, -6.0, 1e-14);
  EXPECT_NEAR(p.inertia[0], -6.0 * (4 + 9) / 12, 1e-13);
  Shape shape;
  shape.kind = ShapeKind::kMesh, shape.name = "hull", shape.file = "hull.stl";
  shape.mesh = std::make_shared<TriangleMesh>(turned);
  const std::string message = error_of([&] { shape_mass_properties(shape, 1.0); });
  EXPECT_NE(message.find("mesh 'hull' (hull.stl)"), std::string::npos) << message;
  EXPECT_NE(message.find("inwards"), std::string::npos) << message;
}

TEST(MassProperties, OpenMeshesAndShapesWithoutVolumeAreRefused) {
  TriangleMesh open = shape_triangles(box(1, 1, 1));
  open.triangles.resize(10);  // the +z face's two triangles removed
  EXPECT_FALSE(mesh_is_closed(open));
  Shape lid;
  lid.kind = ShapeKind::kMesh, lid.name = "lid", lid.file = "lid.stl";
  lid.mesh = std::make_shared<TriangleMesh>(open);
  std::string message = error_of([&] { shape_mass_properties(lid, 1.0); });
  EXPECT_NE(message.find("mesh 'lid' (lid.stl): the mesh is not closed"), std::string::npos) << message;
  Shape plane;
  plane.kind = ShapeKind::kPlane, plane.name = "ground", plane.size = {10, 10, 0};
  EXPECT_EQ(error_of([&] { shape_mass_properties(plane, 1.0); }),
            "plane 'ground': has no volume, so no mass properties");
  Shape curve;
  curve.kind = ShapeKind::kCurve, curve.radius = 0.01, curve.points = {{0, 0, 0}, {1, 0, 0}};
  EXPECT_EQ(error_of([&] { shape_mass_properties(curve, 1.0); }), "curve: has no volume, so no mass properties");
}

TEST(MassProperties, BadSizesDensitiesRotationsAndOutlinesAreRefused) {
  Shape rod = solid(ShapeKind::kCylinder, -0.1, 1.0);
  rod.name = "rod";
  EXPECT_EQ(error_of([&] { shape_mass_properties(rod, 1.0); }), "cylinder 'rod': radius -0.1 is not a positive length");
  EXPECT_EQ(error_of([&] { shape_mass_properties(box(1, 1, 1), 0.0); }), "box: density 0 is not a positive number");
  Shape sheared = box(1, 1, 1);
  sheared.rotation = {1, 0.1, 0, 0, 1, 0, 0, 0, 1};
  EXPECT_NE(error_of([&] { shape_mass_properties(sheared, 1.0); }).find("box: rotation is not a rotation matrix"),
            std::string::npos);
  Shape mirrored = box(1, 1, 1);
  mirrored.rotation = {-1, 0, 0, 0, 1, 0, 0, 0, 1};
  EXPECT_NE(error_of([&] { shape_mass_properties(mirrored, 1.0); }).find("det = -1"), std::string::npos);
  Shape bow_tie = prism({{0, 0}, {1, 1}, {1, 0}, {0, 1}}, 0.1);
  bow_tie.name = "tie";
  EXPECT_EQ(error_of([&] { shape_mass_properties(bow_tie, 1.0); }),
            "polygon 'tie': outline is not a simple polygon: edges 0 and 2 meet");
  EXPECT_EQ(error_of([&] {
              shape_mass_properties(prism({{0, 0}, {1, 0}}, 0.1), 1.0);
            }),
            "polygon: outline has 2 vertices, a polygon needs at least 3");
}

}  // namespace phiq::mass_properties_test
