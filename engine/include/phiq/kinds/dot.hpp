/// @file
/// A constant dot product of two directions (3D natural coordinates). One constraint kind (or one family of
/// kinds sharing a row table): equation, derivatives, validation, joint count, sketch and scene form; the contract
/// is documented on DistanceSpec, and kinds/registry.hpp lists every kind.
#pragma once

#include <array>
#include <cmath>
#include <tuple>

#include "phiq/kinds/spatial_rows.hpp"  // detail3: the row formulas
#include "phiq/spatial_attachment.hpp"
#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// Constant dot product of two directions (3D natural coordinates: the angle between two unit vectors, between a
/// vector and a segment, or between two segments, of one rigid body). A direction is head − tail: a natural unit
/// vector (tail the origin) or a segment between two points.
///   Φ = (D1 · D2 − c) / ref,   ref = |D1|₀ |D2|₀ at the initial placement (1 when that is 0)
/// Unitless (≈ a change of cos of the angle between them). Scene type `dot`.
struct DotSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const DotSpec&) const = default;
  static constexpr int kRows = 1;  ///< one row, unitless
  /// @copydoc DistanceSpec::kKind
  static constexpr const char* kKind = "dot";
  std::array<Attachment3, 4> ends;                     ///< D1 = ends[0] − ends[1], D2 = ends[2] − ends[3]
  Unit end_units[2] = {Unit::kLength, Unit::kLength};  ///< what D1's and D2's ends measure (kNone for vectors)
  double value = 0.0;                                  ///< c, in the product of the directions' units
  double ref = 1.0;                                    ///< set by ModelBuilder::add from the initial placement

  /// @copydoc DistanceSpec::depends_on_time
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kNone; }
  /// @copydoc DistanceSpec::characteristic_length
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  template <class F>
  void for_each_slot(F&& f) const {
    for (int k = 0; k < 4; ++k) ends[k].for_each_slot(f, end_units[k / 2]);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    phi[0] = detail3::row_value(ends.data(), kDef, q, 1.0 / ref, value);
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    detail3::row_jacobian(ends.data(), kDef, q, s, 0, 1.0 / ref);
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double, double* out) const {
    out[0] = detail3::row_gamma(ends.data(), kDef, q, qd, 1.0 / ref);
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the directions' ends (local points and axes, a
  /// fixed end's place), c, and ref (the row's scale, from the placement).
  static constexpr auto data_members() { return std::tuple{&DotSpec::ends, &DotSpec::value, &DotSpec::ref}; }
  /// Derivatives along the data (DistanceSpec::data_derivative()). With P⁽ᵏ⁾ the k-th time derivative of D1 · D2 and
  /// P̂⁽ᵏ⁾ its derivative along the ends (detail3::row_derivatives(), one pass), Φ⁽ᵏ⁾ = (P⁽ᵏ⁾ − c δ_k0) / ref and
  ///   ∂Φ⁽ᵏ⁾/∂p = (P̂⁽ᵏ⁾ − ĉ δ_k0) / ref − Φ⁽ᵏ⁾ ref̂ / ref.
  void data_derivative(const DotSpec& rate, int order, const double* q, const double* qd, const double* qdd, double,
                       double* out) const {
    const double k0 = order == 0 ? 1.0 : 0.0;
    const detail3::RowDerivatives d = detail3::row_derivatives(ends.data(), rate.ends.data(), kDef, order, q, qd, qdd);
    const double phi = (d.value[order] - k0 * value) / ref;
    out[0] = (d.along[order] - k0 * rate.value) / ref - phi * rate.ref / ref;
  }

  /// @copydoc DistanceSpec::joint_count
  JointCount joint_count() const { return JointCount::other(); }
  /// @copydoc DistanceSpec::prepare
  /// ref is set here, from the placement; constant ends are folded into their values.
  void prepare(const double* q0) {
    detail::require(std::isfinite(value), "dot: value is not finite");
    // |D1|₀ |D2|₀ at the initial placement: the row is then ≈ a change of the cosine, whatever the segments' lengths
    const double l1 = kin3::norm(ends[0].value(q0) - ends[1].value(q0));
    const double l2 = kin3::norm(ends[2].value(q0) - ends[3].value(q0));
    ref = (l1 > 0.0 && l2 > 0.0 && std::isfinite(l1 * l2)) ? l1 * l2 : 1.0;
    for (Attachment3& e : ends) e.fold_constant();
  }
  /// @copydoc DistanceSpec::sketch
  /// A dot product draws nothing: its directions are drawn by the constraints of their points.
  template <class Sketch>
  void sketch(Sketch&) const {}
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {{"constraints", "dot", 3,
                                          "- {name: w_across_crank, type: dot, "
                                          "directions: [w, [O, A]], value: 0}"}};
  /// @copydoc DistanceSpec::read
  /// A direction is a vector name or a segment [A, B] of points (B − A).
  template <class Fields>
  static DotSpec read(const Fields& f) {
    f.expect({"type", "name", "directions", "value"});
    DotSpec spec;
    const auto [d1, d2] = f.two_directions("directions");
    spec.ends[0] = d1.head, spec.ends[1] = d1.tail, spec.end_units[0] = d1.unit;
    spec.ends[2] = d2.head, spec.ends[3] = d2.tail, spec.end_units[1] = d2.unit;
    spec.value = f.number("value");
    return spec;
  }

 private:
  static constexpr detail3::RowDef kDef = {detail3::T(0, 1), detail3::T(2, 3), Unit::kNone};
};

}  // namespace phiq
