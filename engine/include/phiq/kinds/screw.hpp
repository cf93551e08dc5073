/// @file
/// The screw (helical) joint in space: a cylindrical joint whose rotation and travel along the axis are tied by
/// the pitch. One constraint kind: its equation, derivatives, validation, joint count, sketch and scene form; the
/// contract is documented on DistanceSpec, and kinds/registry.hpp lists every kind.
#pragma once

#include <cmath>
#include <numbers>

#include "phiq/kinds/spatial_joints.hpp"
#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// Screw joint: the cylindrical joint's rows (the axes parallel, P_b on the line of a), and the travel
/// d = z_a · (P_b − P_a) along the axis tied to the turn θ of x_b about z_a (from x_a, as the joint angle driver
/// measures it: c = x_a · x_b, s = y_a · x_b) by the pitch p, z = p θ / 2π:
///   Φ = [x_a · z_b;  y_a · z_b;  x_a · (P_b − P_a);  y_a · (P_b − P_a);                  (4 rows: the cylindrical)
///        atan2(s cos f − c sin f, c cos f + s sin f)],   f = 2π d / p                  (1 row, an angle)
/// The last row is θ − 2π d/p wrapped to (−π, π]: it holds the angle of the turn modulo 2π against the travel, which
/// fixes the number of turns too (each turn is one pitch of travel), so no angle coordinate is needed and the
/// screw runs through any number of turns. Its derivatives are those of θ (detail3::AngleRows) minus 2π/p times
/// those of d. p > 0 is a right-handed thread, p < 0 a left-handed one; p = 0 (a revolute joint) is refused.
/// Both sides must be bodies or ground. Scene type `screw`: `between: [S1, S2]`, `pitch: p` (m per turn).
struct ScrewSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const ScrewSpec&) const = default;

 private:
  // the cylindrical rows, then c, s and d
  static constexpr detail3::RowDef kDefs[7] = {
      {detail3::T(detail3::kXa), detail3::T(detail3::kZb), Unit::kAngle},
      {detail3::T(detail3::kYa), detail3::T(detail3::kZb), Unit::kAngle},
      {detail3::T(detail3::kXa), detail3::T(detail3::kPb, detail3::kPa), Unit::kLength},
      {detail3::T(detail3::kYa), detail3::T(detail3::kPb, detail3::kPa), Unit::kLength},
      {detail3::T(detail3::kXa), detail3::T(detail3::kXb), Unit::kNone},
      {detail3::T(detail3::kYa), detail3::T(detail3::kXb), Unit::kNone},
      {detail3::T(detail3::kZa), detail3::T(detail3::kPb, detail3::kPa), Unit::kLength}};

 public:
  static constexpr int kRows = 5;  ///< the cylindrical joint's 4 rows and the helix
  /// @copydoc DistanceSpec::kKind
  static constexpr const char* kKind = "screw";
  /// Its angle and its travel (tied by the pitch): output, driven (either one), and a shaft.
  static constexpr JointTraits kJoint{
      .measures = {.angle = true, .distance = true}, .drives = {.angle = true, .distance = true}, .shaft = true};
  /// @var a
  /// @brief Side a (the nut, or ground): its axis z_a is the screw's axis.
  JointSide3 a, b;     ///< side b (the screw)
  double pitch = 1.0;  ///< p, the travel per turn (m), non-zero; negative for a left-handed thread
  /// The rows' attachments and the rows renumbered into them (detail3::compact_rows).
  static constexpr auto kCompact = detail3::compact_rows(kDefs);
  std::array<Attachment3, kCompact.count> att{};  ///< derived by setup(): the attachments the rows read

  /// Validates the sides and the pitch and derives `att`. Throws phiq::Error.
  void setup() {
    detail::require(std::isfinite(pitch), "screw: pitch is not finite");
    detail::require(pitch != 0.0, "screw: the pitch must not be zero (a screw of no pitch is a revolute joint)");
    detail3::set_up_attachments(a, b, kCompact, kKind, att);
  }
  /// The values its reaction has (ConstraintBlock::reaction_width()): Fx, Fy, Fz, Mx, My, Mz, as a spatial joint's.
  static constexpr int kReactionWidth = 6;
  /// The reaction (ReactionSite) as a spatial joint's: on the nut's body (side a), or on the screw's when the nut is
  /// ground, at side a's point; its axes side a's joint frame. Along z there the thread ties the two loads it
  /// carries: no work in the turn and travel it lets through, Mz = −p Fz / 2π.
  ReactionSite reaction_site(const double* q) const { return detail3::joint_reaction_site(a, b, q); }
  /// @copydoc DistanceSpec::depends_on_time
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  Unit row_unit(int r, const std::vector<Unit>&) const { return r < 4 ? kDefs[r].unit : Unit::kAngle; }
  /// @copydoc DistanceSpec::characteristic_length
  /// For a screw: the longer arm |at| of a moving side, as for a joint.
  double characteristic_length() const { return detail3::joint_arm(a, b); }
  /// @copydoc DistanceSpec::for_each_slot
  template <class F>
  void for_each_slot(F&& f) const {
    detail3::side_slots(a, f), detail3::side_slots(b, f);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    for (int r = 0; r < 4; ++r) phi[r] = detail3::row_value(att.data(), kCompact.rows[r], q, 1.0, 0.0);
    phi[4] = angle().minus(att.data(), q, k() * detail3::row_value(att.data(), kCompact.rows[6], q, 1.0, 0.0));
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    for (int r = 0; r < 4; ++r) detail3::row_jacobian(att.data(), kCompact.rows[r], q, s, r, 1.0);
    angle().emit(att.data(), q, s, 4);
    detail3::row_jacobian(att.data(), kCompact.rows[6], q, s, 4, -k());
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const {
    for (int r = 0; r < kRows; ++r) out[r] = 0.0;
  }
  /// @copydoc DistanceSpec::gamma
  /// The helix: γ = −(θ̈'s q̈-free part) + 2π/p (d̈'s q̈-free part).
  void gamma(const double* q, const double* qd, double, double* out) const {
    for (int r = 0; r < 4; ++r) out[r] = detail3::row_gamma(att.data(), kCompact.rows[r], q, qd, 1.0);
    out[4] = -angle().bias(att.data(), q, qd) - k() * detail3::row_gamma(att.data(), kCompact.rows[6], q, qd, 1.0);
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the sides, through their attachments, and the
  /// pitch.
  static constexpr auto data_members() {
    return std::tuple{&ScrewSpec::a, &ScrewSpec::b, &ScrewSpec::att, &ScrewSpec::pitch};
  }
  /// Derivatives along the data (DistanceSpec::data_derivative()): the four rows of the axis along the attachments
  /// (detail3::row_data_derivative()); the helix θ − k d, k = 2π/p, as θ's (AngleRows::data_derivative()) minus
  /// k̂ d⁽ⁱ⁾ + k d̂⁽ⁱ⁾, k̂ = −2π p̂/p².
  void data_derivative(const ScrewSpec& rate, int order, const double* q, const double* qd, const double* qdd, double,
                       double* out) const {
    for (int r = 0; r < 4; ++r)
      out[r] = detail3::row_data_derivative(att.data(), rate.att.data(), kCompact.rows[r], order, q, qd, qdd);
    const double kh = -2.0 * std::numbers::pi * rate.pitch / (pitch * pitch);
    const detail3::RowDerivatives d =
        detail3::row_derivatives(att.data(), rate.att.data(), kCompact.rows[6], order, q, qd, qdd);
    out[4] = angle().data_derivative(att.data(), rate.att.data(), order, q, qd, qdd) - kh * d.value[order] -
             k() * d.along[order];
  }
  /// @copydoc DistanceSpec::joint_count
  /// A screw between bodies or ground removes 5 freedoms (one left: the turn and travel together).
  JointCount joint_count() const { return JointCount::joint(3, kRows); }
  /// @copydoc DistanceSpec::prepare
  /// For a screw: setup().
  void prepare(const double* /*q0*/) { setup(); }
  /// @copydoc DistanceSpec::sketch
  /// A screw draws the arms of its bodies and a hinge at its point; on the parts a shaft in a sleeve, and its
  /// thread (a helix of lead `pitch`) about side b's axis.
  template <class Sketch>
  void sketch(Sketch& sk) const {
    detail3::sketch_joint(a, b, JointMark::kRevolute, JointForm::kShaft, sk);
    sk.thread3(b, pitch);
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {
      {"constraints", "screw", 3,
       "- {name: lead_screw, type: screw, between: [{body: ground, axis: [0, 0, 1]}, "
       "{body: nut, axis: [0, 0, 1]}], pitch: 0.005}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static ScrewSpec read(const Fields& f) {
    f.expect({"type", "name", "between", "pitch"});
    ScrewSpec spec;
    std::tie(spec.a, spec.b) = f.sides3("between");
    spec.pitch = f.number("pitch");
    return spec;
  }

 private:
  static detail3::AngleRows angle() { return {kCompact.rows[4], kCompact.rows[5]}; }
  double k() const { return 2.0 * std::numbers::pi / pitch; }  // radians per metre of travel
};

}  // namespace phiq
