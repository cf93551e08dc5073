/// @file
/// Mixed coordinates in space (the notes' "combinación de coordenadas", 7.2, in 3D): a natural point at an angle on
/// a circle about an axis (the 3D `polar`), and an angle coordinate measuring the turn of a direction about an axis —
/// a segment of natural points (the 3D `segment_angle`) or a body's own direction (`rotation_angle`, the angle of a
/// shaft that gears, belts and racks relate: kinds/transmissions.hpp, kinds/spatial_gear.hpp). Two constraint kinds,
/// each with its equation, derivatives, validation, joint count, sketch and scene forms; the contract is documented
/// on DistanceSpec, and kinds/registry.hpp lists every kind.
///
/// The axis is a side as joints write it (JointSide3): a body or ground, a point `at`, an axis z and a reference
/// direction x ⟂ z in its frame (y = z × x); angles are measured about z from x.
#pragma once

#include <cmath>
#include <array>
#include <string>
#include <tuple>

#include "phiq/kinds/spatial_joints.hpp"
#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// 3D polar (mixed coordinates: a crank's tip at angle θ in space): the natural point P on the circle of radius r
/// about the axis of side a (centre P_a, axis z_a), at angle θ from x_a:
///   Φ = P − P_a − r (cos θ x_a + sin θ y_a)          (3 rows, lengths)
/// Φq: ∂P − ∂P_a − r (cos θ ∂x_a + sin θ ∂y_a), and r (sin θ x_a − cos θ y_a) on θ. γ = −(the q̈-free part of Φ̈):
/// the attachments' own (2 R(ṗ) s), and 2 r θ̇ (−sin θ ẋ_a + cos θ ẏ_a) − r θ̇² (cos θ x_a + sin θ y_a) from θ.
/// Scene type `polar` (dimension 3): `point: P`, `center: {body: B, at, axis, ref}` (ground by default),
/// `radius: r` (≠ 0), `angle: θ` (a coordinate or a constant).
struct SpatialPolarSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const SpatialPolarSpec&) const = default;

 private:
  // rows k: (P_b − P_a)_k, (x_a)_k, (y_a)_k
  static constexpr detail3::RowDef kDefs[9] = {
      {detail3::Axis(0), detail3::T(detail3::kPb, detail3::kPa), Unit::kLength},
      {detail3::Axis(1), detail3::T(detail3::kPb, detail3::kPa), Unit::kLength},
      {detail3::Axis(2), detail3::T(detail3::kPb, detail3::kPa), Unit::kLength},
      {detail3::Axis(0), detail3::T(detail3::kXa), Unit::kNone},
      {detail3::Axis(1), detail3::T(detail3::kXa), Unit::kNone},
      {detail3::Axis(2), detail3::T(detail3::kXa), Unit::kNone},
      {detail3::Axis(0), detail3::T(detail3::kYa), Unit::kNone},
      {detail3::Axis(1), detail3::T(detail3::kYa), Unit::kNone},
      {detail3::Axis(2), detail3::T(detail3::kYa), Unit::kNone}};

 public:
  static constexpr int kRows = 3;  ///< x, y and z of the gap, lengths
  /// @copydoc DistanceSpec::kKind
  static constexpr const char* kKind = "polar3";
  JointSide3 center;    ///< the circle's centre `at` and axis z (angles from x) in a body or ground
  Point3 point;         ///< P, the natural point on the circle
  double radius = 1.0;  ///< r (m), finite and non-zero
  Slot theta;           ///< θ (rad): a coordinate or a constant
  /// The rows' attachments and the rows renumbered into them (detail3::compact_rows).
  static constexpr auto kCompact = detail3::compact_rows(kDefs);
  std::array<Attachment3, kCompact.count> att{};  ///< derived by setup()

  /// Validates the data and derives `att`. Throws phiq::Error.
  void setup() {
    detail::require(std::isfinite(radius), "polar: radius is not finite");
    detail::require(radius != 0.0, "polar: the radius is zero (the angle would be undetermined)");
    detail3::set_up_attachments(center, JointSide3::natural_point(point), kCompact, "polar", att);
  }
  /// @copydoc DistanceSpec::depends_on_time
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  double characteristic_length() const { return std::fabs(radius); }
  /// @copydoc DistanceSpec::for_each_slot
  template <class F>
  void for_each_slot(F&& f) const {
    detail3::side_slots(center, f);
    f(point.x, Unit::kLength), f(point.y, Unit::kLength), f(point.z, Unit::kLength), f(theta, Unit::kAngle);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    const double th = theta.of(q), rc = radius * std::cos(th), rs = radius * std::sin(th);
    for (int k = 0; k < 3; ++k) phi[k] = value(k, q) - rc * value(3 + k, q) - rs * value(6 + k, q);
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    const double th = theta.of(q), rc = radius * std::cos(th), rs = radius * std::sin(th);
    const Attachment3* a = att.data();
    for (int k = 0; k < 3; ++k) {
      detail3::row_jacobian(a, kCompact.rows[k], q, s, k, 1.0);
      detail3::row_jacobian(a, kCompact.rows[3 + k], q, s, k, -rc);
      detail3::row_jacobian(a, kCompact.rows[6 + k], q, s, k, -rs);
      s(k, theta, rs * value(3 + k, q) - rc * value(6 + k, q));
    }
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = out[1] = out[2] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double, double* out) const {
    const double th = theta.of(q), w = theta.rate(qd), rc = radius * std::cos(th), rs = radius * std::sin(th);
    const Attachment3* a = att.data();
    for (int k = 0; k < 3; ++k) {
      const detail3::RowDef &dp = kCompact.rows[k], &dx = kCompact.rows[3 + k], &dy = kCompact.rows[6 + k];
      const double xd = detail3::row_rate(a, dx, q, qd, 1.0), yd = detail3::row_rate(a, dy, q, qd, 1.0);
      out[k] = detail3::row_gamma(a, dp, q, qd, 1.0) + detail3::row_gamma(a, dx, q, qd, -rc) +
               detail3::row_gamma(a, dy, q, qd, -rs) + 2.0 * w * (-rs * xd + rc * yd) -
               w * w * (rc * value(3 + k, q) + rs * value(6 + k, q));
    }
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the centre's side and the point through the
  /// attachments, the radius, and a constant θ.
  static constexpr auto data_members() {
    return std::tuple{&SpatialPolarSpec::center, &SpatialPolarSpec::point, &SpatialPolarSpec::radius,
                      &SpatialPolarSpec::theta, &SpatialPolarSpec::att};
  }
  /// Derivatives along the data (DistanceSpec::data_derivative()). Row k is V − ρc X − ρs Y (V = P − P_a, X = x_a,
  /// Y = y_a, their k-th components; ρc = r cos θ, ρs = r sin θ), so with Leibniz's rule
  ///   Φ⁽ⁿ⁾ = V⁽ⁿ⁾ − Σ_i C(n, i) (ρc⁽ⁱ⁾ X⁽ⁿ⁻ⁱ⁾ + ρs⁽ⁱ⁾ Y⁽ⁿ⁻ⁱ⁾),   ρc′ = −ω ρs, ρs′ = ω ρc, ρc″ = −ω² ρc − α ρs,
  /// ρs″ = −ω² ρs + α ρc; along the data V̂, X̂, Ŷ come from the attachments (detail3::row_derivatives(), one pass
  /// a row) and (ρ̂c, ρ̂s) = (r̂/r) (ρc, ρs) + θ̂ (−ρs, ρc) (θ̂ of a constant θ), their time derivatives by the same
  /// rule.
  void data_derivative(const SpatialPolarSpec& rate, int order, const double* q, const double* qd, const double* qdd,
                       double, double* out) const {
    const double th = theta.of(q), w = order >= 1 ? theta.rate(qd) : 0.0, al = order == 2 ? theta.rate(qdd) : 0.0;
    const double rc = radius * std::cos(th), rs = radius * std::sin(th);
    const double thh = theta.is_coordinate() ? 0.0 : rate.theta.value(), rr = rate.radius / radius;
    // (ρc, ρs) and their first two time derivatives, for the values and for their rates along the data
    auto motion = [&](double c, double s, double mc[3], double ms[3]) {
      mc[0] = c, ms[0] = s;
      mc[1] = -w * s, ms[1] = w * c;
      mc[2] = -w * w * c - al * s, ms[2] = -w * w * s + al * c;
    };
    double mc[3], ms[3], hc[3], hs[3];
    motion(rc, rs, mc, ms);
    motion(rr * rc - thh * rs, rr * rs + thh * rc, hc, hs);
    using detail::kBinomial;
    const Attachment3 *a = att.data(), *ra = rate.att.data();
    for (int k = 0; k < 3; ++k) {
      double d = detail3::row_data_derivative(a, ra, kCompact.rows[k], order, q, qd, qdd);
      const detail3::RowDerivatives x = detail3::row_derivatives(a, ra, kCompact.rows[3 + k], order, q, qd, qdd);
      const detail3::RowDerivatives y = detail3::row_derivatives(a, ra, kCompact.rows[6 + k], order, q, qd, qdd);
      for (int i = 0; i <= order; ++i) {
        const int j = order - i;
        d -= kBinomial[order][i] * (hc[i] * x.value[j] + mc[i] * x.along[j] + hs[i] * y.value[j] + ms[i] * y.along[j]);
      }
      out[k] = d;
    }
  }
  /// @copydoc DistanceSpec::joint_count
  /// Natural coordinates: not a joint of the count.
  JointCount joint_count() const { return JointCount::other(); }
  /// @copydoc DistanceSpec::prepare
  void prepare(const double* /*q0*/) { setup(); }
  /// @copydoc DistanceSpec::sketch
  /// A 3D polar draws its arm, centre to point, of length |r|.
  template <class Sketch>
  void sketch(Sketch& sk) const {
    sk.bar3(Attachment3::body_point(center.frame, center.at), Attachment3::natural(point), std::fabs(radius));
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {
      {"constraints", "polar", 3,
       "- {name: crank, type: polar, point: A, center: {body: ground, axis: [1, 2, 2]}, "
       "radius: 0.3, angle: theta}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static SpatialPolarSpec read(const Fields& f) {
    f.expect({"type", "name", "point", "center", "radius", "angle"});
    SpatialPolarSpec s;
    s.point = f.point3("point");
    if (f.present("center")) s.center = f.side3("center");
    s.radius = f.number("radius");
    s.theta = f.slot("angle");
    return s;
  }

 private:
  double value(int r, const double* q) const { return detail3::row_value(att.data(), kCompact.rows[r], q, 1.0, 0.0); }
};

/// Angle coordinate θ of a direction D about the axis of side a (z_a, from x_a): with c = D · x_a, s = D · y_a,
///   Φ = atan2(s cos θ − c sin θ, c cos θ + s sin θ)      = θ(D) − θ wrapped to (−π, π]   (1 row, an angle)
/// smooth at any θ, so θ follows D through any number of turns (the form of the joint angle driver, with the law
/// replaced by the coordinate: detail3::AngleRows). D is
///  - `rotation_angle`: x_b, the reference direction of side b (a body turning about the axis: the relative
///    rotation of a shaft's body in its bearing, which a gear, belt or rack then relates);
///  - `segment_angle` (dimension 3): B − A, a segment of natural points (the 3D analogue of the planar
///    segment_angle: mixes natural coordinates with an angle).
/// D must not lie along the axis (c = s = 0: no angle). Scene: `rotation_angle` with `between: [S1, S2]` or
/// `joint: J` (the sides of a named revolute, cylindrical or screw joint), `angle: θ`; `segment_angle` with
/// `segment: [A, B]`, `axis: {body: B, axis, ref}` (ground by default), `angle: θ` (a coordinate).
struct SpatialAngleSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const SpatialAngleSpec&) const = default;
  static constexpr int kRows = 1;  ///< one row, an angle
  /// @copydoc DistanceSpec::kKind
  static constexpr const char* kKind = "angle3";
  JointSide3 a;                      ///< the axis z_a and the reference x_a (a body or ground)
  JointSide3 b;                      ///< `rotation_angle`: the turning body (its reference direction x_b is D)
  bool segment = false;              ///< D = B − A (natural points) instead of x_b
  Point3 from;                       ///< A, for a segment
  Point3 to;                         ///< B, for a segment
  Slot theta;                        ///< θ (rad), a coordinate
  std::array<Attachment3, 4> att{};  ///< derived by setup(): x_a, y_a, then D's head and tail

  /// Validates the data and derives `att`. Throws phiq::Error.
  void setup() {
    static constexpr std::int8_t kIndex[3] = {detail3::kXa, detail3::kYa, detail3::kXb};
    const char* kind = segment ? "segment_angle" : "rotation_angle";
    const auto all = detail3::joint_attachments(a, segment ? JointSide3{} : b, kIndex, segment ? 2 : 3, kind);
    att = {all[0], all[1], segment ? Attachment3::natural(to) : all[2],
           segment ? Attachment3::natural(from) : Attachment3::zero()};
    if (segment) {
      const auto same = [](Slot u, Slot v) {
        return u.is_coordinate() ? v.is_coordinate() && u.coord() == v.coord()
                                 : !v.is_coordinate() && u.value() == v.value();
      };
      detail::require(!(same(from.x, to.x) && same(from.y, to.y) && same(from.z, to.z)),
                      "segment_angle: the segment's two ends are the same point");
    }
  }
  /// @copydoc DistanceSpec::depends_on_time
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kAngle; }
  /// @copydoc DistanceSpec::characteristic_length
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  template <class F>
  void for_each_slot(F&& f) const {
    detail3::side_slots(a, f);
    if (segment) {
      f(from.x, Unit::kLength), f(from.y, Unit::kLength), f(from.z, Unit::kLength);
      f(to.x, Unit::kLength), f(to.y, Unit::kLength), f(to.z, Unit::kLength);
    } else {
      detail3::side_slots(b, f);
    }
    f(theta, Unit::kAngle);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const { phi[0] = angle().minus(att.data(), q, theta.of(q)); }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    angle().emit(att.data(), q, s, 0);
    s(0, theta, -1.0);
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  /// θ̈ is in Φq q̈: γ = −(θ(D)̈'s q̈-free part).
  void gamma(const double* q, const double* qd, double, double* out) const {
    out[0] = -angle().bias(att.data(), q, qd);
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the sides and the segment's ends, through the
  /// attachments (θ is a coordinate).
  static constexpr auto data_members() {
    return std::tuple{&SpatialAngleSpec::a, &SpatialAngleSpec::b, &SpatialAngleSpec::from, &SpatialAngleSpec::to,
                      &SpatialAngleSpec::att};
  }
  /// Derivatives along the data (DistanceSpec::data_derivative()): θ(D)'s along the attachments
  /// (detail3::AngleRows::data_derivative()).
  void data_derivative(const SpatialAngleSpec& rate, int order, const double* q, const double* qd, const double* qdd,
                       double, double* out) const {
    out[0] = angle().data_derivative(att.data(), rate.att.data(), order, q, qd, qdd);
  }
  /// @copydoc DistanceSpec::joint_count
  /// A rotation angle between bodies adds a coordinate and the row that fixes it: it counts for no freedom, and
  /// keeps the count defined. A segment angle mixes natural coordinates: not a joint of the count.
  JointCount joint_count() const {
    if (segment || b.natural) return JointCount::other();
    return JointCount::joint(3, 0);
  }
  /// @copydoc DistanceSpec::prepare
  void prepare(const double* /*q0*/) { setup(); }
  /// @copydoc DistanceSpec::sketch
  /// A segment angle draws its segment; a rotation angle nothing (its bodies are drawn by their joints).
  template <class Sketch>
  void sketch(Sketch& sk) const {
    if (segment) sk.bar3(Attachment3::natural(from), Attachment3::natural(to));
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {{"constraints", "rotation_angle", 3,
                                          "- {name: shaft_angle, type: rotation_angle, between: [{body: ground, "
                                          "axis: [1, 0, 0]}, {body: shaft, axis: [1, 0, 0]}], angle: theta1}"},
                                         {"constraints", "segment_angle", 3,
                                          "- {name: crank_angle, type: segment_angle, segment: [O, A], "
                                          "axis: {body: ground, axis: [0, 0, 1]}, angle: theta}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static SpatialAngleSpec read(const Fields& f) {
    SpatialAngleSpec s;
    if (f.type() == "segment_angle") {
      f.expect({"type", "name", "segment", "axis", "angle"});
      s.segment = true;
      std::tie(s.from, s.to) = f.point3_pair("segment", "a segment is [from, to]");
      if (f.present("axis")) s.a = f.side3("axis");
    } else {
      f.expect({"type", "name", "between", "joint", "angle"});
      if (f.present("joint") == f.present("between"))
        f.fail("", "give either 'between: [S1, S2]' or 'joint: NAME' (a " + f.shaft_types() + " joint)");
      std::tie(s.a, s.b) = f.present("joint") ? f.turning_joint("joint") : f.sides3("between");
    }
    s.theta = Slot::coordinate(f.coordinate("angle"));
    return s;
  }

 private:
  // c = D · x_a and s = D · y_a, D = att[2] − att[3] (att[3] absent for a body's direction)
  detail3::AngleRows angle() const {
    const detail3::Term d = segment ? detail3::T(2, 3) : detail3::T(2);
    return {{d, detail3::T(0), Unit::kNone}, {d, detail3::T(1), Unit::kNone}};
  }
};

}  // namespace phiq
