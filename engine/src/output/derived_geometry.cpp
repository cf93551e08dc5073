// The shapes of derived parts (derived_geometry.hpp).
#include "derived_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

namespace phiq::derived {

using kin3::V3;

RotationMatrix about_z(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c, -s, 0, s, c, 0, 0, 0, 1};
}

RotationMatrix z_along(V3 u) {
  const V3 z = (1.0 / kin3::norm(u)) * u;
  const V3 x = kin3::perpendicular_unit(z);  // the world axis least along z, made perpendicular to it
  const V3 y = kin3::cross(z, x);
  return {x.x, y.x, z.x, x.y, y.y, z.y, x.z, y.z, z.z};
}

RotationMatrix compose(const RotationMatrix& a, const RotationMatrix& b) {
  RotationMatrix c{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) c[3 * i + j] += a[3 * i + k] * b[3 * k + j];
  return c;
}

V3 to_local(const Pose& pose, V3 x) {
  const V3 d = x - pose.at;
  const auto& r = pose.rotation;
  return {r[0] * d.x + r[3] * d.y + r[6] * d.z, r[1] * d.x + r[4] * d.y + r[7] * d.z,
          r[2] * d.x + r[5] * d.y + r[8] * d.z};
}

V3 turn(const Pose& pose, V3 v) {
  Pose p = pose;
  p.at = {};
  return p.apply(v);
}

std::optional<Shape> capsule(V3 a, V3 b, double radius) {
  const double length = kin3::norm(b - a);
  if (!(length > 0.0)) return std::nullopt;
  Shape s;
  s.kind = ShapeKind::kCapsule;
  s.at = 0.5 * (a + b);
  s.rotation = z_along(b - a);
  s.radius = radius, s.length = length;
  return s;
}

Shape cylinder(V3 at, V3 axis, double radius, double length) {
  Shape s;
  s.kind = ShapeKind::kCylinder;
  s.at = at, s.rotation = z_along(axis);
  s.radius = radius, s.length = length;
  return s;
}

Shape box(V3 at, const RotationMatrix& rotation, V3 size) {
  Shape s;
  s.kind = ShapeKind::kBox;
  s.at = at, s.rotation = rotation, s.size = size;
  return s;
}

Shape sphere(V3 at, double radius) {
  Shape s;
  s.kind = ShapeKind::kSphere;
  s.at = at, s.radius = radius;
  return s;
}

Shape polyline(std::vector<V3> points, bool closed, double width) {
  Shape s;
  s.kind = ShapeKind::kCurve;
  s.points = std::move(points), s.closed = closed, s.radius = width;
  return s;
}

namespace {
// The arc of radius r about c from angle a0 to a1 (either way), `step` apart at most, without its last point.
void arc(std::vector<V3>& out, V3 c, double r, double a0, double a1, double step) {
  const int n = std::max(1, static_cast<int>(std::ceil(std::fabs(a1 - a0) / step)));
  for (int k = 0; k < n; ++k) {
    const double a = a0 + (a1 - a0) * k / n;
    out.push_back({c.x + r * std::cos(a), c.y + r * std::sin(a), 0.0});
  }
}
}  // namespace

std::vector<V3> belt_path(double d, double r1, double r2, bool crossed, double step) {
  constexpr double pi = std::numbers::pi;
  // φ: the angle from +x of the radius to the upper tangent point on pulley 1
  const double phi = std::acos(std::clamp((crossed ? r1 + r2 : r1 - r2) / d, -1.0, 1.0));
  std::vector<V3> out;
  const V3 c1{0, 0, 0}, c2{d, 0, 0};
  arc(out, c1, r1, phi, 2 * pi - phi, step);  // the far side of pulley 1, then the lower tangent (a straight run)
  if (crossed)
    arc(out, c2, r2, pi - phi, phi - pi, step);  // the far side of pulley 2, turned the other way
  else
    arc(out, c2, r2, -phi, phi, step);
  return out;  // closed: the upper tangent runs back to the first point
}

std::vector<V3> helix(V3 at, V3 axis, V3 ref, double radius, double pitch, int turns, int per_turn) {
  const V3 side = kin3::cross(axis, ref);
  std::vector<V3> out;
  const int n = turns * per_turn;
  for (int k = 0; k <= n; ++k) {
    const double u = static_cast<double>(k - n / 2) / per_turn;  // turns from the middle
    const double a = 2.0 * std::numbers::pi * u;
    out.push_back(at + (radius * std::cos(a)) * ref + (radius * std::sin(a)) * side + (pitch * u) * axis);
  }
  return out;
}

std::vector<V3> curve_samples(const Curve& curve, int count) {
  std::vector<V3> out;
  const int n = curve.closed() ? count : count + 1;
  for (int k = 0; k < n; ++k) {
    kin::V2 c[4];
    curve.evaluate(curve.length() * k / count, c);
    out.push_back({c[0].x, c[0].y, 0.0});
  }
  return out;
}

}  // namespace phiq::derived
