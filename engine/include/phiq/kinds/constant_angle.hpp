/// @file
/// A constant angle between two segments (natural coordinates). One constraint kind: its equation, derivatives,
/// validation, joint count, sketch and scene form (the contract is documented on DistanceSpec; kinds/registry.hpp lists
/// every kind).
#pragma once

#include <cmath>

#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// Constant angle α from segment u = b − a to segment v = d − c (natural coordinates):
///   Φ = (cos α (u × v) − sin α (u · v)) / ref   = |u||v| sin(θ_uv − α) / ref
/// ref is |u||v| at the initial placement, so the row is (close to) the angle error in radians. Well conditioned for
/// every α (unlike a pure dot or cross form); it is also met at α + π, a branch Newton does not reach from nearby.
struct ConstantAngleSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const ConstantAngleSpec&) const = default;
  static constexpr int kRows = 1;  ///< one row: (close to) the angle error
  /// @copydoc DistanceSpec::kKind
  /// Scene type `constant_angle`.
  static constexpr const char* kKind = "constant_angle";
  /// @var a
  /// @brief A, start of segment u = B − A (m).
  /// @var b
  /// @brief B, end of segment u (m).
  /// @var c
  /// @brief C, start of segment v = D − C (m).
  Point2 a, b, c, d;   ///< D, end of segment v (m)
  double angle = 0.0;  ///< α, the constant angle from u to v (rad, counter-clockwise), finite
  /// |u||v| at the initial placement (m²), set when the constraint is added (1 if either segment has zero length).
  /// It scales the row and does not change the solution.
  double ref = 1.0;

  /// @copydoc DistanceSpec::depends_on_time
  /// A constant angle is time-independent.
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// The row of a constant angle is an angle (close to the angle error in radians).
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kAngle; }
  /// @copydoc DistanceSpec::characteristic_length
  /// A constant angle carries no length as data (ref only scales the row): 0.
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Constant angle
  /// A constant angle reads the points a, b, c and d, all lengths.
  template <class F>
  void for_each_slot(F&& f) const {
    f(a.x, Unit::kLength), f(a.y, Unit::kLength), f(b.x, Unit::kLength), f(b.y, Unit::kLength);
    f(c.x, Unit::kLength), f(c.y, Unit::kLength), f(d.x, Unit::kLength), f(d.y, Unit::kLength);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    kin::V2 u = kin::pos(b, q) - kin::pos(a, q), v = kin::pos(d, q) - kin::pos(c, q);
    phi[0] = (std::cos(angle) * kin::cross(u, v) - std::sin(angle) * kin::dot(u, v)) / ref;
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    kin::V2 u = kin::pos(b, q) - kin::pos(a, q), v = kin::pos(d, q) - kin::pos(c, q);
    const double ca = std::cos(angle) / ref, sa = std::sin(angle) / ref;
    kin::V2 du{ca * v.y - sa * v.x, -ca * v.x - sa * v.y};
    kin::V2 dv{-ca * u.y - sa * u.x, ca * u.x - sa * u.y};
    s(0, a.x, -du.x), s(0, a.y, -du.y), s(0, b.x, du.x), s(0, b.y, du.y);
    s(0, c.x, -dv.x), s(0, c.y, -dv.y), s(0, d.x, dv.x), s(0, d.y, dv.y);
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double*, const double* qd, double, double* out) const {
    kin::V2 ud = kin::vel(b, qd) - kin::vel(a, qd), vd = kin::vel(d, qd) - kin::vel(c, qd);
    out[0] = -2.0 * (std::cos(angle) * kin::cross(ud, vd) - std::sin(angle) * kin::dot(ud, vd)) / ref;
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the segments' fixed points, the angle, and ref
  /// (the scale of the row, from the placement, which a parameter may move too).
  static constexpr auto data_members() {
    return std::tuple{&ConstantAngleSpec::a, &ConstantAngleSpec::b,     &ConstantAngleSpec::c,
                      &ConstantAngleSpec::d, &ConstantAngleSpec::angle, &ConstantAngleSpec::ref};
  }
  /// Derivatives along the data (DistanceSpec::data_derivative()). With B(x, y) = cos α (x × y) − sin α (x · y) and
  /// B′(x, y) = ∂B/∂α = −sin α (x × y) − cos α (x · y), the k-th time derivative of Φ is
  /// Σ_i C(k, i) B(u⁽ⁱ⁾, v⁽ᵏ⁻ⁱ⁾) / ref; the data move u and v (û, v̂: their fixed points' rates; their motion
  /// u̇, ü is the coordinates'), α and ref:
  ///
  ///   ∂Φ⁽ᵏ⁾/∂p = [B(û, v⁽ᵏ⁾) + B(u⁽ᵏ⁾, v̂) + α̂ Σ_i C(k, i) B′(u⁽ⁱ⁾, v⁽ᵏ⁻ⁱ⁾)] / ref − Φ⁽ᵏ⁾ ref̂ / ref,
  ///
  /// Φ⁽¹⁾ = Φq q̇ and Φ⁽²⁾ = Φq q̈ − γ.
  void data_derivative(const ConstantAngleSpec& rate, int order, const double* q, const double* qd, const double* qdd,
                       double, double* out) const {
    const double ca = std::cos(angle), sa = std::sin(angle);
    auto B = [&](const kin::V2& x, const kin::V2& y) { return ca * kin::cross(x, y) - sa * kin::dot(x, y); };
    auto Bp = [&](const kin::V2& x, const kin::V2& y) { return -sa * kin::cross(x, y) - ca * kin::dot(x, y); };
    const kin::V2 u = kin::pos(b, q) - kin::pos(a, q), v = kin::pos(d, q) - kin::pos(c, q);
    const kin::V2 uh = kin::pos(rate.b, q) - kin::pos(rate.a, q), vh = kin::pos(rate.d, q) - kin::pos(rate.c, q);
    // u, v and their time derivatives up to `order`; the data's rates touch only the undifferentiated ones
    kin::V2 du[3] = {u, {0, 0}, {0, 0}}, dv[3] = {v, {0, 0}, {0, 0}};
    if (order >= 1) du[1] = kin::vel(b, qd) - kin::vel(a, qd), dv[1] = kin::vel(d, qd) - kin::vel(c, qd);
    if (order == 2) du[2] = kin::vel(b, qdd) - kin::vel(a, qdd), dv[2] = kin::vel(d, qdd) - kin::vel(c, qdd);
    using detail::kBinomial;
    double value = 0.0, along_angle = 0.0;
    for (int i = 0; i <= order; ++i) {
      value += kBinomial[order][i] * B(du[i], dv[order - i]);
      along_angle += kBinomial[order][i] * Bp(du[i], dv[order - i]);
    }
    out[0] = (B(uh, dv[order]) + B(du[order], vh) + rate.angle * along_angle - value * rate.ref / ref) / ref;
  }

  /// @copydoc DistanceSpec::joint_count
  JointCount joint_count() const { return JointCount::other(); }
  /// @copydoc DistanceSpec::prepare
  /// ref is set here, from the placement.
  void prepare(const double* q0) {
    detail::require(std::isfinite(angle), "constant_angle: angle is not finite");
    detail::require(!kin::same_fixed_point(a, b) && !kin::same_fixed_point(c, d),
                    "constant_angle: a segment's two ends are the same fixed point");
    const double lu = kin::initial_length(a, b, q0), lv = kin::initial_length(c, d, q0);
    ref = (lu > 0.0 && lv > 0.0 && std::isfinite(lu * lv)) ? lu * lv : 1.0;
  }
  /// @copydoc DistanceSpec::sketch
  /// A constant angle draws its two segments.
  template <class Sketch>
  void sketch(Sketch& sk) const {
    sk.bar(a, b);
    sk.bar(c, d);
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {{"constraints", "constant_angle", 2,
                                          "- {name: bend, type: constant_angle, segments: [[A, B], [B, C]], "
                                          "angle: pi/3}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static ConstantAngleSpec read(const Fields& f) {
    f.expect({"type", "name", "segments", "angle"});
    const auto [u, v] = f.two_segments("segments");
    return ConstantAngleSpec{u.first, u.second, v.first, v.second, f.number("angle"), 1.0};
  }
};

}  // namespace phiq
