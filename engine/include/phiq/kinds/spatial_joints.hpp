/// @file
/// The spatial joints (spherical, revolute, prismatic, cylindrical, universal, planar, rigid, point on line, point
/// on plane): a family of kinds, one row table each, evaluated by one set of formulas; each with its equation,
/// derivatives, validation, joint count, sketch and scene form. The contract is documented on DistanceSpec, and
/// kinds/registry.hpp lists every kind.
///
/// Every joint is written with one device: each row is w (X · Y − c), X and Y sums of attachments
/// (spatial_attachment.hpp: X = r + R(p) s) or a constant unit axis. So the Jacobian, Φt and γ of every joint come
/// from one set of formulas (detail3 below):
///
///     Φ̇ = w (Ẋ · Y + X · Ẏ),     γ = −w (a_X · Y + 2 Ẋ · Ẏ + X · a_Y)      (a = the q̈-free part of the acceleration)
///
/// A joint joins two sides (JointSide3): a body with a local point `at`, a local axis z and a local reference
/// direction x ⟂ z (y = z × x completes the joint frame); or ground; or a natural point, with a natural unit vector
/// as its axis. Rows that need x or y of a side (the alignment of two axes, the lock of a rotation) need a body or
/// ground on that side: a natural vector fixes no perpendicular direction.
///
/// Rows are lengths (point gaps, offsets of a point from a line or a plane) or angles (x_a · z_b ≈ the
/// misalignment of two axes, in radians), so that one tolerance serves any size of mechanism (models/README.md).
#pragma once

#include <cmath>
#include <array>
#include <tuple>
#include <cstdint>
#include <optional>
#include <string_view>

#include "phiq/spatial_attachment.hpp"
#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// One side of a spatial joint, as given: a body (or ground) with a local point and a local axis and reference
/// direction, or a natural point with an optional natural unit vector. Build it with the factories.
struct JointSide3 {
  bool operator==(const JointSide3&) const = default;  ///< datum by datum
  Frame3 frame = Frame3::ground();  ///< the body; for a natural point, x, y, z are the point and p is constant
  kin3::V3 at;                      ///< the joint point in the body's frame (m); 0 for a natural point
  kin3::V3 axis{0, 0, 1};           ///< the joint axis z in the body's frame (normalised by setup)
  std::optional<kin3::V3> ref;      ///< the reference direction x in the body's frame (its part ⟂ z is used);
                                    ///< default: x, or y when the axis is within 25° of x
  bool natural = false;             ///< a natural point (and vector): no perpendicular directions
  std::optional<Point3> vector;     ///< a natural side's axis: a natural unit vector

  /// A body side.
  static JointSide3 body(const Frame3& f, kin3::V3 at, kin3::V3 axis = {0, 0, 1},
                         std::optional<kin3::V3> ref = std::nullopt) {
    JointSide3 s;
    s.frame = f, s.at = at, s.axis = axis, s.ref = ref;
    return s;
  }
  /// A natural point, with an optional natural unit vector as axis.
  static JointSide3 natural_point(const Point3& p, std::optional<Point3> vector = std::nullopt) {
    JointSide3 s;
    s.frame = Frame3{p.x, p.y, p.z, Slot::constant(1), Slot::constant(0), Slot::constant(0), Slot::constant(0)};
    s.natural = true, s.vector = vector;
    return s;
  }
};

namespace detail3 {
/// Indices of the attachments of a joint (SpatialJointSpec::att): the two points, then the joint frames' x, y, z.
enum Attach : std::int8_t { kPa = 0, kPb, kXa, kYa, kZa, kXb, kYb, kZb, kCount };
/// A vector term of a row: att[plus] − att[minus] (either may be absent, −1), or the constant unit axis `axis`.
struct Term {
  std::int8_t plus = -1, minus = -1, axis = -1;
};
constexpr Term T(int plus, int minus = -1) {
  return Term{static_cast<std::int8_t>(plus), static_cast<std::int8_t>(minus), -1};
}
constexpr Term Axis(int k) { return Term{-1, -1, static_cast<std::int8_t>(k)}; }
/// A row w (X · Y − c) and the unit of its residual.
struct RowDef {
  Term x, y;
  Unit unit;
};

inline kin3::V3 value(const Attachment3* a, Term t, const double* q) {
  if (t.axis >= 0) return kin3::unit_axis(t.axis);
  kin3::V3 v;
  if (t.plus >= 0) v = a[t.plus].value(q);
  if (t.minus >= 0) v = v - a[t.minus].value(q);
  return v;
}
inline kin3::V3 rate(const Attachment3* a, Term t, const double* q, const double* qd) {
  kin3::V3 v;
  if (t.plus >= 0) v = a[t.plus].rate(q, qd);
  if (t.minus >= 0) v = v - a[t.minus].rate(q, qd);
  return v;
}
inline kin3::V3 bias(const Attachment3* a, Term t, const double* qd) {
  kin3::V3 v;
  if (t.plus >= 0) v = a[t.plus].bias(qd);
  if (t.minus >= 0) v = v - a[t.minus].bias(qd);
  return v;
}
/// Entries of ∂(w · term)/∂q; `only` as in Attachment3::emit.
template <class Sink>
void emit(const Attachment3* a, Term t, Sink& s, int row, kin3::V3 w, const double* q, int only) {
  if (t.plus >= 0) a[t.plus].emit(s, row, w, q, only);
  if (t.minus >= 0) a[t.minus].emit(s, row, -w, q, only);
}
/// w (X · Y − c)
inline double row_value(const Attachment3* a, const RowDef& d, const double* q, double w, double c) {
  return w * (kin3::dot(value(a, d.x, q), value(a, d.y, q)) - c);
}
/// Entries of w ∂(X · Y)/∂q: X's with weight w Y, then Y's with weight w X. A constant axis on one side makes all
/// but one r-component of the other's weight zero: only that one is emitted.
template <class Sink>
void row_jacobian(const Attachment3* a, const RowDef& d, const double* q, Sink& s, int row, double w) {
  const kin3::V3 x = value(a, d.x, q), y = value(a, d.y, q);
  emit(a, d.x, s, row, w * y, q, d.y.axis);
  emit(a, d.y, s, row, w * x, q, d.x.axis);
}
/// Ẋ · Y + X · Ẏ (times w)
inline double row_rate(const Attachment3* a, const RowDef& d, const double* q, const double* qd, double w) {
  return w * (kin3::dot(rate(a, d.x, q, qd), value(a, d.y, q)) + kin3::dot(value(a, d.x, q), rate(a, d.y, q, qd)));
}
/// −w (a_X · Y + 2 Ẋ · Ẏ + X · a_Y)
inline double row_gamma(const Attachment3* a, const RowDef& d, const double* q, const double* qd, double w) {
  const kin3::V3 x = value(a, d.x, q), y = value(a, d.y, q);
  return -w * (kin3::dot(bias(a, d.x, qd), y) + 2.0 * kin3::dot(rate(a, d.x, q, qd), rate(a, d.y, q, qd)) +
               kin3::dot(x, bias(a, d.y, qd)));
}

/// An attachment's X and time derivatives Ẋ, Ẍ (up to `order`, into x), and their derivatives along the data's
/// rates `r` (an Attachment3 of the rates: r̂ and p̂ constants, read only where a's slot is a constant, and ŝ; into
/// xh). X = r + B(p, p, s) is quadratic in p and linear in s (file comment of spatial_attachment.hpp), so exactly
///   X̂ = r̂ + 2 B(p, p̂, s) + B(p, p, ŝ),   ∂Ẋ = 2 B(p̂, ṗ, s) + 2 B(p, ṗ, ŝ),
///   ∂Ẍ = 2 B(p̂, p̈, s) + 2 B(p, p̈, ŝ) + 2 B(ṗ, ṗ, ŝ).
inline void attachment_data_derivatives(const Attachment3& a, const Attachment3& r, int order, const double* q,
                                        const double* qd, const double* qdd, kin3::V3 x[3], kin3::V3 xh[3]) {
  // a coordinate slot is no datum: its rate is 0 whatever `r` holds there
  auto rate_of = [&](const Slot& at, const Slot& rate) { return at.is_coordinate() ? 0.0 : rate.of(q); };
  x[0] = a.value(q);
  xh[0] = kin3::V3{rate_of(a.r[0], r.r[0]), rate_of(a.r[1], r.r[1]), rate_of(a.r[2], r.r[2])};
  if (order >= 1) x[1] = a.rate(q, qd), xh[1] = kin3::V3{};
  if (order == 2) x[2] = a.rate(q, qdd) + a.bias(qd), xh[2] = kin3::V3{};
  // the rotations only where something turns: most attachments (natural points, folded ground places, a body's
  // point a parameter does not move) have neither a local vector that moves nor a constant frame that turns
  const bool arm_moves = !kin3::is_zero(r.s);
  std::array<double, 4> ph{};
  bool frame_turns = false;
  if (a.rotates())
    for (int k = 0; k < 4; ++k) frame_turns = (ph[k] = rate_of(a.p[k], r.p[k])) != 0.0 || frame_turns;
  if (!arm_moves && !frame_turns) return;
  const std::array<double, 4> p = a.euler(q);
  if (frame_turns) xh[0] = xh[0] + 2.0 * kin3::bilinear(p.data(), ph.data(), a.s);
  if (arm_moves) xh[0] = xh[0] + kin3::rotate(p.data(), r.s);
  if (order == 0) return;
  const std::array<double, 4> pd = a.euler_rates(qd);
  if (frame_turns) xh[1] = xh[1] + 2.0 * kin3::bilinear(ph.data(), pd.data(), a.s);
  if (arm_moves) xh[1] = xh[1] + 2.0 * kin3::bilinear(p.data(), pd.data(), r.s);
  if (order == 1) return;
  const std::array<double, 4> pdd = a.euler_rates(qdd);
  if (frame_turns) xh[2] = xh[2] + 2.0 * kin3::bilinear(ph.data(), pdd.data(), a.s);
  if (arm_moves)
    xh[2] = xh[2] + 2.0 * (kin3::bilinear(p.data(), pdd.data(), r.s) + kin3::bilinear(pd.data(), pd.data(), r.s));
}
/// The same for a term (att[plus] − att[minus], or a constant axis: no motion, no data), `r` the rates of `a`.
inline void term_data_derivatives(const Attachment3* a, const Attachment3* r, Term t, int order, const double* q,
                                  const double* qd, const double* qdd, kin3::V3 x[3], kin3::V3 xh[3]) {
  for (int k = 0; k < 3; ++k) x[k] = xh[k] = kin3::V3{};
  if (t.axis >= 0) {
    x[0] = kin3::unit_axis(t.axis);
    return;
  }
  kin3::V3 y[3], yh[3];
  for (const auto& [index, sign] : {std::pair{t.plus, 1.0}, std::pair{t.minus, -1.0}}) {
    if (index < 0) continue;
    attachment_data_derivatives(a[index], r[index], order, q, qd, qdd, y, yh);
    for (int k = 0; k <= order; ++k) x[k] = x[k] + sign * y[k], xh[k] = xh[k] + sign * yh[k];
  }
}
/// The derivative of X · Y's `order`-th time derivative along the data (`r`: the rates of `a`), at fixed q, q̇, q̈:
/// Σ_i C(k, i) (X̂⁽ⁱ⁾ · Y⁽ᵏ⁻ⁱ⁾ + X⁽ⁱ⁾ · Ŷ⁽ᵏ⁻ⁱ⁾). For a row w (X · Y − c) with w and c fixed, w times it is
/// ∂Φ/∂p, ∂(Φq q̇)/∂p or ∂(Φq q̈ − γ)/∂p (the row's Ẍ · Y + 2 Ẋ · Ẏ + X · Ÿ is Φq q̈ − γ).
inline double row_data_derivative(const Attachment3* a, const Attachment3* r, const RowDef& d, int order,
                                  const double* q, const double* qd, const double* qdd) {
  kin3::V3 x[3], xh[3], y[3], yh[3];
  term_data_derivatives(a, r, d.x, order, q, qd, qdd, x, xh);
  term_data_derivatives(a, r, d.y, order, q, qd, qdd, y, yh);
  static constexpr double kBinomial[3][3] = {{1, 0, 0}, {1, 1, 0}, {1, 2, 1}};
  double sum = 0.0;
  for (int i = 0; i <= order; ++i)
    sum += kBinomial[order][i] * (kin3::dot(xh[i], y[order - i]) + kin3::dot(x[i], yh[order - i]));
  return sum;
}

/// The `order`-th time derivative of a row's X · Y at (q, q̇, q̈): X · Y, Ẋ · Y + X · Ẏ, or Φq q̈ − γ of the row.
inline double row_time_derivative(const Attachment3* a, const RowDef& d, int order, const double* q, const double* qd,
                                  const double* qdd) {
  if (order == 0) return row_value(a, d, q, 1.0, 0.0);
  if (order == 1) return row_rate(a, d, q, qd, 1.0);
  return row_rate(a, d, q, qdd, 1.0) - row_gamma(a, d, q, qd, 1.0);
}

/// The attachments a joint's rows read, in the order of their indices (`index[i]`: the Attach index of the i-th),
/// and the rows with their terms renumbered into that list: a joint stores only those (a point on a plane reads 3
/// of the 8), since every evaluation streams them.
template <int kRows>
struct CompactRows {
  int count = 0;
  std::int8_t index[kCount] = {};
  RowDef rows[kRows] = {};
};
template <int kRows>
constexpr CompactRows<kRows> compact_rows(const RowDef (&defs)[kRows]) {
  bool used[kCount] = {};
  for (const RowDef& d : defs)
    for (const Term& t : {d.x, d.y}) {
      if (t.plus >= 0) used[t.plus] = true;
      if (t.minus >= 0) used[t.minus] = true;
    }
  CompactRows<kRows> c;
  std::int8_t position[kCount] = {};
  for (int k = 0; k < kCount; ++k)
    if (used[k]) position[k] = static_cast<std::int8_t>(c.count), c.index[c.count++] = static_cast<std::int8_t>(k);
  auto renumber = [&](Term t) {
    if (t.plus >= 0) t.plus = position[t.plus];
    if (t.minus >= 0) t.minus = position[t.minus];
    return t;
  };
  for (int r = 0; r < kRows; ++r) c.rows[r] = RowDef{renumber(defs[r].x), renumber(defs[r].y), defs[r].unit};
  return c;
}

/// The reference direction of a body side, in its body's frame, from which a joint angle is measured: `s.ref` when
/// the scene states it, else x, or y when the axis lies within 25° of x (so that its part perpendicular to the axis
/// is well defined). phiq check reports which one each joint angle driver uses (Scene::joint_angles).
kin3::V3 reference_direction(const JointSide3& s);

/// The attachments of a joint between sides a and b that `index[0 … count − 1]` name (Attach indices, ascending:
/// CompactRows::index), in that order in the first `count` entries; an attachment of constants only is folded
/// into its value (Attachment3::fold_constant). Normalises the axes, makes the reference directions perpendicular.
/// Throws phiq::Error (naming `kind`) for a zero or non-finite axis, a reference along the axis, non-finite
/// points, and rows that need the perpendicular directions of a natural side or the axis of a natural point without
/// a vector.
std::array<Attachment3, kCount> joint_attachments(const JointSide3& a, const JointSide3& b, const std::int8_t* index,
                                                  int count, const char* kind);
/// Validates the sides and fills `att` with the attachments the rows of `c` read: the setup() of every joint and
/// joint driver (`att` has c.count entries).
template <int kRows, std::size_t N>
void set_up_attachments(const JointSide3& a, const JointSide3& b, const CompactRows<kRows>& c, const char* kind,
                        std::array<Attachment3, N>& att) {
  const std::array<Attachment3, kCount> all = joint_attachments(a, b, c.index, c.count, kind);
  std::copy_n(all.begin(), N, att.begin());
}
/// The longer arm |at| of the sides whose body moves (the characteristic length of a joint; see PinSpec).
inline double joint_arm(const JointSide3& a, const JointSide3& b) {
  const double la = a.frame.is_fixed() ? 0.0 : kin3::norm(a.at), lb = b.frame.is_fixed() ? 0.0 : kin3::norm(b.at);
  return std::max(la, lb);
}
/// The angle θ of a direction about an axis, from its two products c (with the reference direction x) and s (with
/// y = z × x): θ = atan2(s, c) wherever ρ = c² + s² > 0. What the joint angle driver, the screw joint and the spatial
/// mixed angles share. dθ = (c ds − s dc)/ρ, and θ̈ = (c s̈ − s c̈)/ρ − (c ṡ − s ċ) ρ̇/ρ², ρ̇ = 2 (c ċ + s ṡ).
struct AngleRows {
  RowDef c, s;  ///< the rows of c and s (w = 1)

  /// (c, s) at q.
  std::array<double, 2> products(const Attachment3* a, const double* q) const {
    return {row_value(a, c, q, 1.0, 0.0), row_value(a, s, q, 1.0, 0.0)};
  }
  /// θ − f wrapped to (−π, π]: the angle of (c, s) turned back by f, atan2(s cos f − c sin f, c cos f + s sin f),
  /// smooth at any θ (a row through any number of turns, where atan2(s, c) − f would jump by 2π).
  double minus(const Attachment3* a, const double* q, double f) const {
    const auto [cv, sv] = products(a, q);
    const double cf = std::cos(f), sf = std::sin(f);
    return std::atan2(sv * cf - cv * sf, cv * cf + sv * sf);
  }
  /// Emits the entries of k · ∂θ/∂q in `row`: ∂c scaled by −k s/ρ, then ∂s by k c/ρ (a slot in both adds up).
  template <class Sink>
  void emit(const Attachment3* a, const double* q, Sink& sink, int row, double k = 1.0) const {
    const auto [cv, sv] = products(a, q);
    const double rho = cv * cv + sv * sv;
    row_jacobian(a, c, q, sink, row, -k * sv / rho);
    row_jacobian(a, s, q, sink, row, k * cv / rho);
  }
  /// The part of θ̈ without q̈ (γ of a row θ − f is f̈'s part minus this).
  double bias(const Attachment3* a, const double* q, const double* qd) const {
    const auto [cv, sv] = products(a, q);
    const double cd = row_rate(a, c, q, qd, 1.0), sd = row_rate(a, s, q, qd, 1.0);
    // row_gamma is −(the q̈-free part of the second derivative)
    const double cb = -row_gamma(a, c, q, qd, 1.0), sb = -row_gamma(a, s, q, qd, 1.0);
    const double rho = cv * cv + sv * sv, rhod = 2.0 * (cv * cd + sv * sd);
    return (cv * sb - sv * cb) / rho - (cv * sd - sv * cd) * rhod / (rho * rho);
  }
  /// The derivative of θ (`order` 0), θ̇ (1) or θ̈ (2) along the attachments' data (`r`: the rates of `a`), at fixed
  /// q, q̇, q̈: with c⁽ᵏ⁾, s⁽ᵏ⁾ the products' time derivatives and ĉ⁽ᵏ⁾, ŝ⁽ᵏ⁾ theirs along the data
  /// (row_data_derivative()), ρ = c² + s², N1 = c ṡ − s ċ, N2 = c s̈ − s c̈, θ̇ = N1/ρ, θ̈ = N2/ρ − N1 ρ̇/ρ², each
  /// differentiated by the product and quotient rules.
  double data_derivative(const Attachment3* a, const Attachment3* r, int order, const double* q, const double* qd,
                         const double* qdd) const {
    const double cv = row_value(a, c, q, 1.0, 0.0), sv = row_value(a, s, q, 1.0, 0.0);
    const double ch = row_data_derivative(a, r, c, 0, q, qd, qdd), sh = row_data_derivative(a, r, s, 0, q, qd, qdd);
    const double rho = cv * cv + sv * sv, rhoh = 2.0 * (cv * ch + sv * sh);
    if (order == 0) return (cv * sh - sv * ch) / rho;
    const double cd = row_rate(a, c, q, qd, 1.0), sd = row_rate(a, s, q, qd, 1.0);
    const double cdh = row_data_derivative(a, r, c, 1, q, qd, qdd), sdh = row_data_derivative(a, r, s, 1, q, qd, qdd);
    const double n1 = cv * sd - sv * cd, n1h = ch * sd + cv * sdh - sh * cd - sv * cdh;
    if (order == 1) return n1h / rho - n1 * rhoh / (rho * rho);
    // c̈ = Φq q̈ − γ of the row
    const double cdd = row_rate(a, c, q, qdd, 1.0) - row_gamma(a, c, q, qd, 1.0);
    const double sdd = row_rate(a, s, q, qdd, 1.0) - row_gamma(a, s, q, qd, 1.0);
    const double cddh = row_data_derivative(a, r, c, 2, q, qd, qdd), sddh = row_data_derivative(a, r, s, 2, q, qd, qdd);
    const double n2 = cv * sdd - sv * cdd, n2h = ch * sdd + cv * sddh - sh * cdd - sv * cddh;
    const double rhod = 2.0 * (cv * cd + sv * sd), rhodh = 2.0 * (ch * cd + cv * cdh + sh * sd + sv * sdh);
    const double rho2 = rho * rho;
    return n2h / rho - n2 * rhoh / rho2 - (n1h * rhod + n1 * rhodh) / rho2 + 2.0 * n1 * rhod * rhoh / (rho2 * rho);
  }
};
/// Draws a joint: the arms of the bodies it joins, and `mark` at its point (on ground when a side is ground).
template <class Sketch>
void sketch_joint(const JointSide3& a, const JointSide3& b, JointMark mark, Sketch& sk) {
  const Attachment3 pa = Attachment3::body_point(a.frame, a.at), pb = Attachment3::body_point(b.frame, b.at);
  sk.arm3(pa);
  sk.arm3(pb);
  sk.joint3(pa, pb, mark);
}
/// Reports the slots of a side: its position (lengths), Euler parameters and vector (unitless).
template <class F>
void side_slots(const JointSide3& s, F& f) {
  f(s.frame.x, Unit::kLength), f(s.frame.y, Unit::kLength), f(s.frame.z, Unit::kLength);
  f(s.frame.e0, Unit::kNone), f(s.frame.e1, Unit::kNone), f(s.frame.e2, Unit::kNone), f(s.frame.e3, Unit::kNone);
  if (s.vector) f(s.vector->x, Unit::kNone), f(s.vector->y, Unit::kNone), f(s.vector->z, Unit::kNone);
}
}  // namespace detail3

/// The rates of an attachment's data along a design parameter (detail::datum_rate, DistanceSpec::data_derivative()):
/// its slots' (constants their rate, coordinates none) and its local vector's.
inline bool datum_rate(Attachment3& rate, const std::array<const Attachment3*, 4>& v, double h) {
  auto slot = [&](Slot& r, auto member, int k) {
    return detail::datum_rate(r, {&(v[0]->*member)[k], &(v[1]->*member)[k], &(v[2]->*member)[k],
                                  &(v[3]->*member)[k]}, h);
  };
  bool ok = true;
  for (int k = 0; k < 3; ++k) ok = ok && slot(rate.r[k], &Attachment3::r, k);
  for (int k = 0; k < 4; ++k) ok = ok && slot(rate.p[k], &Attachment3::p, k);
  return ok && detail::datum_rate(rate.s.x, {&v[0]->s.x, &v[1]->s.x, &v[2]->s.x, &v[3]->s.x}, h) &&
         detail::datum_rate(rate.s.y, {&v[0]->s.y, &v[1]->s.y, &v[2]->s.y, &v[3]->s.y}, h) &&
         detail::datum_rate(rate.s.z, {&v[0]->s.z, &v[1]->s.z, &v[2]->s.z, &v[3]->s.z}, h);
}
/// The rates of a list of attachments, each's.
template <std::size_t N>
bool datum_rate(std::array<Attachment3, N>& rate, const std::array<const std::array<Attachment3, N>*, 4>& v, double h) {
  for (std::size_t i = 0; i < N; ++i)
    if (!datum_rate(rate[i], {&(*v[0])[i], &(*v[1])[i], &(*v[2])[i], &(*v[3])[i]}, h)) return false;
  return true;
}
/// A joint's side, as given, is not what its rows read: its attachments (`att`, derived from the sides) are, and
/// they carry the side's rates (a side that turns from a body to ground changes their slots and is refused there).
/// The side's "rate" is left as the side itself, and never read.
inline bool datum_rate(JointSide3&, const std::array<const JointSide3*, 4>&, double) { return true; }
/// The rates of a spatial point's slots (detail::datum_rate): a natural point's coordinates have none, a fixed
/// component its constant's.
inline bool datum_rate(Point3& rate, const std::array<const Point3*, 4>& v, double h) {
  return detail::datum_rate(rate.x, {&v[0]->x, &v[1]->x, &v[2]->x, &v[3]->x}, h) &&
         detail::datum_rate(rate.y, {&v[0]->y, &v[1]->y, &v[2]->y, &v[3]->y}, h) &&
         detail::datum_rate(rate.z, {&v[0]->z, &v[1]->z, &v[2]->z, &v[3]->z}, h);
}

/// A spatial joint between two sides, its rows given by `Traits` (one struct per joint type below). The sides
/// are data; setup() (called by ModelBuilder::add, or by hand before evaluating a spec built in code) validates
/// them and derives the attachments the rows read.
template <class Traits>
struct SpatialJointSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const SpatialJointSpec&) const = default;
  static constexpr int kRows = Traits::kRows;  ///< the freedoms the joint removes
  /// @copydoc DistanceSpec::kKind
  static constexpr const char* kKind = Traits::kKind;
  /// @var a
  /// @brief Side a: its joint frame carries the axis of one-sided rows (lines, planes).
  JointSide3 a, b;  ///< side b
  /// The rows' attachments and the rows renumbered into them (detail3::compact_rows).
  static constexpr auto kCompact = detail3::compact_rows(Traits::kRowDefs);
  std::array<Attachment3, kCompact.count> att{};  ///< derived by setup(): the attachments the rows read

  /// Validates the sides and derives `att`. Throws phiq::Error.
  void setup() { detail3::set_up_attachments(a, b, kCompact, kKind, att); }
  /// @copydoc DistanceSpec::depends_on_time
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// Point gaps and offsets from lines and planes are lengths; products of axes are angles.
  Unit row_unit(int r, const std::vector<Unit>&) const { return Traits::kRowDefs[r].unit; }
  /// @copydoc DistanceSpec::characteristic_length
  /// For a joint: the longer arm |at| of a moving side.
  double characteristic_length() const { return detail3::joint_arm(a, b); }
  /// @copydoc DistanceSpec::for_each_slot
  /// A joint reports the frame (and vector) slots of side a, then of side b.
  template <class F>
  void for_each_slot(F&& f) const {
    detail3::side_slots(a, f), detail3::side_slots(b, f);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    for (int r = 0; r < kRows; ++r) phi[r] = detail3::row_value(att.data(), kCompact.rows[r], q, 1.0, 0.0);
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    for (int r = 0; r < kRows; ++r) detail3::row_jacobian(att.data(), kCompact.rows[r], q, s, r, 1.0);
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const {
    for (int r = 0; r < kRows; ++r) out[r] = 0.0;
  }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double, double* out) const {
    for (int r = 0; r < kRows; ++r) out[r] = detail3::row_gamma(att.data(), kCompact.rows[r], q, qd, 1.0);
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the sides, through the attachments the rows
  /// read (a side's local point, axis and reference direction, a ground frame's place).
  static constexpr auto data_members() {
    return std::tuple{&SpatialJointSpec::a, &SpatialJointSpec::b, &SpatialJointSpec::att};
  }
  /// Derivatives along the data (DistanceSpec::data_derivative()): each row's, X · Y differentiated along its
  /// attachments' rates (detail3::row_data_derivative(): exact, the attachments being quadratic in the Euler
  /// parameters and linear in the local vectors).
  void data_derivative(const SpatialJointSpec& rate, int order, const double* q, const double* qd, const double* qdd,
                       double, double* out) const {
    for (int r = 0; r < kRows; ++r)
      out[r] = detail3::row_data_derivative(att.data(), rate.att.data(), kCompact.rows[r], order, q, qd, qdd);
  }

  /// @copydoc DistanceSpec::joint_count
  /// A joint between bodies or ground removes kRows freedoms; with a natural side the count is undefined.
  JointCount joint_count() const {
    if (a.natural || b.natural) return JointCount::other();
    return JointCount::joint(3, Traits::kRows);
  }
  /// @copydoc DistanceSpec::prepare
  /// For a joint: setup().
  void prepare(const double* /*q0*/) { setup(); }
  /// @copydoc DistanceSpec::sketch
  /// A spatial joint draws the arms of the bodies it joins, and a mark at its point (a hinge for a revolute, a
  /// block for a prismatic pair, a ball for the others), on ground when a side is ground.
  template <class Sketch>
  void sketch(Sketch& sk) const {
    const std::string_view kind = Traits::kKind;
    const JointMark mark = kind == "revolute"    ? JointMark::kRevolute
                           : kind == "prismatic" ? JointMark::kPrismatic
                                                 : JointMark::kSpherical;
    detail3::sketch_joint(a, b, mark, sk);
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr const auto& kScene = Traits::kScene;
  /// @copydoc DistanceSpec::read
  /// The spherical joint also reads `fixed_point` (a natural point held at a place).
  template <class Fields>
  static SpatialJointSpec read(const Fields& f) {
    SpatialJointSpec spec;
    if (f.type() == "fixed_point") {
      f.expect({"type", "name", "point", "at"});
      spec.a = JointSide3::natural_point(f.point3("point"));
      spec.b = JointSide3::body(Frame3::ground(), f.vec3("at"));
      return spec;
    }
    if (f.present("axis"))  // where a planar prismatic writes it
      f.fail("axis", "in dimension 3 a joint's axis is given on each side, in that body's frame: between: "
                     "[{body: A, axis: [x, y, z]}, {body: B, axis: [x, y, z]}]");
    f.expect({"type", "name", "between"});
    std::tie(spec.a, spec.b) = f.sides3("between");
    return spec;
  }
};

namespace joint3 {
using detail3::Axis;
using detail3::RowDef;
using detail3::T;
using namespace detail3;  // the attachment indices kPa …
inline constexpr Unit kL = Unit::kLength;  ///< shorthand for the row tables: a length row
inline constexpr Unit kA = Unit::kAngle;   ///< shorthand for the row tables: an angle row

/// Spherical joint (ball): the points coincide.   Φ = P_a − P_b   (3 rows, lengths)
struct Spherical {
  static constexpr int kRows = 3;  ///< rows: the freedoms it removes
  static constexpr const char* kKind = "spherical";  ///< scene type and diagnostics name
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {
      {"constraints", "spherical", 3, "- {name: base, type: spherical, between: [{body: ground}, {body: B1}]}"},
      {"constraints", "fixed_point", 3, "- {name: fixP, type: fixed_point, point: P, at: [1, 2, 3]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {{Axis(0), T(kPa, kPb), kL}, {Axis(1), T(kPa, kPb), kL},
                                             {Axis(2), T(kPa, kPb), kL}};
};
/// Revolute joint: spherical, and the axes parallel.
///   Φ = [P_a − P_b;  x_a · z_b;  y_a · z_b]   (5 rows: 3 lengths, 2 angles)
struct Revolute {
  static constexpr int kRows = 5;  ///< rows: the freedoms it removes
  static constexpr const char* kKind = "revolute";  ///< scene type and diagnostics name
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {
      {"constraints", "revolute", 3, "- {name: hinge, type: revolute, between: [{body: ground, at: [0, 0, 1], "
                                     "axis: [0, 0, 1]}, {body: door, at: [0, 0, 1]}]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {{Axis(0), T(kPa, kPb), kL}, {Axis(1), T(kPa, kPb), kL},
                                             {Axis(2), T(kPa, kPb), kL}, {T(kXa), T(kZb), kA},
                                             {T(kYa), T(kZb), kA}};
};
/// Cylindrical joint: the axes parallel, and P_b on the line of a (through P_a along z_a).
///   Φ = [x_a · z_b;  y_a · z_b;  x_a · (P_b − P_a);  y_a · (P_b − P_a)]   (4 rows: 2 angles, 2 lengths)
struct Cylindrical {
  static constexpr int kRows = 4;  ///< rows: the freedoms it removes
  static constexpr const char* kKind = "cylindrical";  ///< scene type and diagnostics name
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {
      {"constraints", "cylindrical", 3, "- {name: cyl, type: cylindrical, between: [{body: ground, axis: [1, 0, "
                                        "0]}, {body: screw, axis: [1, 0, 0]}]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {{T(kXa), T(kZb), kA}, {T(kYa), T(kZb), kA},
                                             {T(kXa), T(kPb, kPa), kL}, {T(kYa), T(kPb, kPa), kL}};
};
/// Prismatic joint: cylindrical, and no rotation about the axis (x_b stays along x_a).
///   Φ = [x_a · z_b;  y_a · z_b;  x_a · (P_b − P_a);  y_a · (P_b − P_a);  y_a · x_b]   (5 rows)
struct Prismatic {
  static constexpr int kRows = 5;  ///< rows: the freedoms it removes
  static constexpr const char* kKind = "prismatic";  ///< scene type and diagnostics name
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {
      {"constraints", "prismatic", 3, "- {name: slide, type: prismatic, between: [{body: ground, axis: [1, 0, 0]}, "
                                      "{body: slider, axis: [1, 0, 0]}]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {{T(kXa), T(kZb), kA}, {T(kYa), T(kZb), kA},
                                             {T(kXa), T(kPb, kPa), kL}, {T(kYa), T(kPb, kPa), kL},
                                             {T(kYa), T(kXb), kA}};
};
/// Universal (Hooke) joint: spherical, and the two axes kept perpendicular (the cross).
///   Φ = [P_a − P_b;  z_a · z_b]   (4 rows: 3 lengths, 1 angle)
struct Universal {
  static constexpr int kRows = 4;  ///< rows: the freedoms it removes
  static constexpr const char* kKind = "universal";  ///< scene type and diagnostics name
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {
      {"constraints", "universal", 3, "- {name: cross, type: universal, between: [{body: s1, axis: [1, 0, 0]}, "
                                      "{body: s2, axis: [0, 1, 0]}]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {{Axis(0), T(kPa, kPb), kL}, {Axis(1), T(kPa, kPb), kL},
                                             {Axis(2), T(kPa, kPb), kL}, {T(kZa), T(kZb), kA}};
};
/// Planar joint: the normals parallel, and P_b in the plane of a (through P_a, normal z_a).
///   Φ = [x_a · z_b;  y_a · z_b;  z_a · (P_b − P_a)]   (3 rows: 2 angles, 1 length)
struct Planar {
  static constexpr int kRows = 3;  ///< rows: the freedoms it removes
  static constexpr const char* kKind = "planar";  ///< scene type and diagnostics name
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {
      {"constraints", "planar", 3, "- {name: on_table, type: planar, between: [{body: ground}, {body: puck}]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {{T(kXa), T(kZb), kA}, {T(kYa), T(kZb), kA}, {T(kZa), T(kPb, kPa), kL}};
};
/// Rigid joint (weld): the points coincide and the joint frames stay aligned (x_b ∥ x_a, y_b ∥ y_a, z_b ∥ z_a).
///   Φ = [P_a − P_b;  x_a · y_b;  y_a · z_b;  z_a · x_b]   (6 rows: 3 lengths, 3 angles)
struct Rigid {
  static constexpr int kRows = 6;  ///< rows: the freedoms it removes
  static constexpr const char* kKind = "rigid";  ///< scene type and diagnostics name
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {
      {"constraints", "rigid", 3, "- {name: weld, type: rigid, between: [{body: frame, at: [1, 0, 0]}, {body: arm}]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {{Axis(0), T(kPa, kPb), kL}, {Axis(1), T(kPa, kPb), kL},
                                             {Axis(2), T(kPa, kPb), kL}, {T(kXa), T(kYb), kA},
                                             {T(kYa), T(kZb), kA},       {T(kZa), T(kXb), kA}};
};
/// Point on line: P_b on the line of a (through P_a along z_a).
///   Φ = [x_a · (P_b − P_a);  y_a · (P_b − P_a)]   (2 rows, lengths)
struct PointOnLine {
  static constexpr int kRows = 2;  ///< rows: the freedoms it removes
  static constexpr const char* kKind = "point_on_line";  ///< scene type and diagnostics name
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {
      {"constraints", "point_on_line", 3, "- {name: axis2, type: point_on_line, between: [{body: ground, axis: [1, "
                                          "0, 0]}, {body: s2, at: [0, 0, 1]}]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {{T(kXa), T(kPb, kPa), kL}, {T(kYa), T(kPb, kPa), kL}};
};
/// Point on plane: P_b in the plane of a (through P_a, normal z_a).
///   Φ = z_a · (P_b − P_a)   (1 row, a length)
struct PointOnPlane {
  static constexpr int kRows = 1;  ///< rows: the freedoms it removes
  static constexpr const char* kKind = "point_on_plane";  ///< scene type and diagnostics name
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {
      {"constraints", "point_on_plane", 3, "- {name: plane0, type: point_on_plane, between: [{body: ground, "
                                           "axis: [1, 2, 2]}, {point: P0}]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {{T(kZa), T(kPb, kPa), kL}};
};
}  // namespace joint3

using SphericalSpec = SpatialJointSpec<joint3::Spherical>;              ///< scene type `spherical` (dimension 3)
using SpatialRevoluteSpec = SpatialJointSpec<joint3::Revolute>;         ///< scene type `revolute` (dimension 3)
using CylindricalSpec = SpatialJointSpec<joint3::Cylindrical>;          ///< scene type `cylindrical`
using SpatialPrismaticSpec = SpatialJointSpec<joint3::Prismatic>;       ///< scene type `prismatic` (dimension 3)
using UniversalSpec = SpatialJointSpec<joint3::Universal>;              ///< scene type `universal`
using PlanarSpec = SpatialJointSpec<joint3::Planar>;                    ///< scene type `planar`
using RigidSpec = SpatialJointSpec<joint3::Rigid>;                      ///< scene type `rigid`
using SpatialPointOnLineSpec = SpatialJointSpec<joint3::PointOnLine>;   ///< scene type `point_on_line` (dim. 3)
using PointOnPlaneSpec = SpatialJointSpec<joint3::PointOnPlane>;        ///< scene type `point_on_plane`

}  // namespace phiq
