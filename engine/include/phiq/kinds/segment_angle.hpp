/// @file
/// The angle coordinate of a segment (natural coordinates mixed with an angle). One constraint kind: its equation,
/// derivatives, validation, joint count, sketch and scene form (the contract is documented on DistanceSpec;
/// kinds/registry.hpp lists every kind).
#pragma once

#include <cmath>

#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// Angle coordinate θ of segment a → b against the x axis (mixes natural coordinates with an angle, typically to
/// drive a natural-coordinate mechanism by a crank angle):
///   Φ = (x_b − x_a) sin θ − (y_b − y_a) cos θ       = |b − a| sin(θ_ab − θ), a length
/// Its gradient never vanishes for a segment of non-zero length, unlike a cos/sin pair chosen by quadrant.
struct SegmentAngleSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const SegmentAngleSpec&) const = default;
  static constexpr int kRows = 1;  ///< one row, a length
  /// @copydoc DistanceSpec::kKind
  /// Scene type `segment_angle`.
  static constexpr const char* kKind = "angle";
  /// @var a
  /// @brief A, start of the segment (m).
  Point2 a, b;  ///< B, end of the segment (m)
  Slot theta;   ///< θ, the angle of b − a against the x axis (rad): usually a coordinate; a constant fixes it

  /// @copydoc DistanceSpec::depends_on_time
  /// A segment angle is time-independent.
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// The row of a segment angle is a length (|b − a| sin(θ_ab − θ)), not an angle.
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  /// A segment angle carries no length as data: 0.
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Segment angle
  /// A segment angle reads a and b (lengths), then θ (an angle).
  template <class F>
  void for_each_slot(F&& f) const {
    f(a.x, Unit::kLength), f(a.y, Unit::kLength), f(b.x, Unit::kLength), f(b.y, Unit::kLength);
    f(theta, Unit::kAngle);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    kin::V2 d = kin::pos(b, q) - kin::pos(a, q);
    double th = theta.of(q);
    phi[0] = d.x * std::sin(th) - d.y * std::cos(th);
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    kin::V2 d = kin::pos(b, q) - kin::pos(a, q);
    double th = theta.of(q), sn = std::sin(th), cs = std::cos(th);
    s(0, a.x, -sn), s(0, a.y, cs), s(0, b.x, sn), s(0, b.y, -cs), s(0, theta, d.x * cs + d.y * sn);
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double, double* out) const {
    kin::V2 d = kin::pos(b, q) - kin::pos(a, q), dd = kin::vel(b, qd) - kin::vel(a, qd);
    double th = theta.of(q), w = theta.rate(qd), sn = std::sin(th), cs = std::cos(th);
    out[0] = -2.0 * w * (dd.x * cs + dd.y * sn) + w * w * (d.x * sn - d.y * cs);
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the segment's fixed ends and a constant θ.
  static constexpr auto data_members() {
    return std::tuple{&SegmentAngleSpec::a, &SegmentAngleSpec::b, &SegmentAngleSpec::theta};
  }
  /// Derivatives along the data (DistanceSpec::data_derivative()). Φ = d × w with d = b − a, w = (cos θ, sin θ),
  /// so Φ⁽ᵏ⁾ = Σ_i C(k, i) d⁽ⁱ⁾ × w⁽ᵏ⁻ⁱ⁾; the data move d (d̂, the fixed ends' rates) and a constant θ (ŵ = θ̂ w⊥,
  /// whose w does not move), so that ∂Φ⁽ᵏ⁾/∂p = d̂ × w⁽ᵏ⁾ + d⁽ᵏ⁾ × ŵ, with ẇ = ω w⊥, ẅ = α w⊥ − ω² w.
  void data_derivative(const SegmentAngleSpec& rate, int order, const double* q, const double* qd, const double* qdd,
                       double, double* out) const {
    const double th = theta.of(q);
    const kin::V2 w{std::cos(th), std::sin(th)}, wh = rate.theta.of(q) * kin::perp(w);
    const kin::V2 dh = kin::pos(rate.b, q) - kin::pos(rate.a, q);
    kin::V2 dk = kin::pos(b, q) - kin::pos(a, q), wk = w;
    if (order == 1) {
      dk = kin::vel(b, qd) - kin::vel(a, qd), wk = theta.rate(qd) * kin::perp(w);
    } else if (order == 2) {
      const double om = theta.rate(qd);
      dk = kin::vel(b, qdd) - kin::vel(a, qdd), wk = theta.rate(qdd) * kin::perp(w) - (om * om) * w;
    }
    out[0] = kin::cross(dh, wk) + kin::cross(dk, wh);
  }

  /// @copydoc DistanceSpec::joint_count
  JointCount joint_count() const { return JointCount::other(); }
  /// @copydoc DistanceSpec::prepare
  /// A segment whose ends are the same fixed point has no direction: refused.
  void prepare(const double* /*q0*/) const {
    detail::require(!kin::same_fixed_point(a, b), "segment_angle: the segment's two ends are the same fixed point");
  }
  /// @copydoc DistanceSpec::sketch
  /// A segment angle draws its segment.
  template <class Sketch>
  void sketch(Sketch& sk) const {
    sk.bar(a, b);
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {{"constraints", "segment_angle", 2,
                                          "- {name: crank_angle, type: segment_angle, segment: [O, A], "
                                          "angle: theta2}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static SegmentAngleSpec read(const Fields& f) {
    f.expect({"type", "name", "segment", "angle"});
    auto [sa, sb] = f.segment("segment");
    return SegmentAngleSpec{sa, sb, Slot::coordinate(f.coordinate("angle"))};
  }
};

}  // namespace phiq
