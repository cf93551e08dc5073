/// @file
/// The unit norm of a natural unit vector (3D natural coordinates). One constraint kind (or one family of
/// kinds sharing a row table): equation, derivatives, validation, joint count, sketch and scene form; the contract
/// is documented on DistanceSpec, and kinds/registry.hpp lists every kind.
#pragma once

#include <cmath>

#include "phiq/spatial_attachment.hpp"
#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// Unit norm of a natural unit vector (3D natural coordinates), added automatically for every scene `vectors`
/// entry:
///   Φ = (u · u − 1) / 2
/// Unitless. Scene: automatic, named `VECTOR.unit`.
struct UnitVectorSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const UnitVectorSpec&) const = default;
  static constexpr int kRows = 1;  ///< one row, unitless
  /// @copydoc DistanceSpec::kKind
  static constexpr const char* kKind = "unit_vector";
  Point3 u;  ///< the vector's three components

  /// @copydoc DistanceSpec::depends_on_time
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kNone; }
  /// @copydoc DistanceSpec::characteristic_length
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  template <class F>
  void for_each_slot(F&& f) const {
    f(u.x, Unit::kNone), f(u.y, Unit::kNone), f(u.z, Unit::kNone);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    const double x = u.x.of(q), y = u.y.of(q), z = u.z.of(q);
    phi[0] = 0.5 * (x * x + y * y + z * z - 1.0);
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    s(0, u.x, u.x.of(q)), s(0, u.y, u.y.of(q)), s(0, u.z, u.z.of(q));
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double*, const double* qd, double, double* out) const {
    const double x = u.x.rate(qd), y = u.y.rate(qd), z = u.z.rate(qd);
    out[0] = -(x * x + y * y + z * z);
  }

  /// @copydoc DistanceSpec::joint_count
  JointCount joint_count() const { return JointCount::other(); }
  /// @copydoc DistanceSpec::prepare
  /// A unit-norm row has nothing to check beyond its slots.
  void prepare(const double* /*q0*/) const {}
  /// @copydoc DistanceSpec::sketch
  /// A unit vector draws nothing: it is a direction, not a place.
  template <class Sketch>
  void sketch(Sketch&) const {}
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {{"vectors", "(every natural vector: VECTOR.unit)", 3, "u: [ux, uy, uz]"}};
};

}  // namespace phiq
