/// @file
/// The normalisation of a body's Euler parameters. One constraint kind (or one family of
/// kinds sharing a row table): equation, derivatives, validation, joint count, sketch and scene form; the contract
/// is documented on DistanceSpec, and kinds/registry.hpp lists every kind.
#pragma once

#include <cmath>

#include "phiq/spatial_attachment.hpp"
#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// Normalisation of a body's Euler parameters, added automatically for every spatial body:
///   Φ = (p · p − 1) / 2
/// Unitless and ≈ |p| − 1 near the solution (so a rough initial guess of p is enough). Scene: automatic, named
/// `BODY.euler`.
struct EulerParametersSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const EulerParametersSpec&) const = default;
  static constexpr int kRows = 1;  ///< one row, unitless
  /// @copydoc DistanceSpec::kKind
  static constexpr const char* kKind = "euler_parameters";
  Slot e[4];  ///< e0 … e3 of the body

  /// @copydoc DistanceSpec::depends_on_time
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kNone; }
  /// @copydoc DistanceSpec::characteristic_length
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  template <class F>
  void for_each_slot(F&& f) const {
    for (const Slot& s : e) f(s, Unit::kNone);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    double n = 0.0;
    for (const Slot& s : e) n += s.of(q) * s.of(q);
    phi[0] = 0.5 * (n - 1.0);
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    for (const Slot& v : e) s(0, v, v.of(q));
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double*, const double* qd, double, double* out) const {
    double g = 0.0;
    for (const Slot& s : e) g -= s.rate(qd) * s.rate(qd);
    out[0] = g;
  }

  /// @copydoc DistanceSpec::joint_count
  /// A body's own normalisation is not counted.
  JointCount joint_count() const { return {JointCount::Role::kBodyOwn, 0, 0}; }
  /// @copydoc DistanceSpec::prepare
  /// A normalisation has nothing to check beyond its slots.
  void prepare(const double* /*q0*/) const {}
  /// @copydoc DistanceSpec::sketch
  /// A normalisation draws nothing: it is one body's own condition.
  template <class Sketch>
  void sketch(Sketch&) const {}
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {{"bodies", "(every spatial body: BODY.euler)", 3,
                                          "crank: [crank_x, crank_y, crank_z, crank_e0, crank_e1, "
                                          "crank_e2, crank_e3]"}};
};

}  // namespace phiq
