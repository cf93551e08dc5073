/// @file
/// The one device of the spatial kinds: rows w (X · Y − c) over attachments. X and Y are sums of attachments
/// (spatial_attachment.hpp: X = r + R(p) s) or a constant unit axis, so that the Jacobian, Φt and γ of every joint,
/// joint driver, distance, dot product, gear and mixed coordinate in space come from one set of formulas (detail3):
///
///     Φ̇ = w (Ẋ · Y + X · Ẏ),     γ = −w (a_X · Y + 2 Ẋ · Ẏ + X · a_Y)      (a = the q̈-free part of the acceleration)
///
/// and so do their derivatives along the attachments' data (a design parameter that moves a local point, an axis or
/// a ground frame: row_derivatives(), and the attachments' datum_rate()); and the angle of a direction about an axis
/// from two such rows (AngleRows), which the joint angle driver, the screw and the spatial angles share.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <utility>

#include "phiq/spatial_attachment.hpp"
#include "phiq/kinds/kind_support.hpp"

namespace phiq {
namespace detail3 {
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
/// The time derivatives of a row's X · Y up to `order`, and their derivatives along the data (`r`: the rates of `a`),
/// at fixed q, q̇, q̈, in one pass over the attachments:
///   value[k] = Σ_i C(k, i) X⁽ⁱ⁾ · Y⁽ᵏ⁻ⁱ⁾   (X · Y, Ẋ · Y + X · Ẏ, and Ẍ · Y + 2 Ẋ · Ẏ + X · Ÿ = Φq q̈ − γ of the row),
///   along[k] = Σ_i C(k, i) (X̂⁽ⁱ⁾ · Y⁽ᵏ⁻ⁱ⁾ + X⁽ⁱ⁾ · Ŷ⁽ᵏ⁻ⁱ⁾).
/// For a row w (X · Y − c) with w and c fixed, w along[k] is ∂Φ/∂p, ∂(Φq q̇)/∂p or ∂(Φq q̈ − γ)/∂p (k = 0, 1, 2).
struct RowDerivatives {
  double value[3] = {0.0, 0.0, 0.0};  ///< the row's product and its time derivatives, up to the order asked
  double along[3] = {0.0, 0.0, 0.0};  ///< their derivatives along the data
};
inline RowDerivatives row_derivatives(const Attachment3* a, const Attachment3* r, const RowDef& d, int order,
                                      const double* q, const double* qd, const double* qdd) {
  kin3::V3 x[3], xh[3], y[3], yh[3];
  term_data_derivatives(a, r, d.x, order, q, qd, qdd, x, xh);
  term_data_derivatives(a, r, d.y, order, q, qd, qdd, y, yh);
  using detail::kBinomial;
  RowDerivatives out;
  for (int k = 0; k <= order; ++k)
    for (int i = 0; i <= k; ++i) {
      out.value[k] += kBinomial[k][i] * kin3::dot(x[i], y[k - i]);
      out.along[k] += kBinomial[k][i] * (kin3::dot(xh[i], y[k - i]) + kin3::dot(x[i], yh[k - i]));
    }
  return out;
}
/// The derivative along the data of the row's `order`-th time derivative: row_derivatives()'s along[order].
inline double row_data_derivative(const Attachment3* a, const Attachment3* r, const RowDef& d, int order,
                                  const double* q, const double* qd, const double* qdd) {
  return row_derivatives(a, r, d, order, q, qd, qdd).along[order];
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
  /// (row_derivatives()), ρ = c² + s², N1 = c ṡ − s ċ, N2 = c s̈ − s c̈, θ̇ = N1/ρ, θ̈ = N2/ρ − N1 ρ̇/ρ², each
  /// differentiated by the product and quotient rules.
  double data_derivative(const Attachment3* a, const Attachment3* r, int order, const double* q, const double* qd,
                         const double* qdd) const {
    const RowDerivatives cr = row_derivatives(a, r, c, order, q, qd, qdd);
    const RowDerivatives sr = row_derivatives(a, r, s, order, q, qd, qdd);
    const double cv = cr.value[0], sv = sr.value[0], ch = cr.along[0], sh = sr.along[0];
    const double rho = cv * cv + sv * sv, rhoh = 2.0 * (cv * ch + sv * sh);
    if (order == 0) return (cv * sh - sv * ch) / rho;
    const double cd = cr.value[1], sd = sr.value[1], cdh = cr.along[1], sdh = sr.along[1];
    const double n1 = cv * sd - sv * cd, n1h = ch * sd + cv * sdh - sh * cd - sv * cdh;
    if (order == 1) return n1h / rho - n1 * rhoh / (rho * rho);
    const double cdd = cr.value[2], sdd = sr.value[2], cddh = cr.along[2], sddh = sr.along[2];
    const double n2 = cv * sdd - sv * cdd, n2h = ch * sdd + cv * sddh - sh * cdd - sv * cddh;
    const double rhod = 2.0 * (cv * cd + sv * sd), rhodh = 2.0 * (ch * cd + cv * cdh + sh * sd + sv * sdh);
    const double rho2 = rho * rho;
    return n2h / rho - n2 * rhoh / rho2 - (n1h * rhod + n1 * rhodh) / rho2 + 2.0 * n1 * rhod * rhoh / (rho2 * rho);
  }
};
}  // namespace detail3

/// The rates of an attachment's data along a design parameter (detail::datum_rate, DistanceSpec::data_derivative()):
/// its slots' (constants their rate, coordinates none) and its local vector's.
inline bool datum_rate(Attachment3& rate, const std::array<const Attachment3*, 4>& v, double h) {
  auto slot = [&](Slot& r, auto member, int k) {
    return detail::datum_rate(r, {&(v[0]->*member)[k], &(v[1]->*member)[k], &(v[2]->*member)[k], &(v[3]->*member)[k]},
                              h);
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
/// An attachment moved by s times its rates (detail::datum_moved(), ConstraintBlock::data_moved()).
inline bool datum_moved(Attachment3& a, const Attachment3& rate, double s) {
  for (int k = 0; k < 3; ++k) detail::datum_moved(a.r[k], rate.r[k], s);
  for (int k = 0; k < 4; ++k) detail::datum_moved(a.p[k], rate.p[k], s);
  a.s = {a.s.x + s * rate.s.x, a.s.y + s * rate.s.y, a.s.z + s * rate.s.z};
  return true;
}
/// A list of attachments moved, each.
template <std::size_t N>
bool datum_moved(std::array<Attachment3, N>& a, const std::array<Attachment3, N>& rate, double s) {
  for (std::size_t i = 0; i < N; ++i) datum_moved(a[i], rate[i], s);
  return true;
}
/// The rates of a spatial point's slots (detail::datum_rate): a natural point's coordinates have none, a fixed
/// component its constant's.
inline bool datum_rate(Point3& rate, const std::array<const Point3*, 4>& v, double h) {
  return detail::datum_rate(rate.x, {&v[0]->x, &v[1]->x, &v[2]->x, &v[3]->x}, h) &&
         detail::datum_rate(rate.y, {&v[0]->y, &v[1]->y, &v[2]->y, &v[3]->y}, h) &&
         detail::datum_rate(rate.z, {&v[0]->z, &v[1]->z, &v[2]->z, &v[3]->z}, h);
}

}  // namespace phiq
