/// @file
/// Gears between two shafts in space (spur and helical on parallel shafts, bevel, crossed helical, worm): the shafts'
/// rotations in their bearings, tied by the tooth ratio. One constraint kind: its equation, derivatives, validation,
/// joint count, sketch and scene form; the contract is documented on DistanceSpec, and kinds/registry.hpp lists every
/// kind.
#pragma once

#include <array>
#include <cmath>
#include <numbers>
#include <tuple>

#include "phiq/kinds/spatial_joints.hpp"
#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// A spatial gear pair as its teeth push its shafts (SpatialGearSpec::spatial_mesh(), add_gear_mesh_forces()): its
/// ratio row θ1 + k θ2 − φ turns the shafts' angles by torques; the teeth push at the pitch point P, on both pitch
/// cones (pitch cylinders, for parallel shafts), at r1 from axis 1 and r2 from axis 2 in the plane of the axes, which
/// loads the shafts' bearings as well.
struct SpatialMesh {
  JointSide3 a1;                ///< shaft 1's housing (its joint's side a: z its axis)
  JointSide3 b1;                ///< shaft 1 (its joint's side b)
  JointSide3 a2;                ///< shaft 2's housing
  JointSide3 b2;                ///< shaft 2
  Slot theta1;                  ///< shaft 1's angle, which the ratio row relates
  Slot theta2;                  ///< shaft 2's angle
  double k = 1.0;               ///< the ratio row's coefficient of θ2
  double r1 = 0.0;              ///< gear 1's mean pitch radius (m); 0 for tooth counts, which do not place P
  double r2 = 0.0;              ///< gear 2's (m)
  double pressure_angle = 0.0;  ///< α (rad): the teeth part the gears by tan α of their push
  bool reversed = false;        ///< the relation z1 θ1 − z2 θ2: an axis away from its gear (P not placed)
  double helix_angle = 0.0;     ///< ψ (rad) of gear 1's teeth on parallel shafts: > 0 right-handed
  double mesh_offset = 0.0;     ///< parallel shafts: the gears' mid-plane, this far along axis 1 from shaft 1's point
};

/// Two gears on parallel shafts, as their push (add_gear_mesh_forces()) and their drawn pitch circles place them.
struct ParallelPitch {
  kin3::V3 rho;     ///< the unit from axis 1 toward axis 2, across them
  double a = 0.0;   ///< the distance between the axes
  double r1 = 0.0;  ///< the pitch radius of gear 1 that, with r2 = ratio r1, fills it; 0 where none does
  double r2 = 0.0;  ///< gear 2's
};

/// Whether a pair on parallel shafts is internal (a ring gear): it turns its shafts the same way, so its ratio row
/// is reversed where the axes point the same way (cos_axes = z1 · z2 > 0), and not where they point opposite ways.
inline bool parallel_pair_internal(double cos_axes, bool reversed) { return (cos_axes > 0.0) == reversed; }

/// Axis 1 through `centre1` along the unit `axis`, axis 2 through `on2`, parallel to it; `ratio` = r2/r1 > 0. The
/// pitch radii fill the distance a: r1 = a/(1 + ratio), or a/|ratio − 1| for an internal pair (none for equal
/// gears, or one axis).
inline ParallelPitch parallel_pitch(kin3::V3 centre1, kin3::V3 axis, kin3::V3 on2, bool internal, double ratio) {
  ParallelPitch p;
  const kin3::V3 across = (on2 - centre1) - kin3::dot(on2 - centre1, axis) * axis;
  p.a = kin3::norm(across);
  if (!(p.a > 0.0)) return p;
  p.rho = (1.0 / p.a) * across;
  const double span = internal ? std::fabs(ratio - 1.0) : 1.0 + ratio;
  if (span > 1e-12) p.r1 = p.a / span, p.r2 = ratio * p.r1;
  return p;
}

/// Spatial gear pair. Each shaft turns in a joint (revolute, cylindrical or screw) whose side a is the housing —
/// ground, or a carrier that moves — and side b the shaft; θ_i, an angle coordinate, is the shaft's turn in it (x_b
/// about z_a from x_a, as `rotation_angle` measures it). The gears roll on each other: in the housing the relative
/// rotations obey the ratio of the tooth counts z_i (or pitch radii, for bevel gears):
///   Φ = [θ(J1) − θ1;  θ(J2) − θ2  (each wrapped to (−π, π], kinds/spatial_mixed.hpp);   (2 rows, angles)
///        θ1 ± (z2/z1) θ2 − φ]                                                            (1 row, an angle)
/// Why +: for a bevel pair with each joint's axis z_a pointing from the apex (where the axes cross) toward its gear,
/// a pitch point P on the line of contact between the axes moves on gear 1 by θ̇1 z1 × P = r1 θ̇1 n and on gear 2 by
/// θ̇2 z2 × P = −r2 θ̇2 n (n = z1 × z2 / |z1 × z2|, r_i the distance of P from axis i), so rolling is
/// r1 θ̇1 + r2 θ̇2 = 0 at any shaft angle, with r1/r2 = z1/z2. `reversed` takes − (the relation z1 θ1 − z2 θ2 = z1 φ):
/// an axis given the other way, or a crossed helical pair whose hands turn it the other way (for crossed helical
/// gears and worms give the tooth counts — a worm's is its number of starts —, not the pitch radii, which do not
/// make the ratio there). The angles must be coordinates
/// because a ratio holds between turns, not orientations: 2.5 turns of one gear and half a turn of the other leave
/// the same orientations. On parallel shafts (spur and helical gears) the same rows hold: + for an external pair
/// whose axes point the same way, − (`reversed`) for an internal one (a ring gear) or axes pointing opposite ways.
/// One joint for both shafts is refused. Scene type `spatial_gear`: `shafts: [J1, J2]` (named joints above it),
/// `angles: [θ1, θ2]` (coordinates), `teeth: [z1, z2]` or `radii: [r1, r2]` (the mean pitch radii, for the
/// bearings' loads: spatial_mesh()), `reversed` (false), `phase: φ` (0), `pressure_angle: α` (rad, 20°),
/// `pitch_radii: [r1, r2]` (m: for the bearings' loads where the teeth give the ratio, as a worm's do); on parallel
/// shafts `helix_angle: ψ` (rad, 0; > 0: gear 1's teeth right-handed) and `mesh_offset: s` (m, 0: the gears'
/// mid-plane, s along shaft 1's axis from its joint's point), for the bearings' loads too.
struct SpatialGearSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const SpatialGearSpec&) const = default;
  static constexpr int kRows = 3;  ///< the two shafts' angles and the ratio
  /// @copydoc DistanceSpec::kKind
  static constexpr const char* kKind = "spatial_gear";
  JointSide3 a1;          ///< shaft 1's joint, side a: the housing (its z is the axis)
  JointSide3 b1;          ///< shaft 1's joint, side b: the shaft
  JointSide3 a2;          ///< shaft 2's joint, side a
  JointSide3 b2;          ///< shaft 2's joint, side b
  Slot theta1;            ///< θ1 (rad): a coordinate
  Slot theta2;            ///< θ2 (rad): a coordinate
  double z1 = 1.0;        ///< gear 1's tooth count (or pitch radius), > 0
  double z2 = 1.0;        ///< gear 2's tooth count (or pitch radius), > 0
  bool reversed = false;  ///< the relation z1 θ1 − z2 θ2 = z1 φ
  double phase = 0.0;     ///< φ (rad)
  bool teeth = false;     ///< z1 and z2 are tooth counts, not radii
  double pitch_r1 = 0.0;  ///< gear 1's pitch radius (m) for its bearings' loads; 0: z1 if radii
  double pitch_r2 = 0.0;  ///< gear 2's
  double pressure_angle = detail::kPressureAngle;  ///< α (rad): its bearings' loads only (SpatialMesh)
  double helix_angle = 0.0;                        ///< ψ (rad), parallel shafts: their bearings' loads only
  double mesh_offset = 0.0;                        ///< s (m), parallel shafts: their bearings' loads only
  std::array<Attachment3, 4> att1{};               ///< derived by setup(): x_a, y_a, z_a, x_b of shaft 1's joint
  std::array<Attachment3, 4> att2{};               ///< the same of shaft 2's joint

  /// Validates the joints and derives the attachments. Throws phiq::Error.
  void setup() {
    static constexpr std::int8_t kIndex[4] = {detail3::kXa, detail3::kYa, detail3::kZa, detail3::kXb};
    detail::require(std::isfinite(z1) && std::isfinite(z2) && z1 > 0.0 && z2 > 0.0,
                    "spatial_gear: the tooth counts (or radii) must be positive");
    detail::require(std::isfinite(phase), "spatial_gear: phase is not finite");
    detail::require(detail::is_pressure_angle(pressure_angle), "spatial_gear: pressure_angle must be in [0, pi/2) rad");
    detail::require(std::isfinite(helix_angle) && std::fabs(helix_angle) < std::numbers::pi / 2,
                    "spatial_gear: helix_angle must be in (-pi/2, pi/2) rad");
    detail::require(std::isfinite(mesh_offset), "spatial_gear: mesh_offset is not finite");
    detail::require(
        pitch_r1 == 0.0 || (std::isfinite(pitch_r1) && std::isfinite(pitch_r2) && pitch_r1 > 0.0 && pitch_r2 > 0.0),
        "spatial_gear: pitch_radii must be positive");
    detail::require(theta1.is_coordinate() && theta2.is_coordinate() && theta1.coord() != theta2.coord(),
                    "spatial_gear: the angles must be two different coordinates");
    const auto j1 = detail3::joint_attachments(a1, b1, kIndex, 4, kKind);
    const auto j2 = detail3::joint_attachments(a2, b2, kIndex, 4, kKind);
    std::copy_n(j1.begin(), 4, att1.begin());
    std::copy_n(j2.begin(), 4, att2.begin());
  }
  /// @copydoc DistanceSpec::depends_on_time
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kAngle; }
  /// @copydoc DistanceSpec::characteristic_length
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  template <class F>
  void for_each_slot(F&& f) const {
    detail3::side_slots(a1, f), detail3::side_slots(b1, f), detail3::side_slots(a2, f), detail3::side_slots(b2, f);
    f(theta1, Unit::kAngle), f(theta2, Unit::kAngle);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    phi[0] = kAngle.minus(att1.data(), q, theta1.of(q));
    phi[1] = kAngle.minus(att2.data(), q, theta2.of(q));
    phi[2] = theta1.of(q) + ratio() * theta2.of(q) - phase;
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    kAngle.emit(att1.data(), q, s, 0);
    s(0, theta1, -1.0);
    kAngle.emit(att2.data(), q, s, 1);
    s(1, theta2, -1.0);
    s(2, theta1, 1.0), s(2, theta2, ratio());
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = out[1] = out[2] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double, double* out) const {
    out[0] = -kAngle.bias(att1.data(), q, qd);
    out[1] = -kAngle.bias(att2.data(), q, qd);
    out[2] = 0.0;
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the shafts' sides through their attachments, the
  /// tooth counts and the phase.
  static constexpr auto data_members() {
    return std::tuple{&SpatialGearSpec::a1,    &SpatialGearSpec::b1,   &SpatialGearSpec::a2,
                      &SpatialGearSpec::b2,    &SpatialGearSpec::z1,   &SpatialGearSpec::z2,
                      &SpatialGearSpec::phase, &SpatialGearSpec::att1, &SpatialGearSpec::att2};
  }
  /// Derivatives along the data (DistanceSpec::data_derivative()): the shafts' angles along their attachments
  /// (detail3::AngleRows::data_derivative()); the ratio row θ1 + k θ2 − φ, k = ±z2/z1, as k̂ θ2⁽ⁿ⁾ − φ̂ δ_n0 with
  /// k̂ = ±(ẑ2 z1 − z2 ẑ1)/z1².
  void data_derivative(const SpatialGearSpec& rate, int order, const double* q, const double* qd, const double* qdd,
                       double, double* out) const {
    out[0] = kAngle.data_derivative(att1.data(), rate.att1.data(), order, q, qd, qdd);
    out[1] = kAngle.data_derivative(att2.data(), rate.att2.data(), order, q, qd, qdd);
    const double kh = (reversed ? -1.0 : 1.0) * (rate.z2 * z1 - z2 * rate.z1) / (z1 * z1);
    const double* v = order == 0 ? q : order == 1 ? qd : qdd;
    out[2] = kh * theta2.of(v) - (order == 0 ? rate.phase : 0.0);  // θ2 is a coordinate
  }
  /// @copydoc DistanceSpec::joint_count
  /// Two angle coordinates and their rows count for nothing; the mesh removes one freedom.
  JointCount joint_count() const { return JointCount::joint(3, 1); }
  /// @copydoc DistanceSpec::prepare
  /// setup(), then the shafts' axes at the placement: a helix angle or a mesh offset is refused unless they are
  /// parallel (crossed helical gears' helices make their shafts' angle; a bevel pair's apex places its mesh).
  void prepare(const double* q0) {
    setup();
    const kin3::V3 u = att1[2].value(q0), v = att2[2].value(q0);
    const bool parallel = kin3::norm(kin3::cross(u, v)) <= 1e-6 * kin3::norm(u) * kin3::norm(v);
    detail::require(parallel || (helix_angle == 0.0 && mesh_offset == 0.0),
                    "spatial_gear: helix_angle and mesh_offset are for parallel shafts (these are not at the "
                    "placement)");
  }
  /// @copydoc DistanceSpec::sketch
  /// A spatial gear's shafts are drawn by their joints; it draws its two pitch circles, on the shafts (sides b),
  /// of the ratio z1 : z2, at the pitch cones' bases about the point where the axes cross (parallel shafts: filling
  /// the distance between the axes, in the gears' mid-plane).
  template <class Sketch>
  void sketch(Sketch& sk) const {
    sk.spatial_gear_pair(a1, b1, a2, b2, z1, z2, reversed, mesh_offset);
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {{"constraints", "spatial_gear", 3,
                                          "- {name: bevel, type: spatial_gear, shafts: [input_bearing, "
                                          "output_bearing], angles: [theta1, theta2], teeth: [15, 30]}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static SpatialGearSpec read(const Fields& f) {
    f.expect({"type", "name", "shafts", "angles", "teeth", "radii", "reversed", "phase", "pressure_angle",
              "pitch_radii", "helix_angle", "mesh_offset"});
    SpatialGearSpec g;
    const auto [j1, j2] = f.turning_joints("shafts");
    std::tie(g.a1, g.b1) = j1;
    std::tie(g.a2, g.b2) = j2;
    const auto [i, j] = f.coordinate_pair("angles");
    g.theta1 = Slot::coordinate(i), g.theta2 = Slot::coordinate(j);
    std::tie(g.z1, g.z2) = f.radii_or_teeth();
    g.teeth = f.present("teeth");
    if (f.present("reversed")) g.reversed = f.boolean("reversed");
    if (f.present("phase")) g.phase = f.number("phase");
    if (f.present("pressure_angle")) g.pressure_angle = f.number("pressure_angle");
    if (f.present("pitch_radii")) std::tie(g.pitch_r1, g.pitch_r2) = f.number_pair("pitch_radii");
    if (f.present("helix_angle")) g.helix_angle = f.number("helix_angle");
    if (f.present("mesh_offset")) g.mesh_offset = f.number("mesh_offset");
    return g;
  }
  /// The mesh as a push on the shafts' bearings (SpatialMesh).
  SpatialMesh spatial_mesh() const {
    SpatialMesh m{a1,
                  b1,
                  a2,
                  b2,
                  theta1,
                  theta2,
                  ratio(),
                  teeth ? 0.0 : z1,
                  teeth ? 0.0 : z2,
                  pressure_angle,
                  reversed,
                  helix_angle,
                  mesh_offset};
    if (pitch_r1 > 0.0) m.r1 = pitch_r1, m.r2 = pitch_r2;
    return m;
  }

 private:
  // c = x_b · x_a, s = x_b · y_a in each shaft's attachments (x_a, y_a, z_a, x_b)
  static constexpr detail3::AngleRows kAngle{{detail3::T(3), detail3::T(0), Unit::kNone},
                                             {detail3::T(3), detail3::T(1), Unit::kNone}};
  double ratio() const { return (reversed ? -z2 : z2) / z1; }
};

}  // namespace phiq
