// The constraint kinds of phiq, as plain data (one struct per kind).
//
// Every kind states its equation Φ(q, t) = 0 in a comment and supplies, for the rows it owns:
//   residual(q, t, phi)        Φ
//   jacobian(q, t, sink)       Φq as (row, slot, value) entries through `sink`, always in the same order and with the
//                              same set of entries (the set may depend on which slots are constants, never on values),
//                              so that one pass in pattern mode fixes the sparsity pattern of the model
//   phi_t(q, t, out)           ∂Φ/∂t (only called when depends_on_time())
//   gamma(q, qd, t, out)       γ = −(Φq q̇)q q̇ − 2 Φqt q̇ − Φtt, the right-hand side of Φq q̈ = γ
// plus the unit of each row and, through for_each_slot, the unit of each coordinate it reads. The solver never
// needs to know which kind it is evaluating (see constraint_block.hpp).
//
// Covers the four coordinate families of the notes: natural coordinates (distance, fixed point through Pin with a
// constant side, point on line, constant angle), reference-point coordinates (revolute Pin between body frames,
// prismatic), relative coordinates (loop closure), mixes (segment angle, polar), general equations and drivers.
#pragma once

#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "phiq/expression.hpp"
#include "phiq/motion_law.hpp"
#include "phiq/types.hpp"

namespace phiq {

namespace kin {
struct V2 {
  double x, y;
};
inline V2 operator+(V2 a, V2 b) { return {a.x + b.x, a.y + b.y}; }
inline V2 operator-(V2 a, V2 b) { return {a.x - b.x, a.y - b.y}; }
inline V2 operator*(double s, V2 a) { return {s * a.x, s * a.y}; }
inline double dot(V2 a, V2 b) { return a.x * b.x + a.y * b.y; }
inline double cross(V2 a, V2 b) { return a.x * b.y - a.y * b.x; }
inline V2 perp(V2 a) { return {-a.y, a.x}; }  // rotation by +90°
inline V2 rotate(double psi, V2 s) {
  double c = std::cos(psi), n = std::sin(psi);
  return {c * s.x - n * s.y, n * s.x + c * s.y};
}
inline V2 pos(const Point2& p, const double* q) { return {p.x.of(q), p.y.of(q)}; }
inline V2 vel(const Point2& p, const double* qd) { return {p.x.rate(qd), p.y.rate(qd)}; }
}  // namespace kin

// Distance between two points (natural coordinates): rigid-body condition of a bar.
//   Φ = (|b − a|² − L²) / (2L)
// Dividing by 2L makes the row a length (≈ |b − a| − L near the solution) for any L, so that one tolerance serves
// links of 1 mm and of 1 km alike. L > 0.
struct DistanceSpec {
  static constexpr int kRows = 1;
  static constexpr const char* kKind = "distance";
  Point2 a, b;
  double length = 1.0;

  bool depends_on_time() const { return false; }
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  double characteristic_length() const { return length; }
  template <class F>
  void for_each_slot(F&& f) const {
    f(a.x, Unit::kLength), f(a.y, Unit::kLength), f(b.x, Unit::kLength), f(b.y, Unit::kLength);
  }
  void residual(const double* q, double, double* phi) const {
    kin::V2 d = kin::pos(b, q) - kin::pos(a, q);
    phi[0] = (kin::dot(d, d) - length * length) / (2.0 * length);
  }
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    kin::V2 d = (1.0 / length) * (kin::pos(b, q) - kin::pos(a, q));
    s(0, a.x, -d.x), s(0, a.y, -d.y), s(0, b.x, d.x), s(0, b.y, d.y);
  }
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  void gamma(const double*, const double* qd, double, double* out) const {
    kin::V2 dd = kin::vel(b, qd) - kin::vel(a, qd);
    out[0] = -kin::dot(dd, dd) / length;
  }
};

// Coincidence of two attachment points ("pin"): a revolute pair between two bodies in reference-point coordinates,
// a body point fixed to ground (one side constant), a fixed point (natural point against a constant), or a body
// pinned to a natural point (mixed). Attachment k is frame_k = (x, y, ψ) plus the local vector s_k:
//   Φ = r_a + R(ψ_a) s_a − r_b − R(ψ_b) s_b            (2 rows, lengths)
// A natural point is a frame with ψ constant and s = 0.
struct PinSpec {
  static constexpr int kRows = 2;
  static constexpr const char* kKind = "pin";
  Frame2 a, b;
  kin::V2 sa{0, 0}, sb{0, 0};

  bool depends_on_time() const { return false; }
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  double characteristic_length() const { return std::max(std::hypot(sa.x, sa.y), std::hypot(sb.x, sb.y)); }
  template <class F>
  void for_each_slot(F&& f) const {
    f(a.x, Unit::kLength), f(a.y, Unit::kLength), f(a.psi, Unit::kAngle);
    f(b.x, Unit::kLength), f(b.y, Unit::kLength), f(b.psi, Unit::kAngle);
  }
  void residual(const double* q, double, double* phi) const {
    kin::V2 pa = kin::V2{a.x.of(q), a.y.of(q)} + kin::rotate(a.psi.of(q), sa);
    kin::V2 pb = kin::V2{b.x.of(q), b.y.of(q)} + kin::rotate(b.psi.of(q), sb);
    phi[0] = pa.x - pb.x;
    phi[1] = pa.y - pb.y;
  }
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    const bool ra = has_arm(a, sa), rb = has_arm(b, sb);
    kin::V2 ja = ra ? kin::perp(kin::rotate(a.psi.of(q), sa)) : kin::V2{0, 0};
    kin::V2 jb = rb ? kin::perp(kin::rotate(b.psi.of(q), sb)) : kin::V2{0, 0};
    s(0, a.x, 1.0), s(0, b.x, -1.0), s(1, a.y, 1.0), s(1, b.y, -1.0);
    if (ra) s(0, a.psi, ja.x), s(1, a.psi, ja.y);
    if (rb) s(0, b.psi, -jb.x), s(1, b.psi, -jb.y);
  }
  void phi_t(const double*, double, double* out) const { out[0] = out[1] = 0.0; }
  void gamma(const double* q, const double* qd, double, double* out) const {
    // d²/dt² R(ψ)s = ψ̈ perp(Rs) − ψ̇² Rs; the ψ̈ part is in Φq q̈.
    double wa = a.psi.rate(qd), wb = b.psi.rate(qd);
    kin::V2 ga = (wa * wa) * kin::rotate(a.psi.of(q), sa);
    kin::V2 gb = (wb * wb) * kin::rotate(b.psi.of(q), sb);
    out[0] = ga.x - gb.x;
    out[1] = ga.y - gb.y;
  }

 private:
  static bool has_arm(const Frame2& f, kin::V2 s) { return f.psi.is_coordinate() && (s.x != 0.0 || s.y != 0.0); }
};

// Prismatic pair between body a and body b (reference-point coordinates). With e = R(ψ_a) u the sliding axis (u a
// unit vector in a's frame), P_a = r_a + R(ψ_a) s_a a point of the line on a and P_b = r_b + R(ψ_b) s_b a point of b:
//   Φ0 = ψ_b − ψ_a − θ0                 (no relative rotation; angle)
//   Φ1 = e × (P_b − P_a)                (P_b stays on the line of a; length since |e| = 1)
struct PrismaticSpec {
  static constexpr int kRows = 2;
  static constexpr const char* kKind = "prismatic";
  Frame2 a, b;
  kin::V2 sa{0, 0}, sb{0, 0};
  kin::V2 axis{1, 0};  // normalised when the model is built
  double angle = 0.0;  // θ0

  bool depends_on_time() const { return false; }
  Unit row_unit(int row, const std::vector<Unit>&) const { return row == 0 ? Unit::kAngle : Unit::kLength; }
  double characteristic_length() const { return std::max(std::hypot(sa.x, sa.y), std::hypot(sb.x, sb.y)); }
  template <class F>
  void for_each_slot(F&& f) const {
    f(a.x, Unit::kLength), f(a.y, Unit::kLength), f(a.psi, Unit::kAngle);
    f(b.x, Unit::kLength), f(b.y, Unit::kLength), f(b.psi, Unit::kAngle);
  }
  void residual(const double* q, double, double* phi) const {
    Geometry g = geometry(q);
    phi[0] = b.psi.of(q) - a.psi.of(q) - angle;
    phi[1] = kin::cross(g.e, g.h);
  }
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    Geometry g = geometry(q);
    s(0, b.psi, 1.0), s(0, a.psi, -1.0);
    s(1, a.x, g.e.y), s(1, a.y, -g.e.x), s(1, b.x, -g.e.y), s(1, b.y, g.e.x);
    // ∂/∂ψa: e turns and P_a moves: −e·(r_b + R_b s_b − r_a); ∂/∂ψb = e·(R_b s_b)
    s(1, a.psi, -kin::dot(g.e, g.h + g.arm_a)), s(1, b.psi, kin::dot(g.e, g.arm_b));
  }
  void phi_t(const double*, double, double* out) const { out[0] = out[1] = 0.0; }
  void gamma(const double* q, const double* qd, double, double* out) const {
    Geometry g = geometry(q);
    double wa = a.psi.rate(qd), wb = b.psi.rate(qd);
    kin::V2 edot = wa * kin::perp(g.e);
    kin::V2 hdot = kin::V2{b.x.rate(qd), b.y.rate(qd)} + wb * kin::perp(g.arm_b) -
                   kin::V2{a.x.rate(qd), a.y.rate(qd)} - wa * kin::perp(g.arm_a);
    // q̈-free parts: ë = −ψ̇a² e, ḧ = −ψ̇b² R_b s_b + ψ̇a² R_a s_a
    kin::V2 hdd = (wa * wa) * g.arm_a - (wb * wb) * g.arm_b;
    double phidd = -wa * wa * kin::cross(g.e, g.h) + 2.0 * kin::cross(edot, hdot) + kin::cross(g.e, hdd);
    out[0] = 0.0;
    out[1] = -phidd;
  }

 private:
  struct Geometry {
    kin::V2 e, arm_a, arm_b, h;
  };
  Geometry geometry(const double* q) const {
    Geometry g;
    double pa = a.psi.of(q), pb = b.psi.of(q);
    g.e = kin::rotate(pa, axis);
    g.arm_a = kin::rotate(pa, sa);
    g.arm_b = kin::rotate(pb, sb);
    g.h = kin::V2{b.x.of(q), b.y.of(q)} + g.arm_b - kin::V2{a.x.of(q), a.y.of(q)} - g.arm_a;
    return g;
  }
};

// Point p on the straight line through a and b (natural coordinates):
//   Φ = ((b − a) × (p − a)) / ref
// ref is |b − a| at the initial placement (set when the model is built), so that the row is the distance of p from
// the line, a length. It scales the row; it does not change the solution.
struct PointOnLineSpec {
  static constexpr int kRows = 1;
  static constexpr const char* kKind = "point_on_line";
  Point2 p, a, b;
  double ref = 1.0;

  bool depends_on_time() const { return false; }
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  double characteristic_length() const { return 0.0; }
  template <class F>
  void for_each_slot(F&& f) const {
    f(p.x, Unit::kLength), f(p.y, Unit::kLength), f(a.x, Unit::kLength), f(a.y, Unit::kLength);
    f(b.x, Unit::kLength), f(b.y, Unit::kLength);
  }
  void residual(const double* q, double, double* phi) const {
    kin::V2 u = kin::pos(b, q) - kin::pos(a, q), w = kin::pos(p, q) - kin::pos(a, q);
    phi[0] = kin::cross(u, w) / ref;
  }
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    kin::V2 u = kin::pos(b, q) - kin::pos(a, q), w = kin::pos(p, q) - kin::pos(a, q);
    const double k = 1.0 / ref;
    // ∂/∂u = (w_y, −w_x), ∂/∂w = (−u_y, u_x); a enters both with a minus sign
    s(0, p.x, -k * u.y), s(0, p.y, k * u.x);
    s(0, b.x, k * w.y), s(0, b.y, -k * w.x);
    s(0, a.x, k * (u.y - w.y)), s(0, a.y, k * (w.x - u.x));
  }
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  void gamma(const double*, const double* qd, double, double* out) const {
    kin::V2 ud = kin::vel(b, qd) - kin::vel(a, qd), wd = kin::vel(p, qd) - kin::vel(a, qd);
    out[0] = -2.0 * kin::cross(ud, wd) / ref;
  }
};

// Constant angle α from segment u = b − a to segment v = d − c (natural coordinates):
//   Φ = (cos α (u × v) − sin α (u · v)) / ref   = |u||v| sin(θ_uv − α) / ref
// ref is |u||v| at the initial placement, so the row is (close to) the angle error in radians. Well conditioned for
// every α (unlike a pure dot or cross form); it is also met at α + π, a branch Newton does not reach from nearby.
struct ConstantAngleSpec {
  static constexpr int kRows = 1;
  static constexpr const char* kKind = "constant_angle";
  Point2 a, b, c, d;
  double angle = 0.0;
  double ref = 1.0;

  bool depends_on_time() const { return false; }
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kAngle; }
  double characteristic_length() const { return 0.0; }
  template <class F>
  void for_each_slot(F&& f) const {
    f(a.x, Unit::kLength), f(a.y, Unit::kLength), f(b.x, Unit::kLength), f(b.y, Unit::kLength);
    f(c.x, Unit::kLength), f(c.y, Unit::kLength), f(d.x, Unit::kLength), f(d.y, Unit::kLength);
  }
  void residual(const double* q, double, double* phi) const {
    kin::V2 u = kin::pos(b, q) - kin::pos(a, q), v = kin::pos(d, q) - kin::pos(c, q);
    phi[0] = (std::cos(angle) * kin::cross(u, v) - std::sin(angle) * kin::dot(u, v)) / ref;
  }
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    kin::V2 u = kin::pos(b, q) - kin::pos(a, q), v = kin::pos(d, q) - kin::pos(c, q);
    const double ca = std::cos(angle) / ref, sa = std::sin(angle) / ref;
    kin::V2 du{ca * v.y - sa * v.x, -ca * v.x - sa * v.y};
    kin::V2 dv{-ca * u.y - sa * u.x, ca * u.x - sa * u.y};
    s(0, a.x, -du.x), s(0, a.y, -du.y), s(0, b.x, du.x), s(0, b.y, du.y);
    s(0, c.x, -dv.x), s(0, c.y, -dv.y), s(0, d.x, dv.x), s(0, d.y, dv.y);
  }
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  void gamma(const double*, const double* qd, double, double* out) const {
    kin::V2 ud = kin::vel(b, qd) - kin::vel(a, qd), vd = kin::vel(d, qd) - kin::vel(c, qd);
    out[0] = -2.0 * (std::cos(angle) * kin::cross(ud, vd) - std::sin(angle) * kin::dot(ud, vd)) / ref;
  }
};

// Angle coordinate θ of segment a → b against the x axis (mixes natural coordinates with an angle, typically to
// drive a natural-coordinate mechanism by a crank angle):
//   Φ = (x_b − x_a) sin θ − (y_b − y_a) cos θ       = |b − a| sin(θ_ab − θ), a length
// Its gradient never vanishes for a segment of non-zero length, unlike a cos/sin pair chosen by quadrant.
struct SegmentAngleSpec {
  static constexpr int kRows = 1;
  static constexpr const char* kKind = "angle";
  Point2 a, b;
  Slot theta;

  bool depends_on_time() const { return false; }
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  double characteristic_length() const { return 0.0; }
  template <class F>
  void for_each_slot(F&& f) const {
    f(a.x, Unit::kLength), f(a.y, Unit::kLength), f(b.x, Unit::kLength), f(b.y, Unit::kLength);
    f(theta, Unit::kAngle);
  }
  void residual(const double* q, double, double* phi) const {
    kin::V2 d = kin::pos(b, q) - kin::pos(a, q);
    double th = theta.of(q);
    phi[0] = d.x * std::sin(th) - d.y * std::cos(th);
  }
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    kin::V2 d = kin::pos(b, q) - kin::pos(a, q);
    double th = theta.of(q), sn = std::sin(th), cs = std::cos(th);
    s(0, a.x, -sn), s(0, a.y, cs), s(0, b.x, sn), s(0, b.y, -cs), s(0, theta, d.x * cs + d.y * sn);
  }
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  void gamma(const double* q, const double* qd, double, double* out) const {
    kin::V2 d = kin::pos(b, q) - kin::pos(a, q), dd = kin::vel(b, qd) - kin::vel(a, qd);
    double th = theta.of(q), w = theta.rate(qd), sn = std::sin(th), cs = std::cos(th);
    out[0] = -2.0 * w * (dd.x * cs + dd.y * sn) + w * w * (d.x * sn - d.y * cs);
  }
};

// Point p at distance L from o in direction θ (mixed coordinates; the notes' crank  x_A − L2 cos θ2 = 0,
// y_A − L2 sin θ2 = 0 with o the origin):
//   Φ = p − o − L (cos θ, sin θ)                         (2 rows, lengths)
struct PolarSpec {
  static constexpr int kRows = 2;
  static constexpr const char* kKind = "polar";
  Point2 p, o;
  double length = 1.0;
  Slot theta;

  bool depends_on_time() const { return false; }
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  double characteristic_length() const { return std::fabs(length); }
  template <class F>
  void for_each_slot(F&& f) const {
    f(p.x, Unit::kLength), f(p.y, Unit::kLength), f(o.x, Unit::kLength), f(o.y, Unit::kLength);
    f(theta, Unit::kAngle);
  }
  void residual(const double* q, double, double* phi) const {
    double th = theta.of(q);
    phi[0] = p.x.of(q) - o.x.of(q) - length * std::cos(th);
    phi[1] = p.y.of(q) - o.y.of(q) - length * std::sin(th);
  }
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    double th = theta.of(q);
    s(0, p.x, 1.0), s(0, o.x, -1.0), s(0, theta, length * std::sin(th));
    s(1, p.y, 1.0), s(1, o.y, -1.0), s(1, theta, -length * std::cos(th));
  }
  void phi_t(const double*, double, double* out) const { out[0] = out[1] = 0.0; }
  void gamma(const double* q, const double* qd, double, double* out) const {
    double th = theta.of(q), w = theta.rate(qd);
    out[0] = -length * w * w * std::cos(th);
    out[1] = -length * w * w * std::sin(th);
  }
};

// Loop closure in relative coordinates: the links of a kinematic loop, each a vector of length ℓ_k (a constant or
// a coordinate, e.g. a slider travel) at angle θ_k = offset_k + Σ_j sign_kj q_j (absolute angles, or the running
// sums of relative joint angles as in the notes: ψ2, ψ2 + ψ3, ψ2 + ψ3 + ψ4), add up to the constant closure vector c:
//   Φ = Σ_k ℓ_k (cos θ_k, sin θ_k) − c                  (2 rows, lengths)
struct LoopSpec {
  static constexpr int kRows = 2;
  static constexpr const char* kKind = "loop";
  struct Term {
    Slot angle;
    double sign = 1.0;
  };
  struct Link {
    Slot length;
    double offset = 0.0;
    std::vector<Term> terms;
  };
  std::vector<Link> links;
  kin::V2 closure{0, 0};

  bool depends_on_time() const { return false; }
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  double characteristic_length() const {
    double l = std::hypot(closure.x, closure.y);
    for (const Link& k : links)
      if (!k.length.is_coordinate()) l = std::max(l, std::fabs(k.length.value));
    return l;
  }
  template <class F>
  void for_each_slot(F&& f) const {
    for (const Link& k : links) {
      f(k.length, Unit::kLength);
      for (const Term& t : k.terms) f(t.angle, Unit::kAngle);
    }
  }
  double angle_of(const Link& k, const double* q) const {
    double th = k.offset;
    for (const Term& t : k.terms) th += t.sign * t.angle.of(q);
    return th;
  }
  double rate_of(const Link& k, const double* qd) const {
    double w = 0.0;
    for (const Term& t : k.terms) w += t.sign * t.angle.rate(qd);
    return w;
  }
  void residual(const double* q, double, double* phi) const {
    double sx = -closure.x, sy = -closure.y;
    for (const Link& k : links) {
      double th = angle_of(k, q), l = k.length.of(q);
      sx += l * std::cos(th);
      sy += l * std::sin(th);
    }
    phi[0] = sx;
    phi[1] = sy;
  }
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    for (const Link& k : links) {
      double th = angle_of(k, q), l = k.length.of(q), cs = std::cos(th), sn = std::sin(th);
      s(0, k.length, cs), s(1, k.length, sn);
      for (const Term& t : k.terms) s(0, t.angle, -t.sign * l * sn), s(1, t.angle, t.sign * l * cs);
    }
  }
  void phi_t(const double*, double, double* out) const { out[0] = out[1] = 0.0; }
  void gamma(const double* q, const double* qd, double, double* out) const {
    // Φ̈ = Σ ℓ̈ e + (ℓ θ̈ + 2 ℓ̇ θ̇) perp(e) − ℓ θ̇² e  ⇒  γ = Σ ℓ θ̇² e − 2 ℓ̇ θ̇ perp(e)
    double gx = 0.0, gy = 0.0;
    for (const Link& k : links) {
      double th = angle_of(k, q), w = rate_of(k, qd), l = k.length.of(q), ld = k.length.rate(qd);
      double cs = std::cos(th), sn = std::sin(th);
      gx += l * w * w * cs + 2.0 * ld * w * sn;
      gy += l * w * w * sn - 2.0 * ld * w * cs;
    }
    out[0] = gx;
    out[1] = gy;
  }
};

// Rheonomic driver on one coordinate (a motor):
//   Φ = q_j − f(t),   Φt = −f'(t),   γ = f''(t)       (0 for a linear law: the notes' erratum)
struct CoordinateDriverSpec {
  static constexpr int kRows = 1;
  static constexpr const char* kKind = "driver";
  Slot coordinate;
  MotionLaw law;

  bool depends_on_time() const { return true; }
  Unit row_unit(int, const std::vector<Unit>& coordinate_units) const {
    return coordinate.is_coordinate() ? coordinate_units[coordinate.coord] : Unit::kNone;
  }
  double characteristic_length() const { return 0.0; }
  template <class F>
  void for_each_slot(F&& f) const {
    f(coordinate, Unit::kNone);
  }
  void residual(const double* q, double t, double* phi) const { phi[0] = coordinate.of(q) - law.evaluate(t).f; }
  template <class Sink>
  void jacobian(const double*, double, Sink& s) const {
    s(0, coordinate, 1.0);
  }
  void phi_t(const double*, double t, double* out) const { out[0] = -law.evaluate(t).df; }
  void gamma(const double*, const double*, double t, double* out) const { out[0] = law.evaluate(t).ddf; }
};

// General equation written as text, optionally driven by a motion law:
//   Φ = g(q, t) − f(t)            (f ≡ 0 without a law)
// with Φq, Φt and γ derived exactly from g (expression.hpp). `unit` says what g measures (for tolerances).
struct EquationSpec {
  static constexpr int kRows = 1;
  static constexpr const char* kKind = "equation";
  std::shared_ptr<const CompiledExpression> g;
  std::optional<MotionLaw> law;
  Unit unit = Unit::kNone;

  bool depends_on_time() const { return law.has_value() || g->depends_on_time(); }
  Unit row_unit(int, const std::vector<Unit>&) const { return unit; }
  double characteristic_length() const { return 0.0; }
  template <class F>
  void for_each_slot(F&& f) const {
    for (Index i : g->coordinates()) f(Slot::coordinate(i), Unit::kNone);
  }
  void residual(const double* q, double t, double* phi) const {
    phi[0] = g->value(q, t) - (law ? law->evaluate(t).f : 0.0);
  }
  template <class Sink>
  void jacobian(const double* q, double t, Sink& s) const {
    thread_local std::vector<double> grad;
    const auto& cols = g->coordinates();
    grad.resize(cols.size());
    g->gradient(q, t, grad.data());
    for (std::size_t k = 0; k < cols.size(); ++k) s(0, Slot::coordinate(cols[k]), grad[k]);
  }
  void phi_t(const double* q, double t, double* out) const {
    out[0] = (g->depends_on_time() ? g->partial_t(q, t) : 0.0) - (law ? law->evaluate(t).df : 0.0);
  }
  void gamma(const double* q, const double* qd, double t, double* out) const {
    out[0] = g->gamma(q, qd, t) + (law ? law->evaluate(t).ddf : 0.0);
  }
};

}  // namespace phiq
