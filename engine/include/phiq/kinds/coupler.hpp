/// @file
/// A linear relation between two coordinates: a gear pair or a belt between two angles, a rack and pinion between
/// a travel and an angle (Drake's CouplerConstraint). One constraint kind: its equation, derivatives, validation,
/// joint count, sketch and scene form; the contract is documented on DistanceSpec, and kinds/registry.hpp lists
/// every kind.
#pragma once

#include <cmath>
#include <tuple>

#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// Coupler: coordinates q_i and q_j tied by a linear relation a q_i + b q_j = c:
///   Φ = (a q_i + b q_j − c) / |a|,   Φt = 0,   γ = 0
/// Dividing by |a| makes the row a value of q_i's unit (q_i + (b/a) q_j − c/a), whatever the scale of the
/// coefficients, so that q_i's tolerance holds for it. An external gear pair of pitch radii r_1, r_2 between the
/// gears' angles is r_1 θ_1 + r_2 θ_2 = c (they turn opposite ways), an internal one or a belt r_1 θ_1 − r_2 θ_2 = c
/// (the same way; a crossed belt like an external pair), a rack and pinion x − r θ = c. Between relative angles of
/// a planet and its carrier it is the ratio of an epicyclic train. a ≠ 0, b ≠ 0, i ≠ j.
///
/// Scene type `coupler`: `coordinates: [q_i, q_j]`, `coefficients: [a, b]`, `constant: c` (default 0). Any
/// dimension. Time-independent; its row has q_i's unit.
struct CouplerSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const CouplerSpec&) const = default;
  static constexpr int kRows = 1;  ///< one row
  /// @copydoc DistanceSpec::kKind
  static constexpr const char* kKind = "coupler";
  Slot first;       ///< q_i (a coordinate): the row takes its unit
  Slot second;      ///< q_j (a coordinate)
  double a = 1.0;   ///< coefficient of q_i, non-zero and finite
  double b = -1.0;  ///< coefficient of q_j, non-zero and finite
  double c = 0.0;   ///< the constant, finite

  /// @copydoc DistanceSpec::depends_on_time
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// A coupler's row has q_i's unit.
  Unit row_unit(int, const std::vector<Unit>& coordinate_units) const {
    return coordinate_units[static_cast<std::size_t>(first.coord())];
  }
  /// @copydoc DistanceSpec::characteristic_length
  /// A coupler carries no length as data (a radius is a ratio here): 0.
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  /// A coupler reads q_i and q_j without telling their units: a gear pair couples angles, a rack a length to an
  /// angle, and the other constraints on them say which.
  template <class F>
  void for_each_slot(F&& f) const {
    f(first, Unit::kNone), f(second, Unit::kNone);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    phi[0] = (a * first.of(q) + b * second.of(q) - c) / std::fabs(a);
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double*, double, Sink& s) const {
    s(0, first, a / std::fabs(a)), s(0, second, b / std::fabs(a));
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  /// Φ is linear in q: γ = 0.
  void gamma(const double*, const double*, double, double* out) const { out[0] = 0.0; }
  /// The data a parameter may move (DistanceSpec::data_members()): the coefficients and the constant.
  static constexpr auto data_members() { return std::tuple{&CouplerSpec::a, &CouplerSpec::b, &CouplerSpec::c}; }
  /// Derivatives along the data (DistanceSpec::data_derivative()). Φ⁽ᵏ⁾ = (a q_i⁽ᵏ⁾ + b q_j⁽ᵏ⁾ − c δ_k0) / |a|, so
  /// ∂Φ⁽ᵏ⁾/∂p = (â q_i⁽ᵏ⁾ + b̂ q_j⁽ᵏ⁾ − ĉ δ_k0) / |a| − Φ⁽ᵏ⁾ â / a (|a| moves as sign(a) â).
  void data_derivative(const CouplerSpec& rate, int order, const double* q, const double* qd, const double* qdd, double,
                       double* out) const {
    const double* v = order == 0 ? q : order == 1 ? qd : qdd;
    const double x = first.of(v), y = second.of(v), k0 = order == 0 ? 1.0 : 0.0;  // both are coordinates
    const double phi = (a * x + b * y - k0 * c) / std::fabs(a);
    out[0] = (rate.a * x + rate.b * y - k0 * rate.c) / std::fabs(a) - phi * rate.a / a;
  }

  /// @copydoc DistanceSpec::joint_count
  /// Between the angles (or an angle and a travel) of two bodies, a coupler is a gear pair or rack and pinion: a
  /// planar higher pair removing one freedom. (Between other coordinates the model has constraints that are not
  /// joints anyway, and the count stays undefined.)
  JointCount joint_count() const { return JointCount::joint(2, 1); }
  /// @copydoc DistanceSpec::prepare
  void prepare(const double* /*q0*/) const {
    detail::require(first.is_coordinate() && second.is_coordinate(), "coupler: relates two coordinates");
    detail::require(first.coord() != second.coord(), "coupler: the two coordinates must differ");
    detail::require(std::isfinite(a) && std::isfinite(b) && std::isfinite(c), "coupler: coefficients are not finite");
    detail::require(a != 0.0 && b != 0.0, "coupler: coefficients must not be zero");
  }
  /// @copydoc DistanceSpec::sketch
  /// A coupler draws nothing: it relates coordinates, not points (the gears' bodies are drawn by their joints).
  template <class Sketch>
  void sketch(Sketch&) const {}
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {{"constraints", "coupler", 0,
                                          "- {name: gears, type: coupler, coordinates: [theta2, theta5], "
                                          "coefficients: [0.1, 0.05], constant: 0}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static CouplerSpec read(const Fields& f) {
    f.expect({"type", "name", "coordinates", "coefficients", "constant"});
    const auto [i, j] = f.coordinate_pair("coordinates");
    const auto [a, b] = f.number_pair("coefficients");
    return CouplerSpec{Slot::coordinate(i), Slot::coordinate(j), a, b,
                       f.present("constant") ? f.number("constant") : 0.0};
  }
};

}  // namespace phiq
