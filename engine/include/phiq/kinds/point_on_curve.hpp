/// @file
/// A point of one body on a curve fixed in another (or in the ground): a pin in a curved slot, and the knife-edge
/// and roller followers of a cam. One constraint kind: its equation, derivatives, validation, joint count, sketch
/// and scene forms (the contract is documented on DistanceSpec; kinds/registry.hpp lists every kind).
#pragma once

#include <cmath>
#include <memory>
#include <string>

#include "phiq/kinds/curve.hpp"
#include "phiq/kinds/reaction_site.hpp"

namespace phiq {

/// Point P_a = r_a + R(ψ_a) s_a of attachment a on the curve p(s) carried by frame b, offset by ρ along its normal:
///   Φ = r_a + R(ψ_a) s_a − r_b − R(ψ_b) p(s),    p(s) = c(s) + ρ n(s),  n = −perp(c′) / |c′|     (2 rows, lengths)
/// s is a coordinate the model adds (ModelBuilder::add names it "NAME.s"; kAddedCoordinates), its initial guess the
/// parameter of the curve's point nearest to P_a at the placement. ρ = 0: a pin in a slot, a knife-edge follower;
/// ρ > 0: a roller of radius ρ, whose centre runs on the offset curve (on the right of the direction of travel of
/// c: the outside of a counter-clockwise closed profile, as circles and radius tables are). With u = c′/|c′| and
/// κ = c′ × c″ / |c′|² (the turn of the tangent per unit s), n′ = κ u and n″ = κ′ u − κ² n: p″ needs c‴.
struct PointOnCurveSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const PointOnCurveSpec&) const = default;
  static constexpr int kRows = 2;  ///< two rows: x and y of the gap between the point and the curve's point
  /// @copydoc DistanceSpec::kKind
  /// Scenes write it `point_on_curve` (a point or a pin in a slot) or `cam` (a knife-edge or roller follower).
  static constexpr const char* kKind = "point_on_curve";
  /// The coordinates the model adds with the constraint, named "NAME.<suffix>": the curve parameter s (m).
  static constexpr const char* kAddedCoordinates[] = {"s"};
  /// @var a
  /// @brief Frame of the point: a body (x, y in m, ψ in rad), a natural point (ψ constant, sa = 0) or ground.
  Frame2 a;
  kin::V2 sa{0, 0};     ///< s_a, the point in a's local frame (m)
  CurveOn on;           ///< the curve and the frame b that carries it
  double offset = 0.0;  ///< ρ, the roller's radius (m); 0 for a knife edge or a pin
  Slot s;               ///< the curve parameter (m along the curve): the added coordinate

  /// @copydoc DistanceSpec::depends_on_time
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  /// For a point on a curve: the point's arm and the curve's reach when they move, and the roller's radius.
  double characteristic_length() const {
    const double reach = on.curve ? kin::moving_arm(on.frame, {on.curve->reach(), 0.0}) : 0.0;
    return std::max({kin::moving_arm(a, sa), reach, std::fabs(offset)});
  }
  /// @copydoc DistanceSpec::for_each_slot
  /// A point on a curve reads the frames of the point and the curve, and s (a length).
  template <class F>
  void for_each_slot(F&& f) const {
    f(a.x, Unit::kLength), f(a.y, Unit::kLength), f(a.psi, Unit::kAngle);
    f(on.frame.x, Unit::kLength), f(on.frame.y, Unit::kLength), f(on.frame.psi, Unit::kAngle);
    f(s, Unit::kLength);
  }
  /// The values its reaction has (ConstraintBlock::reaction_width()): Fx, Fy, Mz of a planar joint.
  static constexpr int kReactionWidth = 3;
  /// The reaction (ReactionSite): the slot's or the cam's force on the point's frame a, or on the curve's when a is
  /// fixed, at the point (a roller's centre: on the force's line); its axes x along the curve, y along its normal.
  /// (With the multipliers of a sweep, whose row of s balances, the force is along the normal: a frictionless
  /// contact.)
  ReactionSite reaction_site(const double* q) const {
    const Geometry g = geometry(q);
    ReactionSite site;
    site.point = {g.pa.x, g.pa.y, 0.0};
    site.frame2 = detail::frame_moves(a) ? a : on.frame;
    const double n = std::hypot(g.dp.x, g.dp.y);
    if (n > 0.0) site.axes[0] = {g.dp.x / n, g.dp.y / n, 0.0}, site.axes[1] = {-g.dp.y / n, g.dp.x / n, 0.0};
    return site;
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    const Geometry g = geometry(q);
    phi[0] = g.pa.x - g.q.x, phi[1] = g.pa.y - g.q.y;
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& k) const {
    const Geometry g = geometry(q);
    const Frame2& b = on.frame;
    k(0, a.x, 1.0), k(1, a.y, 1.0), k(0, b.x, -1.0), k(1, b.y, -1.0);
    if (has_arm()) {
      const kin::V2 j = kin::perp(g.arm_a);
      k(0, a.psi, j.x), k(1, a.psi, j.y);
    }
    const kin::V2 jb = kin::perp(g.p), js = g.dp;  // ∂/∂ψ_b = −perp(R_b p), ∂/∂s = −R_b p′
    k(0, b.psi, -jb.x), k(1, b.psi, -jb.y);
    k(0, s, -js.x), k(1, s, -js.y);
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = out[1] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  /// The q̈-free part of d²/dt² R_b p(s): −ψ̇_b² R_b p + 2 ψ̇_b ṡ perp(R_b p′) + ṡ² R_b p″.
  void gamma(const double* q, const double* qd, double, double* out) const {
    const Geometry g = geometry(q);
    const double wa = a.psi.rate(qd), wb = on.frame.psi.rate(qd), sd = s.rate(qd);
    const kin::V2 ga = (wa * wa) * g.arm_a;
    const kin::V2 gb = (-wb * wb) * g.p + (2.0 * wb * sd) * kin::perp(g.dp) + (sd * sd) * g.ddp;
    out[0] = ga.x + gb.x, out[1] = ga.y + gb.y;
  }

  /// The data a parameter may move (DistanceSpec::data_members()): the point's frame (its constant slots) and
  /// local point, the curve's frame and the roller's radius. The curve itself is no datum: where a parameter changes
  /// its shape (a radius, a profile's points) the constraint is differenced, s moving with the curve's length.
  static constexpr auto data_members() {
    return std::tuple{&PointOnCurveSpec::a, &PointOnCurveSpec::sa, &PointOnCurveSpec::on, &PointOnCurveSpec::offset};
  }
  /// Derivatives along the data (DistanceSpec::data_derivative()). With P = R_b p(s) and N = R_b n(s), carried by
  /// frame b along the curve (their time derivatives in detail::carried_along_curve()), ψ̂_b and r̂_b the rates of
  /// b's constant slots, ρ̂ the radius's, and P̂_a the point's (detail::point_data_derivative()):
  ///
  ///   ∂Φ/∂p = P̂_a − r̂_b − ψ̂_b P⊥ − ρ̂ N,   and its time derivatives: P̂_a⁽ᵏ⁾ − ψ̂_b P⁽ᵏ⁾⊥ − ρ̂ N⁽ᵏ⁾ (k = 1, 2).
  void data_derivative(const PointOnCurveSpec& rate, int order, const double* q, const double* qd, const double* qdd,
                       double, double* out) const {
    const Frame2& b = on.frame;
    const double psid = rate.on.frame.psi.of(q), rhod = rate.offset;
    kin::V2 d = detail::point_data_derivative(a, sa, rate.a, rate.sa, order, q, qd, qdd);
    if (order == 0) d = d - kin::V2{rate.on.frame.x.of(q), rate.on.frame.y.of(q)};
    const double at = s.of(q), pb = b.psi.of(q);
    const double w = order >= 1 ? b.psi.rate(qd) : 0.0, sd = order >= 1 ? s.rate(qd) : 0.0;
    const double al = order == 2 ? b.psi.rate(qdd) : 0.0, sdd = order == 2 ? s.rate(qdd) : 0.0;
    auto carried = [&](const kin::V2 v[3]) {  // the order-th time derivative of R_b v(s)
      const kin::V2 world[3] = {kin::rotate(pb, v[0]), kin::rotate(pb, v[1]), kin::rotate(pb, v[2])};
      kin::V2 out3[3];
      detail::carried_along_curve(world, w, al, sd, sdd, out3);
      return out3[order];
    };
    if (psid != 0.0 || rhod != 0.0) {
      kin::V2 p[3], n[3];
      detail::offset_curve(*on.curve, at, offset, p, n);
      if (psid != 0.0) d = d - psid * kin::perp(carried(p));
      if (rhod != 0.0) d = d - rhod * carried(n);
    }
    out[0] = d.x, out[1] = d.y;
  }

  /// @copydoc DistanceSpec::joint_count
  /// A higher pair between bodies or ground: 2 rows and 1 added coordinate remove 1 freedom.
  JointCount joint_count() const {
    if (!kin::body_or_ground(a) || !kin::body_or_ground(on.frame)) return JointCount::other();
    return JointCount::joint(2, 1);
  }
  /// @copydoc DistanceSpec::prepare
  void prepare(const double* /*q0*/) const {
    detail::require(on.curve != nullptr, "point_on_curve: no curve");
    detail::require(std::isfinite(sa.x) && std::isfinite(sa.y), "point_on_curve: attachment point is not finite");
    detail::require(std::isfinite(offset), "point_on_curve: the roller's radius is not finite");
  }
  /// The initial guess of added coordinate i (s): the parameter of the curve's point nearest to P_a at q0.
  double added_initial(int, const double* q0) const {
    const kin::V2 pa = kin::V2{a.x.of(q0), a.y.of(q0)} + kin::rotate(a.psi.of(q0), sa);
    const double psi = on.frame.psi.of(q0);
    const kin::V2 local = kin::rotate(-psi, pa - kin::V2{on.frame.x.of(q0), on.frame.y.of(q0)});
    // the roller's centre is ρ off the curve: its nearest point on the curve is the contact's (for ρ below the
    // radius of curvature)
    return on.curve->nearest(local);
  }
  /// Added coordinate i's slot (ModelBuilder::add binds it).
  Slot& added(int) { return s; }
  /// @copydoc added
  const Slot& added(int) const { return s; }
  /// The length added coordinate i is measured in proportion to: the curve's length (its period when closed). When
  /// a design parameter changes the curve (a radius, a profile's points), the same contact point keeps s / length,
  /// not s: the sensitivities move s so as they difference along the parameter (ParameterReach::comotion), where
  /// s itself would sweep through the curve s / length times faster than the parameter changes it.
  double added_scale(int) const { return on.curve->length(); }
  /// "" while s is on the curve; on an open curve past an end, what happened (Model::outside_domain).
  std::string outside_domain(const double* q) const { return detail::outside_curve(*on.curve, s.of(q)); }
  /// @copydoc DistanceSpec::sketch
  /// A point on a curve draws the point's arm (the mechanism's sketch has no curves), and on the parts the slot or
  /// profile on its body and a roller of radius ρ.
  template <class Sketch>
  void sketch(Sketch& sk) const {
    sk.arm(a, sa);
    sk.curve(on);
    if (offset > 0.0) sk.roller(a, sa, offset);
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {
      {"constraints", "point_on_curve", 2,
       "- {name: slot, type: point_on_curve, point: {body: slider, at: [0, 0]}, curve: {body: ground, spline: "
       "[[0, 0], [1, 0.5], [2, 0.4], [3, 0]]}}"},
      {"constraints", "cam", 2,
       "- {name: cam, type: cam, cam: {body: disc, circle: {centre: [0.02, 0], radius: 0.05}}, follower: {body: "
       "rod, at: [0, 0]}, roller: 0.01}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static PointOnCurveSpec read(const Fields& f) {
    if (f.type() == "cam") {
      f.expect({"type", "name", "cam", "follower", "roller"});
      const auto follower = f.attachment("follower");
      PointOnCurveSpec spec{follower.frame, follower.at, detail::read_curve(f, "cam"), 0.0, Slot()};
      if (f.present("roller")) spec.offset = f.positive("roller");
      return spec;
    }
    f.expect({"type", "name", "point", "curve", "offset"});
    const auto point = f.attachment("point");
    PointOnCurveSpec spec{point.frame, point.at, detail::read_curve(f, "curve"), 0.0, Slot()};
    if (f.present("offset")) spec.offset = f.number("offset");
    return spec;
  }

 private:
  /// @cond internal
  /// At q: the point's arm R_a s_a and position P_a, the curve's point in the world Q = r_b + R_b p, and the
  /// world vectors R_b p, R_b p′, R_b p″.
  struct Geometry {
    kin::V2 arm_a, pa, p, dp, ddp, q;
  };
  Geometry geometry(const double* q) const {
    kin::V2 d[3];
    detail::offset_curve(*on.curve, s.of(q), offset, d);
    const double pb = on.frame.psi.of(q);
    Geometry g;
    g.arm_a = kin::rotate(a.psi.of(q), sa);
    g.pa = kin::V2{a.x.of(q), a.y.of(q)} + g.arm_a;
    g.p = kin::rotate(pb, d[0]), g.dp = kin::rotate(pb, d[1]), g.ddp = kin::rotate(pb, d[2]);
    g.q = kin::V2{on.frame.x.of(q), on.frame.y.of(q)} + g.p;
    return g;
  }
  bool has_arm() const { return a.psi.is_coordinate() && (sa.x != 0.0 || sa.y != 0.0); }
  /// @endcond
};

}  // namespace phiq
