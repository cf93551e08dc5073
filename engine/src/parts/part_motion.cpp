// part_motion() and part_jacobian() (phiq/part_motion.hpp): a frame's pose in truncated Taylor arithmetic along the
// path q(s) = q + s q̇ + s²/2 q̈ (or along one coordinate), read back as velocities, accelerations and Jacobians.
#include "phiq/part_motion.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "parts/frame_jets.hpp"
#include "parts/planar_motion.hpp"

namespace phiq {

namespace {

using Jet = detail::JetT<double>;
using JV = detail::JetV<double>;
using JR = detail::JetR<double>;
using detail::frame_jets;
using detail::product_transposed;
Jet constant(double c) { return detail::constant_jet<double>(c); }

// Where the path goes: along (q̇, q̈) with time (k < 0), or along coordinate k alone (a Jacobian column).
struct Path {
  const double* q;
  const double* qd;
  const double* qdd;
  double t;
  Index k = -1;

  Jet slot(const Slot& s) const {
    if (!s.is_coordinate()) return constant(s.value());
    const Index j = s.coord();
    if (k >= 0) return {q[j], j == k ? 1.0 : 0.0, 0.0};
    return {q[j], qd[j], qdd ? qdd[j] : 0.0};
  }
  // d/ds e = ∇e · q̇ + ∂e/∂t, d²/ds² e = ∇e · q̈ − γ (γ holds the Hessian's and the time terms).
  Jet expression(const CompiledExpression& e) const {
    const std::vector<Index>& c = e.coordinates();
    thread_local std::vector<double> g;  // (capacity kept: part_motion runs at every row of a sweep's efforts)
    g.resize(c.size());
    e.gradient(q, t, g.data());
    Jet j{e.value(q, t), 0.0, 0.0};
    if (k >= 0) {
      for (std::size_t i = 0; i < c.size(); ++i)
        if (c[i] == k) j.d += g[i];
      return j;
    }
    j.d = e.partial_t(q, t), j.dd = -e.gamma(q, qd, t);
    for (std::size_t i = 0; i < c.size(); ++i) {
      j.d += g[i] * qd[c[i]];
      if (qdd) j.dd += g[i] * qdd[c[i]];
    }
    return j;
  }
  JV natural(const Attachment3& a) const { return {slot(a.r[0]), slot(a.r[1]), slot(a.r[2])}; }
  std::array<double, 3> axis(const PartFrame& f) const { return {f.axis.x, f.axis.y, f.axis.z}; }
};

// The vector of the antisymmetric part of the 3×3 matrix m: (m32 − m23, m13 − m31, m21 − m12) / 2.
kin3::V3 vee(const double m[9]) { return {0.5 * (m[7] - m[5]), 0.5 * (m[2] - m[6]), 0.5 * (m[3] - m[1])}; }

// A planar frame's motion in closed form (parts/planar_motion.hpp) as a PartMotion: inverse dynamics calls
// part_motion() for every part at every row, where the jets cost as much as the row's solves. False for the other
// frames (the jets).
bool planar_part_motion(const PartFrame& f, const double* q, const double* qd, const double* qdd, PartMotion& m) {
  detail::PlanarFrame pf;
  detail::PlanarMotion p;
  if (!detail::planar_frame(f, pf) || !detail::planar_motion(pf, q, qd, qdd, p)) return false;
  m.pose.at = p.at, m.velocity = p.velocity, m.acceleration = p.acceleration;
  m.pose.rotation = {p.cos, -p.sin, 0.0, p.sin, p.cos, 0.0, 0.0, 0.0, 1.0};
  m.omega = {0.0, 0.0, p.omega}, m.alpha = {0.0, 0.0, p.alpha};
  return true;
}

}  // namespace

std::pair<kin3::V3, kin3::V3> PartMotion::point(kin3::V3 s) const {
  const kin3::V3 rs = pose.apply(s) - pose.at;
  return {velocity + kin3::cross(omega, rs),
          acceleration + kin3::cross(alpha, rs) + kin3::cross(omega, kin3::cross(omega, rs))};
}

PartMotion part_motion(const PartFrame& frame, const double* q, const double* qd, const double* qdd, double t) {
  PartMotion m;
  if (planar_part_motion(frame, q, qd, qdd, m)) return m;
  const auto [o, r] = frame_jets<double>(frame, Path{q, qd, qdd, t});
  m.pose = part_pose(frame, q, t);
  m.velocity = {o[0].d, o[1].d, o[2].d};
  m.acceleration = {o[0].dd, o[1].dd, o[2].dd};
  // [ω]× = Ṙ Rᵀ; R̈ Rᵀ = [α]× + [ω]×², whose antisymmetric part is [α]× ([ω]×² is symmetric)
  double w[9], a[9];
  product_transposed(r, &Jet::d, r, &Jet::v, w);
  product_transposed(r, &Jet::dd, r, &Jet::v, a);
  m.omega = vee(w), m.alpha = vee(a);
  return m;
}

PartJacobian part_jacobian(const PartFrame& frame, const double* q, double t) {
  PartJacobian jac;
  part_jacobian(frame, q, t, jac);
  return jac;
}

namespace {

// ∂/∂q in closed form for the frames whose rotation is one angle or Euler parameters: what inverse dynamics calls
// for every part at every row, where a jet pass per coordinate cost more than the rest of the row. False for the
// other frames (spatial frames from points, expressions), which take the jets. Pre-condition: jac.coordinates set,
// jac.d_origin and jac.d_angle zero, one per coordinate.
bool closed_form_jacobian(const PartFrame& f, const double* q, PartJacobian& jac) {
  auto add = [&](const Slot& s, kin3::V3 d_origin, kin3::V3 d_angle) {
    if (!s.is_coordinate()) return;
    const auto k = static_cast<std::size_t>(
        std::lower_bound(jac.coordinates.begin(), jac.coordinates.end(), s.coord()) - jac.coordinates.begin());
    jac.d_origin[k] = jac.d_origin[k] + d_origin, jac.d_angle[k] = jac.d_angle[k] + d_angle;
  };
  const kin3::V3 none{0, 0, 0}, ex{1, 0, 0}, ey{0, 1, 0}, ez{0, 0, 1};
  switch (f.kind) {
    case PartFrameKind::kPlanarBody:
      add(f.planar.x, ex, none), add(f.planar.y, ey, none), add(f.planar.psi, none, ez);
      return true;
    case PartFrameKind::kSpatialBody: {
      const Frame3& b = f.spatial;
      add(b.x, ex, none), add(b.y, ey, none), add(b.z, ez, none);
      // R(e/|e|): δθ = 2 E(ê) δe / |e|, E(ê) = [−ê, ê0 1 + [ê]×] (world axes; E ê = 0 drops the change of |e|)
      const double e[4] = {b.e0.of(q), b.e1.of(q), b.e2.of(q), b.e3.of(q)};
      const double n = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3]);
      const double k = 2.0 / (n * n);  // 2/|e| times the normalisation of ê
      add(b.e0, none, {-k * e[1], -k * e[2], -k * e[3]});
      add(b.e1, none, {k * e[0], k * e[3], -k * e[2]});
      add(b.e2, none, {-k * e[3], k * e[0], k * e[1]});
      add(b.e3, none, {k * e[2], -k * e[1], k * e[0]});
      return true;
    }
    case PartFrameKind::kPoints: {
      if (f.spatial_frame) return false;
      // origin o, x along d = x_toward − o (a point) or x_toward (a vector): θ = atan2(d_y, d_x)
      const Slot* o = f.origin.r;
      const Slot* x = f.x_toward.r;
      double dx = x[0].of(q), dy = x[1].of(q);
      if (f.x_is_point) dx -= o[0].of(q), dy -= o[1].of(q);
      const double d2 = dx * dx + dy * dy;
      const kin3::V3 along_x{0, 0, -dy / d2}, along_y{0, 0, dx / d2};  // ∂θ/∂d
      add(o[0], ex, none), add(o[1], ey, none), add(o[2], ez, none);
      add(x[0], none, along_x), add(x[1], none, along_y);
      if (f.x_is_point) add(o[0], none, -1.0 * along_x), add(o[1], none, -1.0 * along_y);
      return true;
    }
    case PartFrameKind::kExpressions:
      return false;
  }
  return false;
}

}  // namespace

void part_jacobian(const PartFrame& frame, const double* q, double t, PartJacobian& jac) {
  frame_coordinates(frame, jac.coordinates);
  jac.d_origin.assign(jac.coordinates.size(), kin3::V3{0, 0, 0});
  jac.d_angle.assign(jac.coordinates.size(), kin3::V3{0, 0, 0});
  if (closed_form_jacobian(frame, q, jac)) return;
  jac.d_origin.clear(), jac.d_angle.clear();
  for (Index k : jac.coordinates) {
    const auto [o, r] = frame_jets<double>(frame, Path{q, nullptr, nullptr, t, k});
    double w[9];
    product_transposed(r, &Jet::d, r, &Jet::v, w);
    jac.d_origin.push_back({o[0].d, o[1].d, o[2].d});
    jac.d_angle.push_back(vee(w));
  }
}

}  // namespace phiq
