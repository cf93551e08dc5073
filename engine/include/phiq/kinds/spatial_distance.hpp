/// @file
/// The distance between two spatial points. One constraint kind (or one family of
/// kinds sharing a row table): equation, derivatives, validation, joint count, sketch and scene form; the contract
/// is documented on DistanceSpec, and kinds/registry.hpp lists every kind.
#pragma once

#include <array>
#include <cmath>
#include <tuple>
#include <utility>

#include "phiq/kinds/reaction_site.hpp"
#include "phiq/kinds/spatial_rows.hpp"  // detail3: the row formulas
#include "phiq/spatial_attachment.hpp"
#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// Distance between two spatial points (natural points, or points of bodies: a massless bar with a ball joint at
/// each end):
///   Φ = (|B − A|² − L²) / (2L)        (1 row, a length ≈ |B − A| − L)
/// Scene type `distance` (dimension 3).
struct SpatialDistanceSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const SpatialDistanceSpec&) const = default;
  static constexpr int kRows = 1;  ///< one row, a length
  /// @copydoc DistanceSpec::kKind
  static constexpr const char* kKind = "distance";
  std::array<Attachment3, 2> ends;  ///< A, B
  double length = 1.0;              ///< L > 0 (checked when added)

  /// @copydoc DistanceSpec::depends_on_time
  bool depends_on_time() const { return false; }
  /// The values its reaction has (ConstraintBlock::reaction_width()): Fx, Fy, Fz, Mx, My, Mz, as a spatial joint's.
  static constexpr int kReactionWidth = 6;
  /// Whether this one has a reaction (ConstraintBlock::states_reaction()): a bar with a ball joint at each end
  /// between bodies (or a body and ground), not a distance between natural points (a part's own bar).
  bool states_reaction() const {
    const auto [balls, body] = ball_ends();
    return balls && body;
  }
  /// The reaction (ReactionSite): the bar's force on the body of end A at A, or on B's at B when A is fixed; its
  /// x axis from that end toward the other, so that Fx is the bar's tension (y and z complete it). A bar between
  /// balls carries no moment about them, nor any force across itself.
  ReactionSite reaction_site(const double* q) const {
    const bool a_moves = of_body(ends[0]);
    const Attachment3 &on = ends[a_moves ? 0 : 1], &other = ends[a_moves ? 1 : 0];
    ReactionSite site;
    site.point = on.value(q);
    site.spatial = true;
    site.frame3 = Frame3{on.r[0], on.r[1], on.r[2], on.p[0], on.p[1], on.p[2], on.p[3]};
    const kin3::V3 d = other.value(q) - site.point;
    const double n = kin3::norm(d);
    if (n > 0.0) {
      site.axes[0] = (1.0 / n) * d;
      site.axes[1] = kin3::perpendicular_unit(site.axes[0]);  // (y, z: any completion)
      site.axes[2] = kin3::cross(site.axes[0], site.axes[1]);
    }
    return site;
  }
  /// @copydoc DistanceSpec::row_unit
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  double characteristic_length() const { return length; }
  /// @copydoc DistanceSpec::for_each_slot
  template <class F>
  void for_each_slot(F&& f) const {
    ends[0].for_each_slot(f, Unit::kLength), ends[1].for_each_slot(f, Unit::kLength);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    phi[0] = detail3::row_value(ends.data(), kDef, q, 0.5 / length, length * length);
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    detail3::row_jacobian(ends.data(), kDef, q, s, 0, 0.5 / length);
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double, double* out) const {
    out[0] = detail3::row_gamma(ends.data(), kDef, q, qd, 0.5 / length);
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the ends (their local points, a fixed end's
  /// place) and the length.
  static constexpr auto data_members() { return std::tuple{&SpatialDistanceSpec::ends, &SpatialDistanceSpec::length}; }
  /// Derivatives along the data (DistanceSpec::data_derivative()). Φ = (|d|² − L²)/(2L), d = B − A, whose Φq and
  /// γ are 1/(2L) times what does not hold L; the ends move d·d as a row of the joints
  /// (detail3::row_data_derivative(): Dk, the derivative of d·d's k-th time derivative along the ends):
  ///
  ///   ∂Φ/∂p = −L̇ (Φ + L) / L + D0/(2L),   ∂(Φq q̇)/∂p = −(L̇/L) Φq q̇ + D1/(2L),
  ///   ∂(Φq q̈ − γ)/∂p = −(L̇/L) (Φq q̈ − γ) + D2/(2L).
  void data_derivative(const SpatialDistanceSpec& rate, int order, const double* q, const double* qd, const double* qdd,
                       double t, double* out) const {
    const double k = rate.length / length;
    const double ends_term =
        detail3::row_data_derivative(ends.data(), rate.ends.data(), kDef, order, q, qd, qdd) / (2.0 * length);
    double value = 0.0;
    if (order == 0) {
      residual(q, t, &value);
      out[0] = -k * (value + length) + ends_term;
      return;
    }
    const double* v = order == 1 ? qd : qdd;
    auto product = [&](int, const Slot& s, double entry) { value += entry * s.rate(v); };  // Φq v
    jacobian(q, t, product);
    if (order == 2) {
      double g = 0.0;
      gamma(q, qd, t, &g);
      value -= g;
    }
    out[0] = -k * value + ends_term;
  }

  /// @copydoc DistanceSpec::joint_count
  /// A distance between body (or ground) points is a bar with two ball joints, removing one freedom; between
  /// natural points it is no joint.
  JointCount joint_count() const { return ball_ends().first ? JointCount::joint(3, 1) : JointCount::other(); }
  /// Whether end `e` is a moving body's point (its Euler parameters are coordinates).
  static bool of_body(const Attachment3& e) {
    for (const Slot& v : e.p)
      if (v.is_coordinate()) return true;
    return false;
  }
  /// Whether each end is a body's point or fixed (a bar with a ball joint at each end), and whether one is a body's.
  std::pair<bool, bool> ball_ends() const {
    bool any_body = false;
    for (const Attachment3& e : ends) {
      const bool body = of_body(e);
      bool fixed = true;
      for (const Slot& v : e.r) fixed = fixed && !v.is_coordinate();
      if (!body && !fixed) return {false, false};
      any_body = any_body || body;
    }
    return {true, any_body};
  }
  /// @copydoc DistanceSpec::prepare
  /// Constant ends are folded into their values here.
  void prepare(const double* /*q0*/) {
    detail::require(std::isfinite(length) && length > 0.0, "distance: length must be positive and finite");
    for (Attachment3& e : ends) {
      detail::require(std::isfinite(e.s.x) && std::isfinite(e.s.y) && std::isfinite(e.s.z),
                      "distance: point is not finite");
      e.fold_constant();
    }
  }
  /// @copydoc DistanceSpec::sketch
  /// A spatial distance draws its bar, and the arms of the bodies it joins.
  template <class Sketch>
  void sketch(Sketch& sk) const {
    sk.bar3(ends[0], ends[1], length);
    sk.arm3(ends[0]);
    sk.arm3(ends[1]);
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {
      {"constraints", "distance", 3, "- {name: coupler, type: distance, points: [P0, P1], length: 1}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static SpatialDistanceSpec read(const Fields& f) {
    f.expect({"type", "name", "points", "between", "length"});
    SpatialDistanceSpec spec;
    if (f.present("points") == f.present("between"))
      f.fail("", "a distance has either 'points' (natural points) or 'between' (attachments)");
    if (f.present("points")) {
      const auto [pa, pb] = f.point3_pair("points", "a distance joins two points [A, B]");
      spec.ends[0] = Attachment3::natural(pa);
      spec.ends[1] = Attachment3::natural(pb);
    } else {
      const auto [sa, sb] = f.sides3("between");
      spec.ends[0] = Attachment3::body_point(sa.frame, sa.at);
      spec.ends[1] = Attachment3::body_point(sb.frame, sb.at);
    }
    spec.length = f.positive("length");
    return spec;
  }

 private:
  static constexpr detail3::RowDef kDef = {detail3::T(1, 0), detail3::T(1, 0), Unit::kLength};
};

}  // namespace phiq
