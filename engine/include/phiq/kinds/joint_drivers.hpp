/// @file
/// Drivers on a spatial joint: its translation or its rotation, as the joint's kind allows (JointTraits::drives:
/// a prismatic's translation, a revolute's rotation, a cylindrical's or a screw's either). One constraint kind each:
/// equation, derivatives, validation, joint count, sketch and scene form; the contract is documented on
/// DistanceSpec, and kinds/registry.hpp lists every kind.
#pragma once

#include <cmath>

#include "phiq/motion_law.hpp"
#include "phiq/kinds/spatial_joints.hpp"
#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// Driver on the translation of a joint (prismatic, cylindrical, screw): the distance of P_b from P_a along z_a.
///   Φ = z_a · (P_b − P_a) − f(t),   Φt = −f'(t)        (1 row, a length)
/// Scene: a driver `{joint: NAME, measure: distance}`.
struct JointDistanceDriverSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const JointDistanceDriverSpec&) const = default;

  /// @copydoc DistanceSpec::joint_count
  /// A driver is not counted.
  JointCount joint_count() const { return JointCount::driver(); }
  /// @copydoc DistanceSpec::prepare
  /// For a joint driver: setup().
  void prepare(const double* /*q0*/) { setup(); }
  /// @copydoc DistanceSpec::sketch
  /// A driver draws nothing: its joint's bodies are drawn by their constraints.
  template <class Sketch>
  void sketch(Sketch&) const {}
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {{"drivers", "joint (measure: distance)", 3,
                                          "- {name: push, joint: slider, "
                                          "measure: distance, law: {type: linear, initial: 0, rate: 0.1}}"}};

 private:
  static constexpr detail3::RowDef kDefs[1] = {
      {detail3::T(detail3::kZa), detail3::T(detail3::kPb, detail3::kPa), Unit::kLength}};

 public:
  static constexpr int kRows = 1;  ///< one row, a length
  /// @copydoc DistanceSpec::kKind
  static constexpr const char* kKind = "joint_distance_driver";
  /// @var a
  /// @brief Side a of the driven joint.
  JointSide3 a, b;  ///< side b of the driven joint
  MotionLaw law;    ///< f(t), metres
  /// The row's attachments and the row renumbered into them (detail3::compact_rows).
  static constexpr auto kCompact = detail3::compact_rows(kDefs);
  std::array<Attachment3, kCompact.count> att{};  ///< derived by setup(): the attachments the row reads

  /// Validates the sides and derives `att`. Throws phiq::Error.
  void setup() { detail3::set_up_attachments(a, b, kCompact, kKind, att); }
  /// @copydoc DistanceSpec::depends_on_time
  bool depends_on_time() const { return true; }
  /// @copydoc DistanceSpec::row_unit
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  template <class F>
  void for_each_slot(F&& f) const {
    detail3::side_slots(a, f), detail3::side_slots(b, f);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double t, double* phi) const {
    phi[0] = detail3::row_value(att.data(), kCompact.rows[0], q, 1.0, law.evaluate(t).f);
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    detail3::row_jacobian(att.data(), kCompact.rows[0], q, s, 0, 1.0);
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double t, double* out) const { out[0] = -law.evaluate(t).df; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double t, double* out) const {
    out[0] = detail3::row_gamma(att.data(), kCompact.rows[0], q, qd, 1.0) + law.evaluate(t).ddf;
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the sides, through their attachments
  /// (SpatialJointSpec::data_members()), and the law.
  static constexpr auto data_members() {
    return std::tuple{&JointDistanceDriverSpec::a, &JointDistanceDriverSpec::b, &JointDistanceDriverSpec::att,
                      &JointDistanceDriverSpec::law};
  }
  /// Derivatives along the data (DistanceSpec::data_derivative()): the row X · Y − f(t) along its attachments
  /// (detail3::row_data_derivative()) and its law (CoordinateDriverSpec::data_derivative()).
  void data_derivative(const JointDistanceDriverSpec& rate, int order, const double* q, const double* qd,
                       const double* qdd, double t, double* out) const {
    out[0] = detail3::row_data_derivative(att.data(), rate.att.data(), kCompact.rows[0], order, q, qd, qdd) +
             detail::minus_law_rate(rate.law, order, t);
  }
};

/// Driver on the rotation of a joint (revolute, cylindrical, screw): the angle θ of x_b about z_a measured from x_a,
/// with c = x_a · x_b and s = y_a · x_b (so x_b = cos θ x_a + sin θ y_a when the axes are aligned):
///   Φ = atan2(s cos f − c sin f,  c cos f + s sin f)     = θ − f(t) wrapped to (−π, π]
/// The difference is taken as the angle of (c, s) turned back by f, not as atan2(s, c) − f: smooth at any θ, so a
/// driver runs through any number of turns. Φq = (c ∂s − s ∂c) / (c² + s²), Φt = −f'(t).
/// Both sides must be bodies or ground. Scene: a driver `{joint: NAME}` (`measure: angle`).
struct JointAngleDriverSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const JointAngleDriverSpec&) const = default;

 private:
  // c = x_a · x_b and s = y_a · x_b
  static constexpr detail3::RowDef kDefs[2] = {{detail3::T(detail3::kXa), detail3::T(detail3::kXb), Unit::kNone},
                                               {detail3::T(detail3::kYa), detail3::T(detail3::kXb), Unit::kNone}};

 public:
  static constexpr int kRows = 1;  ///< one row, an angle
  /// @copydoc DistanceSpec::kKind
  static constexpr const char* kKind = "joint_angle_driver";
  /// @var a
  /// @brief Side a of the driven joint.
  JointSide3 a, b;  ///< side b of the driven joint
  MotionLaw law;    ///< f(t), radians
  /// The two products' attachments and the products renumbered into them (detail3::compact_rows).
  static constexpr auto kCompact = detail3::compact_rows(kDefs);
  std::array<Attachment3, kCompact.count> att{};  ///< derived by setup(): the attachments c and s read

  /// Validates the sides and derives `att`. Throws phiq::Error.
  void setup() { detail3::set_up_attachments(a, b, kCompact, kKind, att); }
  /// @copydoc DistanceSpec::depends_on_time
  bool depends_on_time() const { return true; }
  /// @copydoc DistanceSpec::row_unit
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kAngle; }
  /// @copydoc DistanceSpec::characteristic_length
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  template <class F>
  void for_each_slot(F&& f) const {
    detail3::side_slots(a, f), detail3::side_slots(b, f);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double t, double* phi) const {
    phi[0] = angle().minus(att.data(), q, law.evaluate(t).f);
  }
  /// @copydoc DistanceSpec::jacobian
  /// @par Joint angle driver
  /// The entries of ∂c (scaled by −s/ρ) and then of ∂s (scaled by c/ρ), ρ = c² + s²; x_b appears in both and its
  /// entries add up (detail3::AngleRows).
  template <class Sink>
  void jacobian(const double* q, double, Sink& sink) const {
    angle().emit(att.data(), q, sink, 0);
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double t, double* out) const { out[0] = -law.evaluate(t).df; }
  /// @copydoc DistanceSpec::gamma
  /// @par Joint angle driver
  /// θ̈ = (c s̈ − s c̈)/ρ − (c ṡ − s ċ) ρ̇/ρ², ρ̇ = 2 (c ċ + s ṡ); γ keeps the q̈-free parts of c̈, s̈, plus f''(t).
  void gamma(const double* q, const double* qd, double t, double* out) const {
    out[0] = -angle().bias(att.data(), q, qd) + law.evaluate(t).ddf;
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the sides, through their attachments (the
  /// reference directions the angle is measured from), and the law.
  static constexpr auto data_members() {
    return std::tuple{&JointAngleDriverSpec::a, &JointAngleDriverSpec::b, &JointAngleDriverSpec::att,
                      &JointAngleDriverSpec::law};
  }
  /// Derivatives along the data (DistanceSpec::data_derivative()): θ's along the attachments
  /// (detail3::AngleRows::data_derivative()) and the law's, which enters the row as − f(t)
  /// (CoordinateDriverSpec::data_derivative()).
  void data_derivative(const JointAngleDriverSpec& rate, int order, const double* q, const double* qd,
                       const double* qdd, double t, double* out) const {
    out[0] = angle().data_derivative(att.data(), rate.att.data(), order, q, qd, qdd) +
             detail::minus_law_rate(rate.law, order, t);
  }

  /// @copydoc DistanceSpec::joint_count
  /// A driver is not counted.
  JointCount joint_count() const { return JointCount::driver(); }
  /// @copydoc DistanceSpec::prepare
  /// For a joint driver: setup().
  void prepare(const double* /*q0*/) { setup(); }
  /// @copydoc DistanceSpec::sketch
  /// A driver draws nothing: its joint's bodies are drawn by their constraints.
  template <class Sketch>
  void sketch(Sketch&) const {}
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {{"drivers", "joint (measure: angle)", 3,
                                          "- {name: crank_motor, "
                                          "joint: crank_hinge, law: {type: linear, initial: 0, rate: 1}}"}};

 private:
  // c = x_a · x_b and s = y_a · x_b
  static detail3::AngleRows angle() { return {kCompact.rows[0], kCompact.rows[1]}; }
};

}  // namespace phiq
