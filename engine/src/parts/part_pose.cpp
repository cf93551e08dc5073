// part_pose() and max_coordinate() (phiq/parts.hpp): a part's frame at q, in each coordinate family.
#include <algorithm>
#include <cmath>
#include <limits>

#include "phiq/orientation.hpp"
#include "phiq/parts.hpp"

namespace phiq {

namespace {

using kin3::V3;

// The rotation whose columns are x, y, z.
RotationMatrix columns(V3 x, V3 y, V3 z) { return {x.x, y.x, z.x, x.y, y.y, z.y, x.z, y.z, z.z}; }

RotationMatrix about_z(double psi) {
  const double c = std::cos(psi), s = std::sin(psi);
  return {c, -s, 0, s, c, 0, 0, 0, 1};
}

// The direction a kPoints frame's axis points along: to a point from the origin, or a vector as it is.
V3 direction(const Attachment3& toward, bool is_point, V3 origin, const double* q) {
  const V3 v = toward.value(q);
  return is_point ? v - origin : v;
}

Pose nan_pose() {
  const double n = std::numeric_limits<double>::quiet_NaN();
  Pose p;
  p.at = {n, n, n};
  p.rotation.fill(n);
  return p;
}

Pose points_pose(const PartFrame& f, const double* q, bool spatial) {
  Pose p;
  p.at = f.origin.value(q);
  V3 x = direction(f.x_toward, f.x_is_point, p.at, q);
  const double nx = kin3::norm(x);
  if (!(nx > 0.0)) return nan_pose();
  x = (1.0 / nx) * x;
  if (!spatial) {  // in the plane: y = z × x
    p.rotation = columns(x, {-x.y, x.x, 0.0}, {0, 0, 1});
    return p;
  }
  const V3 w = direction(f.y_toward, f.y_is_point, p.at, q);
  V3 y = w - kin3::dot(w, x) * x;  // Gram–Schmidt: y is w's part perpendicular to x
  const double ny = kin3::norm(y);
  if (!(ny > 1e-12 * kin3::norm(w))) return nan_pose();
  y = (1.0 / ny) * y;
  p.rotation = columns(x, y, kin3::cross(x, y));
  return p;
}

}  // namespace

Pose part_pose(const PartFrame& f, const double* q, double t) {
  Pose p;
  switch (f.kind) {
    case PartFrameKind::kPlanarBody:
      p.at = {f.planar.x.of(q), f.planar.y.of(q), 0.0};
      p.rotation = about_z(f.planar.psi.of(q));
      return p;
    case PartFrameKind::kSpatialBody: {
      const Frame3& b = f.spatial;
      p.at = {b.x.of(q), b.y.of(q), b.z.of(q)};
      const EulerParameters e{b.e0.of(q), b.e1.of(q), b.e2.of(q), b.e3.of(q)};
      const double n = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3]);
      if (!(n > 0.0)) return nan_pose();
      p.rotation = rotation_matrix({e[0] / n, e[1] / n, e[2] / n, e[3] / n});
      return p;
    }
    case PartFrameKind::kPoints:
      return points_pose(f, q, f.spatial_frame);
    case PartFrameKind::kExpressions: {
      double c[3] = {0.0, 0.0, 0.0};
      for (std::size_t k = 0; k < f.at.size() && k < 3; ++k) c[k] = f.at[k]->value(q, t);
      p.at = {c[0], c[1], c[2]};
      if (f.angle) {  // (cos θ/2, u sin θ/2), u the unit axis (normalised when the frame was read)
        const double h = 0.5 * f.angle->value(q, t), s = std::sin(h);
        p.rotation = rotation_matrix({std::cos(h), f.axis.x * s, f.axis.y * s, f.axis.z * s});
      }
      return p;
    }
  }
  return p;
}

std::vector<Index> frame_coordinates(const PartFrame& f) {
  std::vector<Index> out;
  frame_coordinates(f, out);
  return out;
}

namespace {

// visit(c) for each coordinate `f` reads, in its slots' order (repeats included).
template <class Visit>
void for_each_frame_coordinate(const PartFrame& f, Visit&& visit) {
  auto slot = [&](const Slot& s) {
    if (s.is_coordinate()) visit(s.coord());
  };
  switch (f.kind) {
    case PartFrameKind::kPlanarBody:
      slot(f.planar.x), slot(f.planar.y), slot(f.planar.psi);
      break;
    case PartFrameKind::kSpatialBody:
      for (const Slot* s :
           {&f.spatial.x, &f.spatial.y, &f.spatial.z, &f.spatial.e0, &f.spatial.e1, &f.spatial.e2, &f.spatial.e3})
        slot(*s);
      break;
    case PartFrameKind::kPoints:
      for (const Attachment3* a : {&f.origin, &f.x_toward, &f.y_toward}) {
        for (const Slot& s : a->r) slot(s);
        for (const Slot& s : a->p) slot(s);
      }
      break;
    case PartFrameKind::kExpressions:
      for (const auto& e : f.at)
        for (Index c : e->coordinates()) visit(c);
      if (f.angle)
        for (Index c : f.angle->coordinates()) visit(c);
      break;
  }
}

}  // namespace

void frame_coordinates(const PartFrame& f, std::vector<Index>& out) {
  out.clear();
  for_each_frame_coordinate(f, [&](Index c) { out.push_back(c); });
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

Index max_coordinate(const PartFrame& f) {
  Index most = -1;  // (no list: a scene's 10⁴ parts are each asked, in reading and in checking a sweep)
  for_each_frame_coordinate(f, [&](Index c) { most = std::max(most, c); });
  return most;
}

}  // namespace phiq
