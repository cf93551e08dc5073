/// @file
/// A motion law on one coordinate: a motor. One constraint kind: its equation, derivatives, validation, joint count,
/// sketch and scene form (the contract is documented on DistanceSpec; kinds/registry.hpp lists every kind).
#pragma once

#include <cmath>

#include "phiq/motion_law.hpp"
#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// Rheonomic driver on one coordinate (a motor):
///   Φ = q_j − f(t),   Φt = −f'(t),   γ = f''(t)       (0 for a linear law: the notes' erratum)
struct CoordinateDriverSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const CoordinateDriverSpec&) const = default;
  static constexpr int kRows = 1;  ///< one row, in the unit of the driven coordinate
  /// @copydoc DistanceSpec::kKind
  /// Added with ModelBuilder::add_driver() or, in a scene, as a driver given by `coordinate`.
  static constexpr const char* kKind = "driver";
  Slot coordinate;  ///< q_j, the driven coordinate; must be a coordinate (checked when the constraint is added)
  MotionLaw law;    ///< f(t), the prescribed value of q_j, in q_j's unit; defines the time range of the model

  /// @copydoc DistanceSpec::depends_on_time
  /// A driver always depends on time.
  bool depends_on_time() const { return true; }
  /// @copydoc DistanceSpec::row_unit
  /// A driver's row has the unit of the driven coordinate, `coordinate_units[coordinate.coord()]` (Unit::kNone if
  /// none was inferred).
  Unit row_unit(int, const std::vector<Unit>& coordinate_units) const {
    return coordinate.is_coordinate() ? coordinate_units[coordinate.coord()] : Unit::kNone;
  }
  /// @copydoc DistanceSpec::characteristic_length
  /// A driver carries no length as data: 0.
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Driver
  /// A driver reads only the driven coordinate, with Unit::kNone: driving a coordinate does not tell what it
  /// measures.
  template <class F>
  void for_each_slot(F&& f) const {
    f(coordinate, Unit::kNone);
  }
  /// @copydoc DistanceSpec::residual
  /// @par Driver
  /// A driver evaluates its law at `t`: Φ = q_j − f(t) (NaN outside the law's domain).
  void residual(const double* q, double t, double* phi) const { phi[0] = coordinate.of(q) - law.evaluate(t).f; }
  /// @copydoc DistanceSpec::jacobian
  /// @par Driver
  /// A driver emits one entry, 1 on the driven coordinate; `q` and `t` are not read.
  template <class Sink>
  void jacobian(const double*, double, Sink& s) const {
    s(0, coordinate, 1.0);
  }
  /// @copydoc DistanceSpec::phi_t
  /// @par Driver
  /// For a driver: Φt = −f'(t); `q` is not read.
  void phi_t(const double*, double t, double* out) const { out[0] = -law.evaluate(t).df; }
  /// @copydoc DistanceSpec::gamma
  /// @par Driver
  /// For a driver: γ = f''(t) (0 for a linear law); `q` and `qd` are not read.
  void gamma(const double*, const double*, double t, double* out) const { out[0] = law.evaluate(t).ddf; }
  /// The data a parameter may move (DistanceSpec::data_members()): the law (its coefficients, values or program).
  static constexpr auto data_members() { return std::tuple{&CoordinateDriverSpec::law}; }
  /// Derivatives along the data (DistanceSpec::data_derivative()): −∂f/∂p, −∂f′/∂p, −∂f″/∂p at t, of the law's
  /// rate (MotionLaw::rate_along: exact along a polynomial's, a table's or a harmonic's data).
  void data_derivative(const CoordinateDriverSpec& rate, int order, const double*, const double*, const double*,
                       double t, double* out) const {
    out[0] = detail::minus_law_rate(rate.law, order, t);
  }

  /// @copydoc DistanceSpec::joint_count
  /// A driver is not counted.
  JointCount joint_count() const { return JointCount::driver(); }
  /// @copydoc DistanceSpec::prepare
  void prepare(const double* /*q0*/) const {
    detail::require(coordinate.is_coordinate(), "driver: must act on a coordinate");
  }
  /// @copydoc DistanceSpec::sketch
  /// A driver draws nothing: what it moves is drawn by the constraints of its coordinate.
  template <class Sketch>
  void sketch(Sketch&) const {}
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {
      {"drivers", "coordinate", 0, "- {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 2}}"}};
};

}  // namespace phiq
