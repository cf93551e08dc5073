#include "phiq/output_points.hpp"

#include <algorithm>
#include <cmath>

namespace phiq {

Index OutputPoint::max_coordinate() const {
  switch (kind) {
    case OutputPointKind::kPlanarPoint:
      return std::max(point.x.coord(), point.y.coord());
    case OutputPointKind::kPlanarBodyPoint:
      return std::max({body.x.coord(), body.y.coord(), body.psi.coord()});
    case OutputPointKind::kSpatialPoint:
    case OutputPointKind::kSpatialBodyPoint: {
      Index m = -1;
      for (const Slot& s : spatial.r) m = std::max(m, s.coord());
      for (const Slot& s : spatial.p) m = std::max(m, s.coord());
      return m;
    }
  }
  return -1;
}

OutputPoint planar_point(std::string name, Point2 p) {
  OutputPoint o;
  o.name = std::move(name);
  o.kind = OutputPointKind::kPlanarPoint;
  o.point = p;
  return o;
}

OutputPoint planar_body_point(std::string name, Frame2 body, double sx, double sy) {
  if (!std::isfinite(sx) || !std::isfinite(sy)) throw Error("output point '" + name + "': 'at' is not finite");
  OutputPoint o;
  o.name = std::move(name);
  o.kind = OutputPointKind::kPlanarBodyPoint;
  o.body = body;
  o.local_x = sx, o.local_y = sy;
  return o;
}

OutputPoint spatial_point(std::string name, Point3 p) {
  OutputPoint o;
  o.name = std::move(name);
  o.kind = OutputPointKind::kSpatialPoint;
  o.spatial = Attachment3::natural(p);
  return o;
}

OutputPoint spatial_body_point(std::string name, const Frame3& body, kin3::V3 at) {
  if (!std::isfinite(at.x) || !std::isfinite(at.y) || !std::isfinite(at.z))
    throw Error("output point '" + name + "': 'at' is not finite");
  OutputPoint o;
  o.name = std::move(name);
  o.kind = OutputPointKind::kSpatialBodyPoint;
  o.spatial = Attachment3::body_point(body, at);
  return o;
}

PointMotion evaluate_point(const OutputPoint& p, const double* q, const double* qd, const double* qdd) {
  PointMotion m;
  switch (p.kind) {
    case OutputPointKind::kPlanarPoint:
      m.r = {p.point.x.of(q), p.point.y.of(q), 0.0};
      if (qd) m.v = {p.point.x.rate(qd), p.point.y.rate(qd), 0.0};
      if (qd && qdd) m.a = {p.point.x.rate(qdd), p.point.y.rate(qdd), 0.0};
      break;
    case OutputPointKind::kPlanarBodyPoint: {
      const double psi = p.body.psi.of(q), c = std::cos(psi), s = std::sin(psi);
      const double rsx = c * p.local_x - s * p.local_y, rsy = s * p.local_x + c * p.local_y;  // R(ψ) s
      // R'(ψ) s = perp(R(ψ) s) = (−rsy, rsx)
      m.r = {p.body.x.of(q) + rsx, p.body.y.of(q) + rsy, 0.0};
      if (qd) {
        const double w = p.body.psi.rate(qd);
        m.v = {p.body.x.rate(qd) - w * rsy, p.body.y.rate(qd) + w * rsx, 0.0};
        if (qdd) {
          const double al = p.body.psi.rate(qdd);
          m.a = {p.body.x.rate(qdd) - al * rsy - w * w * rsx, p.body.y.rate(qdd) + al * rsx - w * w * rsy, 0.0};
        }
      }
      break;
    }
    case OutputPointKind::kSpatialPoint:
    case OutputPointKind::kSpatialBodyPoint: {
      const Attachment3& x = p.spatial;
      const kin3::V3 r = x.value(q);
      m.r = {r.x, r.y, r.z};
      if (qd) {
        const kin3::V3 v = x.rate(q, qd);
        m.v = {v.x, v.y, v.z};
        if (qdd) {
          const kin3::V3 a = x.rate(q, qdd) + x.bias(qd);  // the q̈-linear part, and the rest (2 R(ė) s)
          m.a = {a.x, a.y, a.z};
        }
      }
      break;
    }
  }
  return m;
}

}  // namespace phiq
