/// @file
/// A point on the straight line through two points (natural coordinates). One constraint kind: its equation,
/// derivatives, validation, joint count, sketch and scene form (the contract is documented on DistanceSpec;
/// kinds/registry.hpp lists every kind).
#pragma once

#include <cmath>
#include <tuple>

#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// Point p on the straight line through a and b (natural coordinates):
///   Φ = ((b − a) × (p − a)) / ref
/// ref is |b − a| at the initial placement (set when the model is built), so that the row is the distance of p from
/// the line, a length. It scales the row; it does not change the solution.
struct PointOnLineSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const PointOnLineSpec&) const = default;
  static constexpr int kRows = 1;  ///< one row: the distance of p from the line
  /// @copydoc DistanceSpec::kKind
  /// Scene type `point_on_line`.
  static constexpr const char* kKind = "point_on_line";
  /// @var p
  /// @brief P, the point kept on the line (m).
  /// @var a
  /// @brief A, first point of the line (m).
  Point2 p, a, b;  ///< B, second point of the line (m); must differ from A at the initial placement to set ref
  /// |B − A| at the initial placement (m), set when the constraint is added (1 if that length is zero or not
  /// finite). It scales the row and does not change the solution.
  double ref = 1.0;

  /// @copydoc DistanceSpec::depends_on_time
  /// A point on a line is time-independent.
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// The row of a point on a line is a length.
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  /// A point on a line carries no length as data (ref only scales the row): 0.
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Point on a line
  /// A point on a line reads p, a and b, all lengths.
  template <class F>
  void for_each_slot(F&& f) const {
    f(p.x, Unit::kLength), f(p.y, Unit::kLength), f(a.x, Unit::kLength), f(a.y, Unit::kLength);
    f(b.x, Unit::kLength), f(b.y, Unit::kLength);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    kin::V2 u = kin::pos(b, q) - kin::pos(a, q), w = kin::pos(p, q) - kin::pos(a, q);
    phi[0] = kin::cross(u, w) / ref;
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    kin::V2 u = kin::pos(b, q) - kin::pos(a, q), w = kin::pos(p, q) - kin::pos(a, q);
    const double k = 1.0 / ref;
    // ∂/∂u = (w_y, −w_x), ∂/∂w = (−u_y, u_x); a enters both with a minus sign
    s(0, p.x, -k * u.y), s(0, p.y, k * u.x);
    s(0, b.x, k * w.y), s(0, b.y, -k * w.x);
    s(0, a.x, k * (u.y - w.y)), s(0, a.y, k * (w.x - u.x));
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double*, const double* qd, double, double* out) const {
    kin::V2 ud = kin::vel(b, qd) - kin::vel(a, qd), wd = kin::vel(p, qd) - kin::vel(a, qd);
    out[0] = -2.0 * kin::cross(ud, wd) / ref;
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the points' constants and the reference length.
  static constexpr auto data_members() {
    return std::tuple{&PointOnLineSpec::p, &PointOnLineSpec::a, &PointOnLineSpec::b, &PointOnLineSpec::ref};
  }
  /// Derivatives along the data (DistanceSpec::data_derivative()). With u = B − A, w = P − A, their data's rates
  /// u̇, ẇ (constants' rates), velocities u′, w′ and accelerations u″, w″, and the reference length's rate ṙ:
  ///
  ///   ∂Φ/∂p = (u̇ × w + u × ẇ)/ref − (ṙ/ref) Φ,   ∂(Φq q̇)/∂p = (u̇ × w′ + u′ × ẇ)/ref − (ṙ/ref) Φq q̇,
  ///   ∂(Φq q̈ − γ)/∂p = (u̇ × w″ + u″ × ẇ)/ref − (ṙ/ref) (Φq q̈ − γ),   Φq q̈ − γ = (u × w″ + u″ × w + 2 u′ × w′)/ref.
  void data_derivative(const PointOnLineSpec& rate, int order, const double* q, const double* qd, const double* qdd,
                       double, double* out) const {
    const kin::V2 u = kin::pos(b, q) - kin::pos(a, q), w = kin::pos(p, q) - kin::pos(a, q);
    const kin::V2 ud = kin::pos(rate.b, q) - kin::pos(rate.a, q), wd = kin::pos(rate.p, q) - kin::pos(rate.a, q);
    const double k = rate.ref / ref;
    if (order == 0) {
      out[0] = (kin::cross(ud, w) + kin::cross(u, wd)) / ref - k * kin::cross(u, w) / ref;
      return;
    }
    const kin::V2 uv = kin::vel(b, qd) - kin::vel(a, qd), wv = kin::vel(p, qd) - kin::vel(a, qd);
    if (order == 1) {
      out[0] = (kin::cross(ud, wv) + kin::cross(uv, wd)) / ref - k * (kin::cross(u, wv) + kin::cross(uv, w)) / ref;
      return;
    }
    const kin::V2 ua = kin::vel(b, qdd) - kin::vel(a, qdd), wa = kin::vel(p, qdd) - kin::vel(a, qdd);
    out[0] = (kin::cross(ud, wa) + kin::cross(ua, wd)) / ref -
             k * (kin::cross(u, wa) + kin::cross(ua, w) + 2.0 * kin::cross(uv, wv)) / ref;
  }

  /// @copydoc DistanceSpec::joint_count
  JointCount joint_count() const { return JointCount::other(); }
  /// @copydoc DistanceSpec::prepare
  /// ref is set here, from the placement.
  void prepare(const double* q0) {
    detail::require(!kin::same_fixed_point(a, b), "point_on_line: the line's two points are the same fixed point");
    const double l = kin::initial_length(a, b, q0);
    ref = (std::isfinite(l) && l > 0.0) ? l : 1.0;
  }
  /// @copydoc DistanceSpec::sketch
  /// A point on a line draws the line's guide, a to b.
  template <class Sketch>
  void sketch(Sketch& sk) const {
    sk.bar(a, b);
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {
      {"constraints", "point_on_line", 2, "- {name: guide, type: point_on_line, point: B, line: [O, C]}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static PointOnLineSpec read(const Fields& f) {
    f.expect({"type", "name", "point", "line"});
    auto [la, lb] = f.segment("line");
    return PointOnLineSpec{f.point("point"), la, lb, 1.0};
  }
};

}  // namespace phiq
