/// @file
/// The coincidence of two attachment points: revolute pairs and fixed points in the plane. One constraint kind: its
/// equation, derivatives, validation, joint count, sketch and scene form (the contract is documented on DistanceSpec;
/// kinds/registry.hpp lists every kind).
#pragma once

#include <cmath>
#include <tuple>

#include "phiq/kinds/kind_support.hpp"
#include "phiq/kinds/reaction_site.hpp"

namespace phiq {

/// Coincidence of two attachment points ("pin"): a revolute pair between two bodies in reference-point coordinates,
/// a body point fixed to ground (one side constant), a fixed point (natural point against a constant), or a body
/// pinned to a natural point (mixed). Attachment k is frame_k = (x, y, ψ) plus the local vector s_k:
///   Φ = r_a + R(ψ_a) s_a − r_b − R(ψ_b) s_b            (2 rows, lengths)
/// A natural point is a frame with ψ constant and s = 0.
struct PinSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const PinSpec&) const = default;
  static constexpr int kRows = 2;  ///< two rows: x and y of the gap between the attachment points
  /// @copydoc DistanceSpec::kKind
  /// Scenes write a pin as `revolute` (between attachments) or `fixed_point` (a point at constant coordinates).
  static constexpr const char* kKind = "pin";
  /// @var a
  /// @brief Frame of attachment a: a body frame (x, y in m, ψ in rad), a natural point (ψ constant) or ground.
  Frame2 a, b;  ///< frame of attachment b, like a
  /// @var sa
  /// @brief s_a, the attachment point in a's local frame (m); (0, 0) for a natural point or a body's origin.
  kin::V2 sa{0, 0}, sb{0, 0};  ///< s_b, the attachment point in b's local frame (m)

  /// @copydoc DistanceSpec::depends_on_time
  /// A pin is time-independent.
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// Both rows of a pin are lengths.
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  /// For a pin: the longer arm, max(|s_a|, |s_b|), of the frames that move. An attachment on a fixed frame
  /// (ground: x, y, ψ all constants) is a position in the plane, not a link dimension: the 10^6-th pivot of a chain
  /// on the ground at (10^6, 0) must not make the model's length scale 10^6 m.
  double characteristic_length() const { return std::max(kin::moving_arm(a, sa), kin::moving_arm(b, sb)); }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Pin
  /// A pin reads x, y (lengths) and ψ (an angle) of frame a, then of frame b.
  template <class F>
  void for_each_slot(F&& f) const {
    f(a.x, Unit::kLength), f(a.y, Unit::kLength), f(a.psi, Unit::kAngle);
    f(b.x, Unit::kLength), f(b.y, Unit::kLength), f(b.psi, Unit::kAngle);
  }
  /// The values its reaction has (ConstraintBlock::reaction_width()): Fx, Fy, Mz of a planar joint.
  static constexpr int kReactionWidth = 3;
  /// The reaction (ReactionSite): on frame a, or on b when a is fixed, at the pin's point (a's attachment point);
  /// its axes that body's.
  ReactionSite reaction_site(const double* q) const {
    const kin::V2 p = kin::V2{a.x.of(q), a.y.of(q)} + kin::rotate(a.psi.of(q), sa);
    ReactionSite site;
    site.point = {p.x, p.y, 0.0};
    site.frame2 = detail::frame_moves(a) ? a : b;
    const double psi = site.frame2.psi.of(q), c = std::cos(psi), s = std::sin(psi);
    site.axes[0] = {c, s, 0.0}, site.axes[1] = {-s, c, 0.0};
    return site;
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    kin::V2 pa = kin::V2{a.x.of(q), a.y.of(q)} + kin::rotate(a.psi.of(q), sa);
    kin::V2 pb = kin::V2{b.x.of(q), b.y.of(q)} + kin::rotate(b.psi.of(q), sb);
    phi[0] = pa.x - pb.x;
    phi[1] = pa.y - pb.y;
  }
  /// @copydoc DistanceSpec::jacobian
  /// @par Pin
  /// A pin emits the ψ entries of an attachment only if its ψ is a coordinate and its arm s is non-zero (decided by
  /// the data, never by q).
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    const bool ra = has_arm(a, sa), rb = has_arm(b, sb);
    kin::V2 ja = ra ? kin::perp(kin::rotate(a.psi.of(q), sa)) : kin::V2{0, 0};
    kin::V2 jb = rb ? kin::perp(kin::rotate(b.psi.of(q), sb)) : kin::V2{0, 0};
    s(0, a.x, 1.0), s(0, b.x, -1.0), s(1, a.y, 1.0), s(1, b.y, -1.0);
    if (ra) s(0, a.psi, ja.x), s(1, a.psi, ja.y);
    if (rb) s(0, b.psi, -jb.x), s(1, b.psi, -jb.y);
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = out[1] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double, double* out) const {
    // d²/dt² R(ψ)s = ψ̈ perp(Rs) − ψ̇² Rs; the ψ̈ part is in Φq q̈.
    double wa = a.psi.rate(qd), wb = b.psi.rate(qd);
    kin::V2 ga = (wa * wa) * kin::rotate(a.psi.of(q), sa);
    kin::V2 gb = (wb * wb) * kin::rotate(b.psi.of(q), sb);
    out[0] = ga.x - gb.x;
    out[1] = ga.y - gb.y;
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the frames' constant slots and the local points.
  static constexpr auto data_members() { return std::tuple{&PinSpec::a, &PinSpec::b, &PinSpec::sa, &PinSpec::sb}; }
  /// Derivatives along the data (DistanceSpec::data_derivative()). Per side, with u = R(ψ) s, u̇ = R(ψ) ṡ, ψ̂ the
  /// rate of a constant ψ, ω = ψ̇ and α = ψ̈ (a side's terms enter a minus b):
  ///
  ///   ∂Φ/∂p: ṙ + u̇ + ψ̂ u⊥,   ∂(Φq q̇)/∂p: ω u̇⊥ − ψ̂ ω u,   ∂(Φq q̈ − γ)/∂p: α u̇⊥ − ω² u̇ − ψ̂ (α u + ω² u⊥).
  void data_derivative(const PinSpec& rate, int order, const double* q, const double* qd, const double* qdd, double,
                       double* out) const {
    const kin::V2 d = detail::point_data_derivative(a, sa, rate.a, rate.sa, order, q, qd, qdd) -
                      detail::point_data_derivative(b, sb, rate.b, rate.sb, order, q, qd, qdd);
    out[0] = d.x, out[1] = d.y;
  }

  /// @copydoc DistanceSpec::joint_count
  /// A pin between bodies or ground is a revolute pair (2 freedoms); with a natural point the count is undefined.
  JointCount joint_count() const { return detail::planar_pair_joint_count(a, b); }
  /// @copydoc DistanceSpec::prepare
  void prepare(const double* /*q0*/) const {
    detail::require(std::isfinite(sa.x) && std::isfinite(sa.y) && std::isfinite(sb.x) && std::isfinite(sb.y),
                    "pin: attachment point is not finite");
  }
  /// @copydoc DistanceSpec::sketch
  /// A pin draws the arms of the bodies it joins, and a pivot where they meet (on ground when a side is ground).
  template <class Sketch>
  void sketch(Sketch& sk) const {
    sk.arm(a, sa);
    sk.arm(b, sb);
    sk.pivot(a, sa, b, sb);
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {
      {"constraints", "revolute", 2,
       "- {name: A, type: revolute, between: [{body: crank, at: [0.2, 0]}, "
       "{body: coupler, at: [-0.6, 0]}]}"},
      {"constraints", "fixed_point", 2, "- {name: pin, type: fixed_point, point: P, at: [0.5, 0]}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static PinSpec read(const Fields& f) {
    if (f.type() == "fixed_point") {
      f.expect({"type", "name", "point", "at"});
      const Point2 p = f.point("point");
      const kin::V2 at = f.vec2("at");
      return PinSpec{Frame2{p.x, p.y, Slot::constant(0)},
                     Frame2{Slot::constant(at.x), Slot::constant(at.y), Slot::constant(0)},
                     {0, 0},
                     {0, 0}};
    }
    f.expect({"type", "name", "between"});
    const auto [ea, eb] = f.attachments("between", "a revolute joins two attachments");
    return PinSpec{ea.frame, eb.frame, ea.at, eb.at};
  }

 private:
  /// @cond internal
  /// Whether the attachment turns with a coordinate: then Φ depends on its ψ.
  static bool has_arm(const Frame2& f, kin::V2 s) { return f.psi.is_coordinate() && (s.x != 0.0 || s.y != 0.0); }
  /// @endcond
};

}  // namespace phiq
