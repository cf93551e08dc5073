/// @file
/// A point at a distance and an angle from another (mixed coordinates: the notes' crank). One constraint kind: its
/// equation, derivatives, validation, joint count, sketch and scene form (the contract is documented on DistanceSpec;
/// kinds/registry.hpp lists every kind).
#pragma once

#include <cmath>
#include <tuple>

#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// Point p at distance L from o in direction θ (mixed coordinates; the notes' crank  x_A − L2 cos θ2 = 0,
/// y_A − L2 sin θ2 = 0 with o the origin):
///   Φ = p − o − L (cos θ, sin θ)                         (2 rows, lengths)
struct PolarSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const PolarSpec&) const = default;
  static constexpr int kRows = 2;  ///< two rows: x and y, lengths
  /// @copydoc DistanceSpec::kKind
  /// Scene type `polar`.
  static constexpr const char* kKind = "polar";
  /// @var p
  /// @brief P, the point placed at distance L from o (m).
  Point2 p, o;          ///< O, the origin of the polar vector (m)
  double length = 1.0;  ///< L, metres, finite (a negative L points against θ)
  Slot theta;           ///< θ, the direction of P − O against the x axis (rad): a coordinate or a constant

  /// @copydoc DistanceSpec::depends_on_time
  /// A polar constraint is time-independent.
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// Both rows of a polar constraint are lengths.
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  /// For a polar constraint: |L|.
  double characteristic_length() const { return std::fabs(length); }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Polar
  /// A polar constraint reads p and o (lengths), then θ (an angle).
  template <class F>
  void for_each_slot(F&& f) const {
    f(p.x, Unit::kLength), f(p.y, Unit::kLength), f(o.x, Unit::kLength), f(o.y, Unit::kLength);
    f(theta, Unit::kAngle);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    double th = theta.of(q);
    phi[0] = p.x.of(q) - o.x.of(q) - length * std::cos(th);
    phi[1] = p.y.of(q) - o.y.of(q) - length * std::sin(th);
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    double th = theta.of(q);
    s(0, p.x, 1.0), s(0, o.x, -1.0), s(0, theta, length * std::sin(th));
    s(1, p.y, 1.0), s(1, o.y, -1.0), s(1, theta, -length * std::cos(th));
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = out[1] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double, double* out) const {
    double th = theta.of(q), w = theta.rate(qd);
    out[0] = -length * w * w * std::cos(th);
    out[1] = -length * w * w * std::sin(th);
  }

  /// The data a parameter may move (DistanceSpec::data_members()).
  static constexpr auto data_members() {
    return std::tuple{&PolarSpec::p, &PolarSpec::o, &PolarSpec::length, &PolarSpec::theta};
  }
  /// Derivatives along the data (DistanceSpec::data_derivative()). With u = (cos θ, sin θ), u⊥ = (−sin θ, cos θ),
  /// ω = θ̇, α = θ̈ and θ̂ the rate of a constant θ:
  ///
  ///   ∂Φ/∂p = ṗ − ȯ − L̇ u − L θ̂ u⊥,   ∂(Φq q̇)/∂p = −L̇ ω u⊥ + L θ̂ ω u,
  ///   ∂(Φq q̈ − γ)/∂p = L̇ (ω² u − α u⊥) + L θ̂ (α u + ω² u⊥).
  void data_derivative(const PolarSpec& rate, int order, const double* q, const double* qd, const double* qdd, double,
                       double* out) const {
    const double th = theta.of(q), c = std::cos(th), s = std::sin(th), Ld = rate.length, thd = rate.theta.of(q);
    if (order == 0) {
      out[0] = rate.p.x.of(q) - rate.o.x.of(q) - Ld * c + length * s * thd;
      out[1] = rate.p.y.of(q) - rate.o.y.of(q) - Ld * s - length * c * thd;
      return;
    }
    const double w = theta.rate(qd);
    if (order == 1) {
      out[0] = Ld * w * s + length * thd * w * c;
      out[1] = -Ld * w * c + length * thd * w * s;
      return;
    }
    const double al = theta.rate(qdd);
    out[0] = Ld * (w * w * c + al * s) + length * thd * (al * c - w * w * s);
    out[1] = Ld * (w * w * s - al * c) + length * thd * (al * s + w * w * c);
  }

  /// @copydoc DistanceSpec::joint_count
  JointCount joint_count() const { return JointCount::other(); }
  /// @copydoc DistanceSpec::prepare
  /// A zero length is refused: the point would sit on the origin whatever θ, leaving θ undetermined.
  void prepare(const double* /*q0*/) const {
    detail::require(std::isfinite(length), "polar: length is not finite");
    detail::require(length != 0.0, "polar: the length is zero (the angle would be undetermined)");
  }
  /// @copydoc DistanceSpec::sketch
  /// A polar constraint draws its arm, o to p, of length |L|.
  template <class Sketch>
  void sketch(Sketch& sk) const {
    sk.bar(o, p, std::fabs(length));
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {
      {"constraints", "polar", 2, "- {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static PolarSpec read(const Fields& f) {
    f.expect({"type", "name", "point", "origin", "length", "angle"});
    return PolarSpec{f.point("point"), f.point("origin"), f.number("length"), f.slot("angle")};
  }
};

}  // namespace phiq
