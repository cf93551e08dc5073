// The triangles that draw a shape (shapes.hpp: shape_triangles): every closed one counter-clockwise seen from
// outside, tessellated in the shape's frame and then placed in the body's.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "parts/curve_tube.hpp"
#include "parts/polygon.hpp"
#include "parts/shape_checks.hpp"
#include "phiq/shapes.hpp"

namespace phiq {

namespace {

using kin3::V3;
using Profile = std::vector<std::array<double, 2>>;  // (r, z) points of a surface of revolution

TriangleMesh box_triangles(V3 size) {
  TriangleMesh mesh;
  for (int k = 0; k < 8; ++k)  // corner k = i + 2 j + 4 k' at ((i − ½) a, (j − ½) b, (k' − ½) c)
    mesh.vertices.push_back({((k & 1) - 0.5) * size.x, (((k >> 1) & 1) - 0.5) * size.y, ((k >> 2) - 0.5) * size.z});
  // each face's corners counter-clockwise seen from outside: −x, +x, −y, +y, −z, +z
  const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces) {
    mesh.triangles.push_back({f[0], f[1], f[2]});
    mesh.triangles.push_back({f[0], f[2], f[3]});
  }
  return mesh;
}

// The surface swept by `profile` about z: it runs from a point on the axis (r = 0) below to one above, with r > 0
// in between, so that it turns counter-clockwise about the solid in the (r, z) half-plane. Each point with r > 0
// becomes a ring of n vertices, each on the axis one vertex. Between two rings, the quad (p, q) below and (s, r)
// above, at angles j, j + 1, is (p, q, r) and (p, r, s): (q − p) × (s − p) lies along θ̂ × t̂, outwards.
TriangleMesh revolve(const Profile& profile, int n) {
  TriangleMesh mesh;
  std::vector<int> first;  // index of each profile point's first vertex
  for (const auto& [r, z] : profile) {
    first.push_back(static_cast<int>(mesh.vertices.size()));
    if (r == 0.0) {
      mesh.vertices.push_back({0.0, 0.0, z});
      continue;
    }
    for (int j = 0; j < n; ++j) {
      const double angle = 2.0 * std::numbers::pi * j / n;
      mesh.vertices.push_back({r * std::cos(angle), r * std::sin(angle), z});
    }
  }
  for (std::size_t k = 0; k + 1 < profile.size(); ++k) {
    const bool axis_below = profile[k][0] == 0.0, axis_above = profile[k + 1][0] == 0.0;
    for (int j = 0; j < n; ++j) {
      const int jn = (j + 1) % n;
      const int p = first[k] + (axis_below ? 0 : j), q = first[k] + (axis_below ? 0 : jn);
      const int r = first[k + 1] + (axis_above ? 0 : jn), s = first[k + 1] + (axis_above ? 0 : j);
      if (!axis_below) mesh.triangles.push_back({p, q, r});
      if (!axis_above) mesh.triangles.push_back({p, r, s});
    }
  }
  return mesh;
}

// A quarter circle of radius `r` about (0, z0) from angle a0 to a1 (from the xy-plane towards +z) in `steps`,
// appended to `profile` without its first point; an arc that ends at a pole (a1 = ±π/2) ends on the axis exactly.
void append_arc(Profile& profile, double r, double z0, double a0, double a1, int steps) {
  for (int k = 1; k <= steps; ++k) {
    const double a = a0 + (a1 - a0) * k / steps;
    if (k == steps && a1 != 0.0)
      profile.push_back({0.0, z0 + std::copysign(r, a1)});
    else
      profile.push_back({r * std::cos(a), z0 + r * std::sin(a)});
  }
}

// A sphere (length = 0) or a capsule: from the bottom pole a quarter circle of n/4 steps (at least 2) to the
// equator, the cylinder's side, and a quarter circle to the top pole.
TriangleMesh rounded(double r, double length, int n) {
  const int steps = std::max(n / 4, 2);
  const double half = std::numbers::pi / 2.0;
  Profile profile{{0.0, -length / 2.0 - r}};
  append_arc(profile, r, -length / 2.0, -half, 0.0, steps);
  if (length > 0.0) profile.push_back({r, length / 2.0});
  append_arc(profile, r, length / 2.0, 0.0, half, steps);
  return revolve(profile, n);
}

// The polygon's prism: its outline (counter-clockwise) at z = ∓t/2, the caps from its triangles (the lower one
// turned over), each side quad (p, q) below, (s, r) above.
TriangleMesh polygon_prism_triangles(const Shape& shape) {
  const detail::parts::Outline outline = detail::parts::counter_clockwise_outline(shape);
  const int n = static_cast<int>(outline.size());
  TriangleMesh mesh;
  for (double z : {-shape.length / 2.0, shape.length / 2.0})
    for (const auto& v : outline) mesh.vertices.push_back({v[0], v[1], z});
  for (const auto& t : detail::parts::polygon_triangles(outline, shape)) {
    mesh.triangles.push_back({t[0], t[2], t[1]});
    mesh.triangles.push_back({n + t[0], n + t[1], n + t[2]});
  }
  for (int i = 0; i < n; ++i) {
    const int p = i, q = (i + 1) % n, r = n + q, s = n + i;
    mesh.triangles.push_back({p, q, r});
    mesh.triangles.push_back({p, r, s});
  }
  return mesh;
}

TriangleMesh in_shape_frame(const Shape& shape, int n) {
  const double r = shape.radius, h = shape.length;
  switch (shape.kind) {
    case ShapeKind::kBox:
      return box_triangles(shape.size);
    case ShapeKind::kCylinder:
      return revolve({{0, -h / 2}, {r, -h / 2}, {r, h / 2}, {0, h / 2}}, n);
    case ShapeKind::kSphere:
      return rounded(r, 0.0, n);
    case ShapeKind::kCapsule:
      return rounded(r, h, n);
    case ShapeKind::kCone:
      return revolve({{0, 0}, {r, 0}, {0, h}}, n);
    case ShapeKind::kPolygon:
      return polygon_prism_triangles(shape);
    case ShapeKind::kMesh:
      return *shape.mesh;
    case ShapeKind::kCurve:
      return detail::parts::curve_tube(shape, n);
    case ShapeKind::kPlane:
      break;
  }
  TriangleMesh plane;  // z = 0, seen from +z
  const double x = shape.size.x / 2.0, y = shape.size.y / 2.0;
  plane.vertices = {{-x, -y, 0}, {x, -y, 0}, {x, y, 0}, {-x, y, 0}};
  plane.triangles = {{0, 1, 2}, {0, 2, 3}};
  return plane;
}

}  // namespace

TriangleMesh shape_triangles(const Shape& shape, int segments) {
  detail::parts::check_shape(shape);
  TriangleMesh mesh = in_shape_frame(shape, std::max(segments, 8));
  for (V3& v : mesh.vertices) v = detail::parts::place_point(shape, v);
  return mesh;
}

}  // namespace phiq
