/// @file
/// A flat-faced cam follower: the follower's face, a line of one body, touches a convex curve of another (the cam)
/// with matching normal. One constraint kind: its equation, derivatives, validation, joint count, sketch and scene
/// form (the contract is documented on DistanceSpec; kinds/registry.hpp lists every kind).
#pragma once

#include <array>
#include <cmath>
#include <memory>
#include <string>

#include "phiq/kinds/curve.hpp"
#include "phiq/kinds/reaction_site.hpp"

namespace phiq {

/// The face of follower a, the line through P_a = r_a + R(ψ_a) s_a along e = R(ψ_a) u (u a unit vector in a's
/// frame), touches the curve c(s) carried by frame b at Q = r_b + R(ψ_b) c(s), tangent to it there:
///   Φ0 = e × (Q − P_a)              (Q on the face: a length)
///   Φ1 = e × R(ψ_b) c′(s)           (the curve's tangent along the face: the sine of their angle, |c′| ≈ 1)
/// s is a coordinate the model adds ("NAME.s"), its initial guess the point of the curve farthest towards the
/// face (the support point of the profile in the direction of the face's normal that points away from the
/// profile's centre), which is the contact of a convex profile. The profile must be convex (checked when the
/// constraint is added): a flat face touches a concave stretch at no single point. A translating follower is a
/// body on a prismatic pair, an oscillating one a body on a revolute; the face is the same.
struct FlatFollowerSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const FlatFollowerSpec&) const = default;
  static constexpr int kRows = 2;  ///< Φ0, the contact point's distance from the face; Φ1, the tangency
  /// @copydoc DistanceSpec::kKind
  /// Scene type `flat_cam`.
  static constexpr const char* kKind = "flat_cam";
  /// @copydoc PointOnCurveSpec::kAddedCoordinates
  static constexpr const char* kAddedCoordinates[] = {"s"};
  /// @var a
  /// @brief Frame of the follower, which carries the face (x, y in m, ψ in rad).
  Frame2 a;
  kin::V2 sa{0, 0};    ///< s_a, a point of the face in a's frame (m)
  kin::V2 axis{1, 0};  ///< u, the face's direction in a's frame; normalised when the constraint is added
  CurveOn on;          ///< the cam's profile and the frame b that carries it
  Slot s;              ///< the contact's curve parameter (m along the profile): the added coordinate

  /// @copydoc DistanceSpec::depends_on_time
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// Row 0 is a length, row 1 the sine of an angle (an angle near the solution).
  Unit row_unit(int row, const std::vector<Unit>&) const { return row == 0 ? Unit::kLength : Unit::kAngle; }
  /// @copydoc DistanceSpec::characteristic_length
  /// For a flat follower: the face point's arm and the profile's reach, where they move.
  double characteristic_length() const {
    const double reach = on.curve ? kin::moving_arm(on.frame, {on.curve->reach(), 0.0}) : 0.0;
    return std::max(kin::moving_arm(a, sa), reach);
  }
  /// @copydoc DistanceSpec::for_each_slot
  template <class F>
  void for_each_slot(F&& f) const {
    f(a.x, Unit::kLength), f(a.y, Unit::kLength), f(a.psi, Unit::kAngle);
    f(on.frame.x, Unit::kLength), f(on.frame.y, Unit::kLength), f(on.frame.psi, Unit::kAngle);
    f(s, Unit::kLength);
  }
  /// The values its reaction has (ConstraintBlock::reaction_width()): Fx, Fy, Mz of a planar joint.
  static constexpr int kReactionWidth = 3;
  /// The reaction (ReactionSite): the cam's force on the follower a, or on the cam's frame when a is fixed, at the
  /// contact point Q; its axes x along the face, y across it (the face carries no force along itself).
  ReactionSite reaction_site(const double* q) const {
    const Geometry g = geometry(q);
    const kin::V2 contact = kin::V2{on.frame.x.of(q), on.frame.y.of(q)} + g.c;
    ReactionSite site;
    site.point = {contact.x, contact.y, 0.0};
    site.frame2 = detail::frame_moves(a) ? a : on.frame;
    site.axes[0] = {g.e.x, g.e.y, 0.0}, site.axes[1] = {-g.e.y, g.e.x, 0.0};
    return site;
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    const Geometry g = geometry(q);
    phi[0] = kin::cross(g.e, g.h);
    phi[1] = kin::cross(g.e, g.w);
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& k) const {
    const Geometry g = geometry(q);
    const Frame2& b = on.frame;
    // Φ0: ∂e/∂ψa = perp(e), h = Q − P_a moves with r_b, ψ_b (perp(R_b c)), s (w) and against r_a, ψ_a
    k(0, a.x, g.e.y), k(0, a.y, -g.e.x), k(0, b.x, -g.e.y), k(0, b.y, g.e.x);
    k(0, a.psi, -kin::dot(g.e, g.h + g.arm_a)), k(0, b.psi, kin::dot(g.e, g.c)), k(0, s, kin::cross(g.e, g.w));
    // Φ1: the relative rotation turns e against w; s moves w by R_b c″
    k(1, a.psi, -kin::dot(g.e, g.w)), k(1, b.psi, kin::dot(g.e, g.w)), k(1, s, kin::cross(g.e, g.w2));
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = out[1] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  /// Φ̈ = ë × h + 2 ė × ḣ + e × ḧ (and with w for Φ1), less its q̈ terms: ë → −ψ̇a² e; ḧ → −ψ̇b² R_b c +
  /// 2 ψ̇b ṡ perp(w) + ṡ² R_b c″ + ψ̇a² R_a s_a; ẅ → −ψ̇b² w + 2 ψ̇b ṡ perp(R_b c″) + ṡ² R_b c‴.
  void gamma(const double* q, const double* qd, double, double* out) const {
    const Geometry g = geometry(q);
    const Frame2& b = on.frame;
    const double wa = a.psi.rate(qd), wb = b.psi.rate(qd), sd = s.rate(qd);
    const kin::V2 ed = wa * kin::perp(g.e);
    const kin::V2 hd = kin::V2{b.x.rate(qd), b.y.rate(qd)} + wb * kin::perp(g.c) + sd * g.w -
                       kin::V2{a.x.rate(qd), a.y.rate(qd)} - wa * kin::perp(g.arm_a);
    const kin::V2 hdd = (-wb * wb) * g.c + (2.0 * wb * sd) * kin::perp(g.w) + (sd * sd) * g.w2 + (wa * wa) * g.arm_a;
    const kin::V2 wd = wb * kin::perp(g.w) + sd * g.w2;
    const kin::V2 wdd = (-wb * wb) * g.w + (2.0 * wb * sd) * kin::perp(g.w2) + (sd * sd) * g.w3;
    out[0] = -(-wa * wa * kin::cross(g.e, g.h) + 2.0 * kin::cross(ed, hd) + kin::cross(g.e, hdd));
    out[1] = -(-wa * wa * kin::cross(g.e, g.w) + 2.0 * kin::cross(ed, wd) + kin::cross(g.e, wdd));
  }

  /// The data a parameter may move (DistanceSpec::data_members()): the follower's frame (its constant slots), the
  /// face's point and direction (as normalised), and the cam's frame. The profile itself is no datum: where a
  /// parameter changes its shape the constraint is differenced (PointOnCurveSpec::data_members()).
  static constexpr auto data_members() {
    return std::tuple{&FlatFollowerSpec::a, &FlatFollowerSpec::sa, &FlatFollowerSpec::axis, &FlatFollowerSpec::on};
  }
  /// Derivatives along the data (DistanceSpec::data_derivative()): Φ0 = e × h and Φ1 = e × w are products, so
  /// their k-th time derivatives along p are Σᵢ C(k, i) (ê⁽ⁱ⁾ × h⁽ᵏ⁻ⁱ⁾ + e⁽ⁱ⁾ × ĥ⁽ᵏ⁻ⁱ⁾), and alike with w, where
  /// ê = R_a û + ψ̂_a e⊥ (detail::turned_data_derivative()), ĥ = r̂_b + ψ̂_b C⊥ − P̂_a with C = R_b c(s), and
  /// ŵ = ψ̂_b w⊥; C, w and their time derivatives are carried by b along the profile (detail::carried_along_curve()).
  void data_derivative(const FlatFollowerSpec& rate, int order, const double* q, const double* qd, const double* qdd,
                       double, double* out) const {
    const Geometry g = geometry(q);
    const Frame2& b = on.frame;
    const double wa = order >= 1 ? a.psi.rate(qd) : 0.0, wb = order >= 1 ? b.psi.rate(qd) : 0.0;
    const double sd = order >= 1 ? s.rate(qd) : 0.0;
    const double aa = order == 2 ? a.psi.rate(qdd) : 0.0, ab = order == 2 ? b.psi.rate(qdd) : 0.0;
    const double sdd = order == 2 ? s.rate(qdd) : 0.0;
    // the motion: e, the arm R_a s_a, C, w and h = r_b + C − r_a − R_a s_a, with their first two time derivatives
    auto turning = [&](const kin::V2& v, double w, double al) {
      return std::array<kin::V2, 3>{v, w * kin::perp(v), al * kin::perp(v) - (w * w) * v};
    };
    const std::array<kin::V2, 3> e = turning(g.e, wa, aa), arm = turning(g.arm_a, wa, aa);
    kin::V2 c[3], w[3];
    const kin::V2 cv[3] = {g.c, g.w, g.w2}, wv[3] = {g.w, g.w2, g.w3};
    detail::carried_along_curve(cv, wb, ab, sd, sdd, c);
    detail::carried_along_curve(wv, wb, ab, sd, sdd, w);
    auto translation_rate = [&](const Frame2& f, int k) {  // ṙ (k = 1) or r̈ (k = 2) of a frame's origin
      const double* v = k == 1 ? qd : qdd;
      return kin::V2{f.x.rate(v), f.y.rate(v)};
    };
    std::array<kin::V2, 3> h{}, eh{}, hh{}, wh{};
    const double psid_b = rate.on.frame.psi.of(q);
    h[0] = g.h;
    for (int k = 0; k <= order; ++k) {
      if (k > 0) h[k] = translation_rate(b, k) + c[k] - translation_rate(a, k) - arm[k];
      eh[k] = detail::turned_data_derivative(a.psi, axis, rate.a.psi, rate.axis, k, q, qd, qdd);
      hh[k] = psid_b * kin::perp(c[k]) - detail::point_data_derivative(a, sa, rate.a, rate.sa, k, q, qd, qdd);
      wh[k] = psid_b * kin::perp(w[k]);
    }
    hh[0] = hh[0] + kin::V2{rate.on.frame.x.of(q), rate.on.frame.y.of(q)};
    double d0 = 0.0, d1 = 0.0;
    for (int i = 0; i <= order; ++i) {
      const double m = detail::kBinomial[order][i];
      d0 += m * (kin::cross(eh[i], h[order - i]) + kin::cross(e[i], hh[order - i]));
      d1 += m * (kin::cross(eh[i], w[order - i]) + kin::cross(e[i], wh[order - i]));
    }
    out[0] = d0, out[1] = d1;
  }

  /// @copydoc DistanceSpec::joint_count
  /// A higher pair between bodies or ground: 2 rows and 1 added coordinate remove 1 freedom.
  JointCount joint_count() const {
    if (!kin::body_or_ground(a) || !kin::body_or_ground(on.frame)) return JointCount::other();
    return JointCount::joint(2, 1);
  }
  /// @copydoc DistanceSpec::prepare
  /// The face's direction is normalised here, and the profile checked for convexity.
  void prepare(const double* /*q0*/) {
    detail::require(on.curve != nullptr, "flat_cam: no profile");
    const double n = std::hypot(axis.x, axis.y);
    detail::require(std::isfinite(n) && n > 0.0, "flat_cam: the face's direction must be a non-zero finite vector");
    axis = (1.0 / n) * axis;
    detail::require(std::isfinite(sa.x) && std::isfinite(sa.y), "flat_cam: the face's point is not finite");
    detail::require(on.curve->convex(),
                    "flat_cam: the profile is not convex (it turns both ways): a flat face "
                    "would touch it at more than one point");
  }
  /// @copydoc PointOnCurveSpec::added_initial
  /// For a flat follower: the profile's point farthest towards the face, in the direction of the face's normal
  /// that points from the profile's centre (its frame's origin) to the face.
  double added_initial(int, const double* q0) const {
    const double pb = on.frame.psi.of(q0);
    const kin::V2 e = kin::rotate(-pb, kin::rotate(a.psi.of(q0), axis));
    const kin::V2 pa = kin::V2{a.x.of(q0), a.y.of(q0)} + kin::rotate(a.psi.of(q0), sa);
    const kin::V2 local = kin::rotate(-pb, pa - kin::V2{on.frame.x.of(q0), on.frame.y.of(q0)});
    kin::V2 m = kin::perp(e);
    if (kin::dot(m, local) < 0.0) m = -1.0 * m;
    return on.curve->extreme(m);
  }
  /// @copydoc PointOnCurveSpec::added
  Slot& added(int) { return s; }
  /// @copydoc PointOnCurveSpec::added
  const Slot& added(int) const { return s; }
  /// @copydoc PointOnCurveSpec::added_scale
  double added_scale(int) const { return on.curve->length(); }
  /// @copydoc PointOnCurveSpec::outside_domain
  std::string outside_domain(const double* q) const { return detail::outside_curve(*on.curve, s.of(q)); }
  /// @copydoc DistanceSpec::sketch
  /// A flat follower draws the arm of its face's point (the mechanism's sketch has no curves), and on the parts the
  /// profile on its body and the face.
  template <class Sketch>
  void sketch(Sketch& sk) const {
    sk.arm(a, sa);
    sk.curve(on);
    sk.face(a, sa, axis);
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {
      {"constraints", "flat_cam", 2,
       "- {name: cam, type: flat_cam, cam: {body: disc, circle: {centre: [0.02, 0], radius: 0.05}}, follower: "
       "{body: rod, at: [0, 0], direction: [1, 0]}}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static FlatFollowerSpec read(const Fields& f) {
    f.expect({"type", "name", "cam", "follower"});
    const Fields face = f.sub("follower");
    face.expect({"body", "at", "direction"});
    FlatFollowerSpec spec{face.body("body"), {0, 0}, {1, 0}, detail::read_curve(f, "cam"), Slot()};
    if (face.present("at")) spec.sa = face.vec2("at");
    if (face.present("direction")) spec.axis = face.vec2("direction");
    if (spec.axis.x == 0.0 && spec.axis.y == 0.0) face.fail("direction", "the face's direction must not be zero");
    return spec;
  }

 private:
  /// @cond internal
  /// At q: e = R_a u, arm_a = R_a s_a, h = Q − P_a, and the world vectors c = R_b c(s), w = R_b c′, w2 = R_b c″,
  /// w3 = R_b c‴.
  struct Geometry {
    kin::V2 e, arm_a, h, c, w, w2, w3;
  };
  Geometry geometry(const double* q) const {
    kin::V2 d[4];
    on.curve->evaluate(s.of(q), d);
    const double pa = a.psi.of(q), pb = on.frame.psi.of(q);
    Geometry g;
    g.e = kin::rotate(pa, axis);
    g.arm_a = kin::rotate(pa, sa);
    g.c = kin::rotate(pb, d[0]), g.w = kin::rotate(pb, d[1]), g.w2 = kin::rotate(pb, d[2]);
    g.w3 = kin::rotate(pb, d[3]);
    g.h = kin::V2{on.frame.x.of(q), on.frame.y.of(q)} + g.c - kin::V2{a.x.of(q), a.y.of(q)} - g.arm_a;
    return g;
  }
  /// @endcond
};

}  // namespace phiq
