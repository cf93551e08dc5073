/// @file
/// Points and vectors that move with the coordinates of a spatial model: the one building block of every 3D
/// constraint kind (constraint_kinds_3d.hpp).
///
/// An attachment is X = r + R(p) s: r three slots (a body's reference point, a natural point or a natural unit
/// vector, or constants), p four slots (a body's Euler parameters, or constants) and s a constant local vector (a
/// point or an axis fixed in the body; 0 for a natural point or vector). R(p) is written as the homogeneous
/// quadratic form of the Euler parameters
///
///     R(p) s = (p0² − e·e) s + 2 (e·s) e + 2 p0 (e × s),    e = (p1, p2, p3),
///
/// which is the rotation matrix (2p0² − 1) I + 2 (e eᵀ + p0 ẽ) of the notes wherever p·p = 1 (the body's own
/// normalisation constraint holds at every solution). Being a quadratic form, R(p) s = B(p, p, s) with B the
/// symmetric bilinear form below, and so exactly
///
///     ∂(R s)/∂p_k = 2 B(p, e_k, s),   d/dt (R s) = 2 B(p, ṗ, s),   d²/dt² (R s) = 2 B(p, p̈, s) + 2 R(ṗ) s,
///
/// so the q̈-free part of the acceleration of an attachment (what γ needs) is 2 R(ṗ) s. No trigonometry, no
/// special case at any orientation, and the same formulas for ground (constant p) and natural coordinates (s = 0).
#pragma once

#include <array>
#include <cmath>

#include "phiq/types.hpp"

namespace phiq {

namespace kin3 {
/// A plain 3-vector (metres for points, unitless for directions).
struct V3 {
  double x = 0.0, y = 0.0, z = 0.0;
  bool operator==(const V3&) const = default;  ///< component by component
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator-(V3 a) { return {-a.x, -a.y, -a.z}; }
inline V3 operator*(double k, V3 a) { return {k * a.x, k * a.y, k * a.z}; }
inline double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline double norm(V3 a) { return std::sqrt(dot(a, a)); }
inline bool is_zero(V3 a) { return a.x == 0.0 && a.y == 0.0 && a.z == 0.0; }
/// Component k (0: x, 1: y, 2: z).
inline double component(V3 a, int k) { return k == 0 ? a.x : (k == 1 ? a.y : a.z); }
/// The unit vector along axis k (0: x, 1: y, 2: z).
inline V3 unit_axis(int k) { return {k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0}; }
/// A unit vector perpendicular to unit vector `u`: the coordinate axis least along u (x, then y, on a tie), made
/// perpendicular to it (that axis is at least 54.7° from u, so the result is always well defined).
inline V3 perpendicular_unit(V3 u) {
  const double ax = std::fabs(u.x), ay = std::fabs(u.y), az = std::fabs(u.z);
  const V3 axis = unit_axis(ax <= ay && ax <= az ? 0 : (ay <= az ? 1 : 2));
  const V3 p = axis - dot(axis, u) * u;
  return (1.0 / norm(p)) * p;
}

/// B(p, r, s), the symmetric bilinear form in the Euler parameters p, r with B(p, p, s) = R(p) s (file comment).
inline V3 bilinear(const double p[4], const double r[4], V3 s) {
  const V3 ep{p[1], p[2], p[3]}, er{r[1], r[2], r[3]};
  return (p[0] * r[0] - dot(ep, er)) * s + dot(er, s) * ep + dot(ep, s) * er + p[0] * cross(er, s) +
         r[0] * cross(ep, s);
}
/// R(p) s (file comment): a rotation of s wherever p·p = 1.
inline V3 rotate(const double p[4], V3 s) { return bilinear(p, p, s); }
}  // namespace kin3

/// A point or a vector that moves with the coordinates: X = r + R(p) s (file comment). Built by the factories
/// below; ground and fixed points are attachments of constants.
struct Attachment3 {
  bool operator==(const Attachment3&) const = default;                    ///< slot by slot, and the local vector
  Slot r[3] = {Slot::constant(0), Slot::constant(0), Slot::constant(0)};  ///< translation part (m, or a vector)
  Slot p[4] = {Slot::constant(1), Slot::constant(0), Slot::constant(0), Slot::constant(0)};  ///< Euler parameters
  kin3::V3 s;  ///< the local vector rotated by R(p): a point or an axis fixed in the body

  /// The point `at` fixed in body `f` (`at` in the body's frame, metres): r + R(p) at.
  static Attachment3 body_point(const Frame3& f, kin3::V3 at) {
    return Attachment3{{f.x, f.y, f.z}, {f.e0, f.e1, f.e2, f.e3}, at};
  }
  /// The direction `u` fixed in body `f` (in the body's frame): R(p) u.
  static Attachment3 body_vector(const Frame3& f, kin3::V3 u) {
    Attachment3 a;
    a.p[0] = f.e0, a.p[1] = f.e1, a.p[2] = f.e2, a.p[3] = f.e3, a.s = u;
    return a;
  }
  /// A natural point, or a natural unit vector (its three slots).
  static Attachment3 natural(const Point3& v) {
    Attachment3 a;
    a.r[0] = v.x, a.r[1] = v.y, a.r[2] = v.z;
    return a;
  }
  /// The origin (nothing moves): used for the missing end of a vector term.
  static Attachment3 zero() { return Attachment3{}; }

  /// Whether R(p) s varies: s ≠ 0 (decided by the data, so the Jacobian's entry set never depends on values).
  bool rotates() const { return !kin3::is_zero(s); }
  /// When r and p are all constants (a ground or fixed-frame attachment), X is a constant: stores it in r and sets
  /// s = 0, so that every evaluation reads three constants instead of rotating s (on a natural-coordinate chain
  /// the ground's points and axes are most of the rotations). The value is the one value() computed, to the last
  /// bit, and no Jacobian entry changes (constants have none). The setup of the spatial kinds calls it.
  void fold_constant() {
    if (!rotates()) return;
    for (const Slot& k : r)
      if (k.is_coordinate()) return;
    for (const Slot& k : p)
      if (k.is_coordinate()) return;
    const kin3::V3 x = value(nullptr);  // constants only: q is not read
    *this = Attachment3{};
    r[0] = Slot::constant(x.x), r[1] = Slot::constant(x.y), r[2] = Slot::constant(x.z);
  }
  /// X at q.
  kin3::V3 value(const double* q) const {
    kin3::V3 x{r[0].of(q), r[1].of(q), r[2].of(q)};
    return rotates() ? x + rotated(q) : x;  // natural points and folded constants: three reads, inlined
  }
  /// Ẋ = ṙ + 2 B(p, ṗ, s).
  kin3::V3 rate(const double* q, const double* qd) const {
    kin3::V3 v{r[0].rate(qd), r[1].rate(qd), r[2].rate(qd)};
    return rotates() ? v + rotated_rate(q, qd) : v;
  }
  /// R(p) s at q (kept out of the callers: only moving frames need it).
  [[gnu::noinline]] kin3::V3 rotated(const double* q) const { return kin3::rotate(euler(q).data(), s); }
  /// 2 B(p, ṗ, s) at (q, q̇).
  [[gnu::noinline]] kin3::V3 rotated_rate(const double* q, const double* qd) const {
    return 2.0 * kin3::bilinear(euler(q).data(), euler_rates(qd).data(), s);
  }
  /// The part of Ẍ that does not contain q̈: 2 R(ṗ) s.
  kin3::V3 bias(const double* qd) const {
    if (!rotates()) return {};
    return 2.0 * kin3::rotate(euler_rates(qd).data(), s);
  }
  /// Emits the entries of ∂(w · X)/∂q at q for row `row`, with w held fixed: w_k on r_k (only on r_only when
  /// `only` ≥ 0: the other components of w are structurally zero), then 2 w · B(p, e_k, s) on p_k when s ≠ 0.
  /// The set and order of entries depend only on the data and `only`, never on q.
  template <class Sink>
  void emit(Sink& sink, int row, kin3::V3 w, const double* q, int only = -1) const {
    if (only >= 0) {
      sink(row, r[only], kin3::component(w, only));
    } else {
      sink(row, r[0], w.x), sink(row, r[1], w.y), sink(row, r[2], w.z);
    }
    if (!rotates()) return;
    const std::array<double, 4> e = euler(q);
    const kin3::V3 ep{e[1], e[2], e[3]};
    const double ws = kin3::dot(w, s), we = kin3::dot(w, ep), es = kin3::dot(ep, s);
    const kin3::V3 sw = kin3::cross(s, w);
    // 2 w · B(p, e_k, s): k = 0 gives p0 s + e × s; k ≥ 1 gives −p_k s + s_k e + (e·s) ê_k + p0 (ê_k × s)
    sink(row, p[0], 2.0 * (e[0] * ws + kin3::dot(w, kin3::cross(ep, s))));
    sink(row, p[1], 2.0 * (-e[1] * ws + s.x * we + es * w.x + e[0] * sw.x));
    sink(row, p[2], 2.0 * (-e[2] * ws + s.y * we + es * w.y + e[0] * sw.y));
    sink(row, p[3], 2.0 * (-e[3] * ws + s.z * we + es * w.z + e[0] * sw.z));
  }
  /// The Euler parameters p at q.
  std::array<double, 4> euler(const double* q) const { return {p[0].of(q), p[1].of(q), p[2].of(q), p[3].of(q)}; }
  /// Their rates ṗ at q̇.
  std::array<double, 4> euler_rates(const double* qd) const {
    return {p[0].rate(qd), p[1].rate(qd), p[2].rate(qd), p[3].rate(qd)};
  }
  /// Calls f(slot, unit) for the slots X reads: r as `r_unit` (a length for points, none for vectors), p as
  /// Unit::kNone (Euler parameters are unitless).
  template <class F>
  void for_each_slot(F&& f, Unit r_unit) const {
    f(r[0], r_unit), f(r[1], r_unit), f(r[2], r_unit);
    if (rotates()) f(p[0], Unit::kNone), f(p[1], Unit::kNone), f(p[2], Unit::kNone), f(p[3], Unit::kNone);
  }
};

}  // namespace phiq
