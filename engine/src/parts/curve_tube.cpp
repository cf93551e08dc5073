// A curve drawn as a tube (curve_tube.hpp).
#include "parts/curve_tube.hpp"

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "parts/shape_checks.hpp"
#include "phiq/types.hpp"

namespace phiq::detail::parts {

namespace {

using kin3::V3;

V3 unit(V3 v) { return (1.0 / kin3::norm(v)) * v; }

// The points with consecutive repeats (and, when closed, a last point equal to the first) dropped.
std::vector<V3> distinct_points(const Shape& shape) {
  std::vector<V3> points;
  for (std::size_t i = 0; i < shape.points.size(); ++i) {
    const V3& p = shape.points[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw Error(shape_label(shape) + ": point " + std::to_string(i) + " is not finite");
    if (points.empty() || !(points.back() == p)) points.push_back(p);
  }
  while (shape.closed && points.size() > 1 && points.back() == points.front()) points.pop_back();
  const std::size_t least = shape.closed ? 3 : 2;
  if (points.size() < least)
    throw Error(shape_label(shape) + ": " + std::to_string(points.size()) + " distinct points, a" +
                (shape.closed ? " closed" : "n open") + " curve needs at least " + std::to_string(least));
  return points;
}

// The direction of the ring at each point: halfway between its segments' (the segment's own at an open end, and
// the next segment's where the curve turns back on itself).
std::vector<V3> ring_tangents(const std::vector<V3>& x, bool closed) {
  const std::size_t n = x.size();
  std::vector<V3> segment;
  for (std::size_t i = 0; i + 1 < n + (closed ? 1 : 0); ++i) segment.push_back(unit(x[(i + 1) % n] - x[i]));
  std::vector<V3> tangent(n);
  for (std::size_t k = 0; k < n; ++k) {
    const bool has_before = closed || k > 0, has_after = closed || k + 1 < n;
    const V3 after = has_after ? segment[k] : segment[k - 1];
    const V3 sum = has_before ? segment[(k + n - 1) % n] + after : after;
    tangent[k] = kin3::norm(sum) > 1e-12 ? unit(sum) : after;
  }
  return tangent;
}

// The normal r at x0 (tangent t0) carried to x1 (tangent t1) by two reflections: the first in the plane bisecting
// x0 x1, the second taking the reflected tangent to t1.
V3 carry_normal(V3 x0, V3 t0, V3 r, V3 x1, V3 t1) {
  const V3 v1 = x1 - x0;
  const double c1 = kin3::dot(v1, v1);
  const V3 r_l = r - (2.0 / c1 * kin3::dot(v1, r)) * v1, t_l = t0 - (2.0 / c1 * kin3::dot(v1, t0)) * v1;
  const V3 v2 = t1 - t_l;
  const double c2 = kin3::dot(v2, v2);
  const V3 carried = c2 > 0.0 ? r_l - (2.0 / c2 * kin3::dot(v2, r_l)) * v2 : r_l;
  return unit(carried - kin3::dot(carried, t1) * t1);
}

}  // namespace

TriangleMesh curve_tube(const Shape& shape, int n) {
  const std::vector<V3> x = distinct_points(shape);
  const std::vector<V3> t = ring_tangents(x, shape.closed);
  const std::size_t count = x.size();
  std::vector<V3> r{kin3::perpendicular_unit(t[0])};
  for (std::size_t k = 0; k + 1 < count; ++k) r.push_back(carry_normal(x[k], t[k], r[k], x[k + 1], t[k + 1]));
  if (shape.closed) {
    // back at the start the carried normal is off by a turn φ about t0: each ring takes its share k φ / count
    const V3 back = carry_normal(x[count - 1], t[count - 1], r[count - 1], x[0], t[0]);
    const double phi = std::atan2(kin3::dot(kin3::cross(back, r[0]), t[0]), kin3::dot(back, r[0]));
    for (std::size_t k = 1; k < count; ++k) {
      const double a = phi * static_cast<double>(k) / static_cast<double>(count);
      r[k] = std::cos(a) * r[k] + std::sin(a) * kin3::cross(t[k], r[k]);
    }
  }
  TriangleMesh mesh;
  const double half_width = shape.radius;  // the tube's radius: half the drawn width
  for (std::size_t k = 0; k < count; ++k) {
    const V3 b = kin3::cross(t[k], r[k]);  // r, b, t right-handed: the ring turns counter-clockwise about t
    for (int j = 0; j < n; ++j) {
      const double angle = 2.0 * std::numbers::pi * j / n;
      mesh.vertices.push_back(x[k] + half_width * (std::cos(angle) * r[k] + std::sin(angle) * b));
    }
  }
  const auto ring = [n](std::size_t k, int j) { return static_cast<int>(k) * n + (j % n); };
  for (std::size_t k = 0; k + 1 < count + (shape.closed ? 1 : 0); ++k) {
    const std::size_t next = (k + 1) % count;
    for (int j = 0; j < n; ++j) {  // quad (p, q) on this ring, (s, r) on the next: outward as in revolve()
      mesh.triangles.push_back({ring(k, j), ring(k, j + 1), ring(next, j + 1)});
      mesh.triangles.push_back({ring(k, j), ring(next, j + 1), ring(next, j)});
    }
  }
  if (!shape.closed) {  // caps: fans from each end point, facing away from the tube
    const int start = static_cast<int>(mesh.vertices.size()), end = start + 1;
    mesh.vertices.push_back(x.front());
    mesh.vertices.push_back(x.back());
    for (int j = 0; j < n; ++j) {
      mesh.triangles.push_back({start, ring(0, j + 1), ring(0, j)});
      mesh.triangles.push_back({ring(count - 1, j), ring(count - 1, j + 1), end});
    }
  }
  return mesh;
}

}  // namespace phiq::detail::parts
