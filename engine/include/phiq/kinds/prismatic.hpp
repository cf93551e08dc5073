/// @file
/// The planar prismatic pair between two bodies (reference-point coordinates). One constraint kind: its equation,
/// derivatives, validation, joint count, sketch and scene form (the contract is documented on DistanceSpec;
/// kinds/registry.hpp lists every kind).
#pragma once

#include <cmath>

#include "phiq/kinds/kind_support.hpp"
#include "phiq/kinds/reaction_site.hpp"

namespace phiq {

/// Prismatic pair between body a and body b (reference-point coordinates). With e = R(ψ_a) u the sliding axis (u a
/// unit vector in a's frame), P_a = r_a + R(ψ_a) s_a a point of the line on a and P_b = r_b + R(ψ_b) s_b a point of b:
///   Φ0 = ψ_b − ψ_a − θ0                 (no relative rotation; angle)
///   Φ1 = e × (P_b − P_a)                (P_b stays on the line of a; length since |e| = 1)
struct PrismaticSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const PrismaticSpec&) const = default;
  static constexpr int kRows = 2;  ///< two rows: Φ0 (relative rotation) and Φ1 (distance of P_b from the line)
  /// @copydoc DistanceSpec::kKind
  /// Scene type `prismatic`.
  static constexpr const char* kKind = "prismatic";
  /// @var a
  /// @brief Frame of body a, which carries the sliding line (x, y in m, ψ in rad).
  Frame2 a, b;  ///< frame of body b, which slides along the line
  /// @var sa
  /// @brief s_a, a point of the sliding line in a's local frame (m).
  kin::V2 sa{0, 0}, sb{0, 0};  ///< s_b, the point of b kept on the line, in b's local frame (m)
  kin::V2 axis{1, 0};          ///< u, direction of the line in a's local frame; normalised when the constraint is added
  double angle = 0.0;          ///< θ0, the constant relative angle ψ_b − ψ_a (rad)

  /// @copydoc DistanceSpec::depends_on_time
  /// A prismatic pair is time-independent.
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// For a prismatic pair, row 0 (relative rotation) is an angle and row 1 (distance from the line) a length.
  Unit row_unit(int row, const std::vector<Unit>&) const { return row == 0 ? Unit::kAngle : Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  /// For a prismatic pair: the longer arm, max(|s_a|, |s_b|), of the frames that move. An attachment on a fixed frame
  /// (ground: x, y, ψ all constants) is a position in the plane, not a link dimension: the 10^6-th pivot of a chain
  /// on the ground at (10^6, 0) must not make the model's length scale 10^6 m.
  double characteristic_length() const { return std::max(kin::moving_arm(a, sa), kin::moving_arm(b, sb)); }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Prismatic pair
  /// A prismatic pair reads x, y (lengths) and ψ (an angle) of frame a, then of frame b.
  template <class F>
  void for_each_slot(F&& f) const {
    f(a.x, Unit::kLength), f(a.y, Unit::kLength), f(a.psi, Unit::kAngle);
    f(b.x, Unit::kLength), f(b.y, Unit::kLength), f(b.psi, Unit::kAngle);
  }
  /// The values its reaction has (ConstraintBlock::reaction_width()): Fx, Fy, Mz of a planar joint.
  static constexpr int kReactionWidth = 3;
  /// The reaction (ReactionSite): on frame a, or on b when a is fixed, at the point s_b of the slider, which the
  /// pair keeps on the line; its axes x along the slide (e) and y across it.
  ReactionSite reaction_site(const double* q) const {
    const kin::V2 p = kin::V2{b.x.of(q), b.y.of(q)} + kin::rotate(b.psi.of(q), sb);
    ReactionSite site;
    site.point = {p.x, p.y, 0.0};
    site.frame2 = detail::frame_moves(a) ? a : b;
    const kin::V2 e = geometry(q).e;
    site.axes[0] = {e.x, e.y, 0.0}, site.axes[1] = {-e.y, e.x, 0.0};
    return site;
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    Geometry g = geometry(q);
    phi[0] = b.psi.of(q) - a.psi.of(q) - angle;
    phi[1] = kin::cross(g.e, g.h);
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    Geometry g = geometry(q);
    s(0, b.psi, 1.0), s(0, a.psi, -1.0);
    s(1, a.x, g.e.y), s(1, a.y, -g.e.x), s(1, b.x, -g.e.y), s(1, b.y, g.e.x);
    // ∂/∂ψa: e turns and P_a moves: −e·(r_b + R_b s_b − r_a); ∂/∂ψb = e·(R_b s_b)
    s(1, a.psi, -kin::dot(g.e, g.h + g.arm_a)), s(1, b.psi, kin::dot(g.e, g.arm_b));
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = out[1] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double, double* out) const {
    Geometry g = geometry(q);
    double wa = a.psi.rate(qd), wb = b.psi.rate(qd);
    kin::V2 edot = wa * kin::perp(g.e);
    kin::V2 hdot = kin::V2{b.x.rate(qd), b.y.rate(qd)} + wb * kin::perp(g.arm_b) - kin::V2{a.x.rate(qd), a.y.rate(qd)} -
                   wa * kin::perp(g.arm_a);
    // q̈-free parts: ë = −ψ̇a² e, ḧ = −ψ̇b² R_b s_b + ψ̇a² R_a s_a
    kin::V2 hdd = (wa * wa) * g.arm_a - (wb * wb) * g.arm_b;
    double phidd = -wa * wa * kin::cross(g.e, g.h) + 2.0 * kin::cross(edot, hdot) + kin::cross(g.e, hdd);
    out[0] = 0.0;
    out[1] = -phidd;
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the frames' constant slots, the local points, the
  /// axis and the relative angle.
  static constexpr auto data_members() {
    return std::tuple{&PrismaticSpec::a,  &PrismaticSpec::b,    &PrismaticSpec::sa,
                      &PrismaticSpec::sb, &PrismaticSpec::axis, &PrismaticSpec::angle};
  }
  /// Derivatives along the data (DistanceSpec::data_derivative()). Row 0 reads only angles: ψ̂_b − ψ̂_a − θ̂0 at
  /// order 0, nothing at orders 1 and 2. Row 1 is e × h; with the data's rates ê = R(ψ_a) û + ψ̂_a e⊥ and
  /// ĥ = r̂_b + â_b − r̂_a − â_a, â_k = R(ψ_k) ŝ_k + ψ̂_k (R(ψ_k) s_k)⊥ (ψ̂ the rate of a constant ψ), and the
  /// motion's ė = ω_a e⊥, ë = α_a e⊥ − ω_a² e, ḣ, ḧ (their data parts ∂ė = ω_a ê⊥, ∂ë = α_a ê⊥ − ω_a² ê,
  /// ∂ḣ = ω_b â_b⊥ − ω_a â_a⊥, ∂ḧ = α_b â_b⊥ − ω_b² â_b − α_a â_a⊥ + ω_a² â_a):
  ///
  ///   ∂Φ1/∂p = ê × h + e × ĥ,   ∂(Φq q̇)1/∂p = ∂ė × h + ė × ĥ + ê × ḣ + e × ∂ḣ,
  ///   ∂(Φq q̈ − γ)1/∂p = ∂ë × h + ë × ĥ + 2 (∂ė × ḣ + ė × ∂ḣ) + ê × ḧ + e × ∂ḧ.
  void data_derivative(const PrismaticSpec& rate, int order, const double* q, const double* qd, const double* qdd,
                       double, double* out) const {
    const Geometry g = geometry(q);
    const double pa = a.psi.of(q), pb = b.psi.of(q), psia = rate.a.psi.of(q), psib = rate.b.psi.of(q);
    const kin::V2 eh = kin::rotate(pa, rate.axis) + psia * kin::perp(g.e);
    const kin::V2 ha = kin::rotate(pa, rate.sa) + psia * kin::perp(g.arm_a);
    const kin::V2 hb = kin::rotate(pb, rate.sb) + psib * kin::perp(g.arm_b);
    const kin::V2 hh = kin::V2{rate.b.x.of(q), rate.b.y.of(q)} + hb - kin::V2{rate.a.x.of(q), rate.a.y.of(q)} - ha;
    if (order == 0) {
      out[0] = psib - psia - rate.angle;
      out[1] = kin::cross(eh, g.h) + kin::cross(g.e, hh);
      return;
    }
    out[0] = 0.0;
    const double wa = a.psi.rate(qd), wb = b.psi.rate(qd);
    const kin::V2 ed = wa * kin::perp(g.e), edh = wa * kin::perp(eh);
    const kin::V2 hd = kin::V2{b.x.rate(qd), b.y.rate(qd)} + wb * kin::perp(g.arm_b) -
                       kin::V2{a.x.rate(qd), a.y.rate(qd)} - wa * kin::perp(g.arm_a);
    const kin::V2 hdh = wb * kin::perp(hb) - wa * kin::perp(ha);
    if (order == 1) {
      out[1] = kin::cross(edh, g.h) + kin::cross(ed, hh) + kin::cross(eh, hd) + kin::cross(g.e, hdh);
      return;
    }
    const double aa = a.psi.rate(qdd), ab = b.psi.rate(qdd);
    const kin::V2 edd = aa * kin::perp(g.e) - (wa * wa) * g.e, eddh = aa * kin::perp(eh) - (wa * wa) * eh;
    const kin::V2 hdd = kin::V2{b.x.rate(qdd), b.y.rate(qdd)} + ab * kin::perp(g.arm_b) - (wb * wb) * g.arm_b -
                        kin::V2{a.x.rate(qdd), a.y.rate(qdd)} - aa * kin::perp(g.arm_a) + (wa * wa) * g.arm_a;
    const kin::V2 hddh = ab * kin::perp(hb) - (wb * wb) * hb - aa * kin::perp(ha) + (wa * wa) * ha;
    out[1] = kin::cross(eddh, g.h) + kin::cross(edd, hh) + 2.0 * (kin::cross(edh, hd) + kin::cross(ed, hdh)) +
             kin::cross(eh, hdd) + kin::cross(g.e, hddh);
  }

  /// @copydoc DistanceSpec::joint_count
  /// A prismatic pair between bodies or ground removes 2 freedoms.
  JointCount joint_count() const { return detail::planar_pair_joint_count(a, b); }
  /// @copydoc DistanceSpec::prepare
  /// The axis is normalised here.
  void prepare(const double* /*q0*/) {
    const double n = std::hypot(axis.x, axis.y);
    detail::require(std::isfinite(n) && n > 0.0, "prismatic: axis must be a non-zero finite vector");
    axis = (1.0 / n) * axis;
    detail::require(std::isfinite(angle), "prismatic: angle is not finite");
  }
  /// @copydoc DistanceSpec::sketch
  /// A prismatic pair draws the arms of the bodies it joins, and b's block on a's guide.
  template <class Sketch>
  void sketch(Sketch& sk) const {
    sk.arm(a, sa);
    sk.arm(b, sb);
    sk.slider(a, axis, b, sb);
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {{"constraints", "prismatic", 2,
                                          "- {name: slide, type: prismatic, between: [{body: ground}, {body: slider}], "
                                          "axis: [1, 0]}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static PrismaticSpec read(const Fields& f) {
    f.expect({"type", "name", "between", "axis", "angle"});
    const auto [ea, eb] = f.attachments("between", "a prismatic pair joins two attachments");
    if (!ea.frame.psi.is_coordinate() && !eb.frame.psi.is_coordinate() && !ea.body)
      f.fail("between", "a prismatic pair needs bodies");
    PrismaticSpec spec{ea.frame, eb.frame, ea.at, eb.at, {1, 0}, 0.0};
    if (f.present("axis")) spec.axis = f.vec2("axis");
    if (f.present("angle")) spec.angle = f.number("angle");
    if (spec.axis.x == 0.0 && spec.axis.y == 0.0) f.fail("axis", "the axis must not be zero");
    return spec;
  }

 private:
  /// @cond internal
  /// The vectors of the equations at q: e = R(ψ_a) u, arm_k = R(ψ_k) s_k, h = P_b − P_a.
  struct Geometry {
    kin::V2 e, arm_a, arm_b, h;
  };
  /// Computes Geometry at q.
  Geometry geometry(const double* q) const {
    Geometry g;
    double pa = a.psi.of(q), pb = b.psi.of(q);
    g.e = kin::rotate(pa, axis);
    g.arm_a = kin::rotate(pa, sa);
    g.arm_b = kin::rotate(pb, sb);
    g.h = kin::V2{b.x.of(q), b.y.of(q)} + g.arm_b - kin::V2{a.x.of(q), a.y.of(q)} - g.arm_a;
    return g;
  }
  /// @endcond
};

}  // namespace phiq
