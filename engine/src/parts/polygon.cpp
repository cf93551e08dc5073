// A polygon's outline checked and oriented, its area moments and its ear-clipped triangles (polygon.hpp).
#include "parts/polygon.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "parts/shape_checks.hpp"
#include "phiq/text.hpp"
#include "phiq/types.hpp"

namespace phiq::detail::parts {

namespace {

using P2 = std::array<double, 2>;

// (b − a) × (c − a): positive when a, b, c turn counter-clockwise, zero when they are collinear.
double turn(const P2& a, const P2& b, const P2& c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

int sign(double v) { return (v > 0.0) - (v < 0.0); }

// p, collinear with segment ab, lies on it (ends included).
bool within(const P2& a, const P2& b, const P2& p) {
  return std::min(a[0], b[0]) <= p[0] && p[0] <= std::max(a[0], b[0]) && std::min(a[1], b[1]) <= p[1] &&
         p[1] <= std::max(a[1], b[1]);
}

// Segments ab and cd share a point (crossing, touching or overlapping).
bool segments_meet(const P2& a, const P2& b, const P2& c, const P2& d) {
  const int o1 = sign(turn(a, b, c)), o2 = sign(turn(a, b, d)), o3 = sign(turn(c, d, a)), o4 = sign(turn(c, d, b));
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  return (o1 == 0 && within(a, b, c)) || (o2 == 0 && within(a, b, d)) || (o3 == 0 && within(c, d, a)) ||
         (o4 == 0 && within(c, d, b));
}

// The first pair of edges that makes the outline not simple, as "edges i and j", or "" for a simple outline. Edges
// that share a vertex may only meet there: they fail when they fold back over each other.
std::string self_contact(const Outline& o) {
  const std::size_t n = o.size();
  for (std::size_t i = 0; i < n; ++i) {
    const P2 &a = o[i], &b = o[(i + 1) % n], &c = o[(i + 2) % n];
    const double dot = (b[0] - a[0]) * (c[0] - b[0]) + (b[1] - a[1]) * (c[1] - b[1]);
    if (n > 3 && turn(a, b, c) == 0.0 && dot < 0.0)
      return "edges " + std::to_string(i) + " and " + std::to_string((i + 1) % n) + " fold back";
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // neighbours across the closing vertex
      if (segments_meet(a, b, o[j], o[(j + 1) % n]))
        return "edges " + std::to_string(i) + " and " + std::to_string(j) + " meet";
    }
  }
  return "";
}

}  // namespace

Outline counter_clockwise_outline(const Shape& shape) {
  Outline outline = shape.outline;
  const std::string where = shape_label(shape) + ": outline";
  if (outline.size() < 3)
    throw Error(where + " has " + std::to_string(outline.size()) + " vertices, a polygon needs at least 3");
  for (std::size_t i = 0; i < outline.size(); ++i) {
    if (!std::isfinite(outline[i][0]) || !std::isfinite(outline[i][1]))
      throw Error(where + " vertex " + std::to_string(i) + " is not finite");
    if (outline[i] == outline[(i + 1) % outline.size()])
      throw Error(where + " vertices " + std::to_string(i) + " and " + std::to_string((i + 1) % outline.size()) +
                  " are the same point");
  }
  const std::string contact = self_contact(outline);
  if (!contact.empty()) throw Error(where + " is not a simple polygon: " + contact);
  const double area = area_moments(outline).area;
  if (area == 0.0) throw Error(where + " encloses no area");
  if (area < 0.0) std::reverse(outline.begin(), outline.end());
  return outline;
}

AreaMoments area_moments(const Outline& o) {
  // Green's theorem over each edge (x0, y0) → (x1, y1), with c = x0 y1 − x1 y0 twice the signed area of the
  // triangle (origin, edge): the integrals of 1, x, y, x², y², xy over that triangle, summed.
  AreaMoments m;
  for (std::size_t i = 0; i < o.size(); ++i) {
    const double x0 = o[i][0], y0 = o[i][1], x1 = o[(i + 1) % o.size()][0], y1 = o[(i + 1) % o.size()][1];
    const double c = x0 * y1 - x1 * y0;
    m.area += c / 2.0;
    m.x += c * (x0 + x1) / 6.0;
    m.y += c * (y0 + y1) / 6.0;
    m.xx += c * (x0 * x0 + x0 * x1 + x1 * x1) / 12.0;
    m.yy += c * (y0 * y0 + y0 * y1 + y1 * y1) / 12.0;
    m.xy += c * (x0 * y1 + 2.0 * x0 * y0 + 2.0 * x1 * y1 + x1 * y0) / 24.0;
  }
  return m;
}

std::vector<std::array<int, 3>> polygon_triangles(const Outline& ccw, const Shape& shape) {
  std::vector<int> left(ccw.size());
  for (std::size_t i = 0; i < left.size(); ++i) left[i] = static_cast<int>(i);
  std::vector<std::array<int, 3>> triangles;
  // An ear: a vertex turning counter-clockwise whose triangle with its neighbours holds no other vertex (not even
  // on its border); a vertex on a straight run between its neighbours is one too, of zero area.
  const auto is_ear = [&](std::size_t k) {
    const std::size_t m = left.size();
    const P2 &a = ccw[left[(k + m - 1) % m]], &b = ccw[left[k]], &c = ccw[left[(k + 1) % m]];
    const double t = turn(a, b, c);
    if (t < 0.0) return false;
    if (t == 0.0) return true;  // between its neighbours: the outline is simple, so it cannot fold back
    for (std::size_t j = 0; j < m; ++j) {
      if (j == k || j == (k + 1) % m || j == (k + m - 1) % m) continue;
      const P2& p = ccw[left[j]];
      if (turn(a, b, p) >= 0.0 && turn(b, c, p) >= 0.0 && turn(c, a, p) >= 0.0) return false;
    }
    return true;
  };
  while (left.size() > 3) {
    const std::size_t m = left.size();
    std::size_t k = 0;
    while (k < m && !is_ear(k)) ++k;
    if (k == m) throw Error(shape_label(shape) + ": outline could not be cut into triangles (not a simple polygon)");
    triangles.push_back({left[(k + m - 1) % m], left[k], left[(k + 1) % m]});
    left.erase(left.begin() + static_cast<std::ptrdiff_t>(k));
  }
  triangles.push_back({left[0], left[1], left[2]});
  return triangles;
}

}  // namespace phiq::detail::parts
