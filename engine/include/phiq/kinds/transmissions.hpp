/// @file
/// The transmissions between angles: a gear pair (external or internal, with the carrier of an epicyclic train),
/// a rack and pinion, and a belt or chain (open or crossed). Three constraint kinds, each one linear row in angle
/// (or travel) coordinates, written as the named relation a machine designer states instead of the generic
/// `coupler` (kinds/coupler.hpp); they share its evaluation (detail::LinearRow below). The contract is documented
/// on DistanceSpec, and kinds/registry.hpp lists every kind.
///
/// Angles are coordinates: a planar body's ψ (a scene names the body), or an angle coordinate, such as the
/// rotation of a spatial body about an axis (`rotation_angle`, kinds/spatial_mixed.hpp). The relations hold
/// between the angles themselves, not between their values modulo 2π, so a gear pair turns through any number of
/// turns at any ratio (a relation of orientations alone could not: 2.5 turns of one gear and 0.5 turn of the other
/// leave the same orientations).
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>

#include "phiq/kinds/kind_support.hpp"
#include "phiq/kinds/reaction_site.hpp"

namespace phiq {

/// @cond internal
namespace detail {
// A row Σ w_k q_k − c over three slots (a constant slot adds w_k times its value and emits no entry): what every
// transmission evaluates. Φ is linear in q: Φt = 0, γ = 0.
struct LinearRow {
  bool operator==(const LinearRow&) const = default;
  std::array<Slot, 3> slot{Slot::constant(0), Slot::constant(0), Slot::constant(0)};
  std::array<double, 3> w{0.0, 0.0, 0.0};
  double c = 0.0;

  double value(const double* q) const { return w[0] * slot[0].of(q) + w[1] * slot[1].of(q) + w[2] * slot[2].of(q) - c; }
  template <class Sink>
  void emit(Sink& s) const {
    s(0, slot[0], w[0]), s(0, slot[1], w[1]), s(0, slot[2], w[2]);
  }
};
// Radii (or tooth counts) of a pair: positive and finite, else "KIND: WHAT must be positive".
inline void require_positive_pair(double r1, double r2, const char* message) {
  require(std::isfinite(r1) && std::isfinite(r2) && r1 > 0.0 && r2 > 0.0, message);
}
}  // namespace detail
/// @endcond

/// What the transmissions share: one time-independent row, linear in q (`Derived::row()`, a detail::LinearRow), so
/// Φt = 0 and γ = 0; a higher pair removing one freedom in the scene's dimension (`Derived::dimension`). Each kind's
/// sketch() draws its own geometry (the bodies are drawn by their joints).
template <class Derived>
struct LinearTransmission {
  /// No data of its own: the derived kind's operator== compares its own.
  bool operator==(const LinearTransmission&) const = default;
  /// @copydoc phiq::DistanceSpec::depends_on_time
  bool depends_on_time() const { return false; }
  /// @copydoc phiq::DistanceSpec::residual
  void residual(const double* q, double, double* phi) const { phi[0] = self().row().value(q); }
  /// @copydoc phiq::DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double*, double, Sink& s) const {
    self().row().emit(s);
  }
  /// @copydoc phiq::DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  /// @copydoc phiq::DistanceSpec::gamma
  void gamma(const double*, const double*, double, double* out) const { out[0] = 0.0; }
  /// Derivatives along the data (DistanceSpec::data_derivative()): the row Σ w_k q_k − c is linear in q, its
  /// coefficients and constants functions of the data whose rates `Derived::row_rate(rate)` gives (ŵ, ĉ, and the
  /// rates of constant slots), so ∂Φ/∂p = Σ ŵ_k q_k + Σ_constants w_k q̂_k − ĉ, and the higher orders Σ ŵ_k q_k⁽ᵏ⁾
  /// (Φt = γ = 0).
  void data_derivative(const Derived& rate, int order, const double* q, const double* qd, const double* qdd, double,
                       double* out) const {
    const detail::LinearRow row = self().row(), r = self().row_rate(rate);
    double sum = 0.0;
    for (int k = 0; k < 3; ++k) {
      if (order == 0) {
        sum += r.w[k] * row.slot[k].of(q);
        if (!row.slot[k].is_coordinate()) sum += row.w[k] * r.slot[k].value();
      } else {
        sum += r.w[k] * row.slot[k].rate(order == 1 ? qd : qdd);
      }
    }
    out[0] = order == 0 ? sum - r.c : sum;
  }
  /// @copydoc phiq::DistanceSpec::joint_count
  /// A transmission between two bodies is a higher pair: one freedom.
  JointCount joint_count() const { return JointCount::joint(self().dimension == 3 ? 3 : 2, 1); }

 private:
  const Derived& self() const { return static_cast<const Derived&>(*this); }
};

/// Gear pair: the angles θ1, θ2 of two gears of pitch radii r1, r2 (or tooth counts z1, z2: the ratio is the same),
/// both measured relative to the carrier's angle θc (0, the ground, without a carrier):
///   external:  r1 (θ1 − θc) + r2 (θ2 − θc) = r1 φ      (they turn opposite ways)
///   internal:  r1 (θ1 − θc) − r2 (θ2 − θc) = r1 φ      (gear 2 is the ring, r2 > r1: the same way)
///   Φ = (θ1 − θc) ± (r2/r1) (θ2 − θc) − φ,   Φt = 0,   γ = 0      (1 row, an angle of gear 1)
/// φ (the phase, default 0) is gear 1's angle when both angles read 0. With a moving carrier (the arm of an
/// epicyclic train) the relative rotations obey the ratio: a sun s and a ring r meshing with planets of one arm c
/// give Willis' formula (θs − θc)/(θr − θc) = −r_r/r_s. A gear, the ring or the carrier may be fixed (a constant).
///
/// Scene type `gear` (any dimension): `between: [G1, G2]` (each a body — its ψ, dimension 2 — or an angle
/// coordinate), `radii: [r1, r2]` or `teeth: [z1, z2]`, `mesh: external | internal` (external), `carrier: C` (a
/// body or an angle coordinate; none), `phase: φ` (0), `pressure_angle: α` (rad, 20° = 0.349; for the bearings' loads).
struct GearSpec : LinearTransmission<GearSpec> {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const GearSpec&) const = default;
  static constexpr int kRows = 1;  ///< one row, an angle
  /// @copydoc DistanceSpec::kKind
  static constexpr const char* kKind = "gear";
  Slot first;                          ///< θ1, gear 1's angle (rad): the row takes its unit
  Slot second;                         ///< θ2, gear 2's angle (rad)
  Slot carrier = Slot::constant(0.0);  ///< θc, the carrier's angle (rad); a constant 0 without a carrier
  double r1 = 1.0;                     ///< gear 1's pitch radius (or tooth count), > 0
  double r2 = 1.0;                     ///< gear 2's pitch radius (or tooth count), > 0; > r1 for an internal pair
  bool internal = false;               ///< internal mesh: gear 2 is a ring gear and both turn the same way
  double phase = 0.0;                  ///< φ (rad)
  int dimension = 2;                   ///< the scene's dimension (for the Grübler count)
  double pressure_angle = detail::kPressureAngle;  ///< α (rad): its bearings' loads only (GearMesh)

  /// @copydoc DistanceSpec::row_unit
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kAngle; }
  /// @copydoc DistanceSpec::characteristic_length
  /// A gear pair's radii are a ratio here, not a link length: 0.
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  template <class F>
  void for_each_slot(F&& f) const {
    f(first, Unit::kAngle), f(second, Unit::kAngle), f(carrier, Unit::kAngle);
  }
  /// @copydoc DistanceSpec::prepare
  void prepare(const double* /*q0*/) const {
    detail::require_positive_pair(r1, r2, "gear: the radii (or tooth counts) must be positive");
    detail::require(std::isfinite(phase), "gear: phase is not finite");
    detail::require(detail::is_pressure_angle(pressure_angle), "gear: pressure_angle must be in [0, pi/2) rad");
    detail::require(!internal || r2 > r1,
                    "gear: an internal pair's second gear is the ring: its radius must exceed the first's");
    detail::require(!(first.is_coordinate() && second.is_coordinate() && first.coord() == second.coord()),
                    "gear: the two gears must be different angles");
    detail::require(!(carrier.is_coordinate() && ((first.is_coordinate() && first.coord() == carrier.coord()) ||
                                                  (second.is_coordinate() && second.coord() == carrier.coord()))),
                    "gear: the carrier must not be one of the gears");
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {
      {"constraints", "gear", 0, "- {name: mesh, type: gear, between: [pinion, wheel], teeth: [12, 36]}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static GearSpec read(const Fields& f) {
    f.expect({"type", "name", "between", "radii", "teeth", "mesh", "carrier", "phase", "pressure_angle"});
    GearSpec g;
    std::tie(g.first, g.second) = f.angle_pair("between");
    std::tie(g.r1, g.r2) = f.radii_or_teeth();
    if (f.present("mesh")) g.internal = f.choice("mesh", {"external", "internal"}) == 1;
    if (f.present("carrier")) g.carrier = f.angle("carrier");
    if (f.present("phase")) g.phase = f.number("phase");
    if (f.present("pressure_angle")) g.pressure_angle = f.number("pressure_angle");
    g.dimension = f.dimension();
    return g;
  }

  /// @copydoc DistanceSpec::sketch
  /// A gear pair draws the pitch circles of the gears on their bodies (a ring for an internal gear).
  template <class Sketch>
  void sketch(Sketch& sk) const {
    sk.gear_pair(first, second, r1, r2, internal);
  }
  /// The row as a linear form (LinearTransmission evaluates it).
  detail::LinearRow row() const {
    const double k = ratio();
    return detail::LinearRow{{first, second, carrier}, {1.0, k, -(1.0 + k)}, phase};
  }
  /// The mesh as a force on the gears' bearings (kinds/reaction_site.hpp): the angles and the row's ratio.
  GearMesh gear_mesh() const {
    GearMesh m{first, second, carrier, ratio()};
    m.pressure_angle = pressure_angle;
    return m;
  }
  /// k of the row: r2/r1 external, −r2/r1 internal.
  double ratio() const { return (internal ? -r2 : r2) / r1; }
  /// The data a parameter may move (DistanceSpec::data_members()): fixed angles, the radii and the phase.
  static constexpr auto data_members() {
    return std::tuple{&GearSpec::first, &GearSpec::second, &GearSpec::carrier,
                      &GearSpec::r1,    &GearSpec::r2,     &GearSpec::phase};
  }
  /// The rates of row()'s coefficients along the data's `rate`: k̂ = ±(r̂2 r1 − r2 r̂1)/r1², the fixed angles', φ̂.
  detail::LinearRow row_rate(const GearSpec& rate) const {
    const double kd = (internal ? -1.0 : 1.0) * (rate.r2 * r1 - r2 * rate.r1) / (r1 * r1);
    return detail::LinearRow{{rate.first, rate.second, rate.carrier}, {0.0, kd, -kd}, rate.phase};
  }
};

/// Rack and pinion: the rack's travel x equals the pinion's pitch radius times its rotation θ (a rack along +x
/// below a pinion turning counter-clockwise; `reversed` for a rack above it, or one whose travel runs the other way):
///   Φ = x ∓ r θ − c,   Φt = 0,   γ = 0      (1 row, a length)
/// c (the offset, default 0) is the travel at θ = 0.
///
/// Scene type `rack_pinion` (any dimension): `rack: x` (a travel coordinate), `pinion: P` (a body — its ψ,
/// dimension 2 — or an angle coordinate), `radius: r` (> 0), `offset: c` (0), `reversed: true | false` (false),
/// `pressure_angle: α` (rad, 20° = 0.349; for the bearings' loads).
struct RackPinionSpec : LinearTransmission<RackPinionSpec> {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const RackPinionSpec&) const = default;
  static constexpr int kRows = 1;  ///< one row, a length
  /// @copydoc DistanceSpec::kKind
  static constexpr const char* kKind = "rack_pinion";
  Slot rack;                                       ///< x, the rack's travel (m)
  Slot pinion;                                     ///< θ, the pinion's angle (rad)
  double radius = 1.0;                             ///< r, the pinion's pitch radius (m), > 0
  double offset = 0.0;                             ///< c, the travel at θ = 0 (m)
  bool reversed = false;                           ///< x = −r θ + c
  int dimension = 2;                               ///< the scene's dimension (for the Grübler count)
  double pressure_angle = detail::kPressureAngle;  ///< α (rad): its bearings' loads only (GearMesh)

  /// @copydoc DistanceSpec::row_unit
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  /// For a rack and pinion: the pinion's radius.
  double characteristic_length() const { return radius; }
  /// @copydoc DistanceSpec::for_each_slot
  template <class F>
  void for_each_slot(F&& f) const {
    f(rack, Unit::kLength), f(pinion, Unit::kAngle);
  }
  /// @copydoc DistanceSpec::prepare
  void prepare(const double* /*q0*/) const {
    detail::require(std::isfinite(radius) && radius > 0.0, "rack_pinion: the radius must be positive");
    detail::require(std::isfinite(offset), "rack_pinion: offset is not finite");
    detail::require(detail::is_pressure_angle(pressure_angle), "rack_pinion: pressure_angle must be in [0, pi/2) rad");
    detail::require(!(rack.is_coordinate() && pinion.is_coordinate() && rack.coord() == pinion.coord()),
                    "rack_pinion: the rack's travel and the pinion's angle must be different coordinates");
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {{"constraints", "rack_pinion", 0,
                                          "- {name: steering, type: rack_pinion, rack: x_rack, pinion: pinion, "
                                          "radius: 0.05}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static RackPinionSpec read(const Fields& f) {
    f.expect({"type", "name", "rack", "pinion", "radius", "offset", "reversed", "pressure_angle"});
    RackPinionSpec s;
    s.rack = Slot::coordinate(f.coordinate("rack"));
    s.pinion = f.angle("pinion");
    s.radius = f.number("radius");
    if (f.present("offset")) s.offset = f.number("offset");
    if (f.present("reversed")) s.reversed = f.boolean("reversed");
    if (f.present("pressure_angle")) s.pressure_angle = f.number("pressure_angle");
    s.dimension = f.dimension();
    return s;
  }

  /// @copydoc DistanceSpec::sketch
  /// A rack and pinion draws the pinion's pitch circle on its body and the rack on the body whose coordinate is the
  /// travel.
  template <class Sketch>
  void sketch(Sketch& sk) const {
    sk.rack(rack, pinion, radius, reversed);
  }
  /// The row as a linear form (LinearTransmission evaluates it).
  detail::LinearRow row() const {
    return detail::LinearRow{{rack, pinion, Slot::constant(0)}, {1.0, reversed ? radius : -radius, 0.0}, offset};
  }
  /// The mesh as a push on the pinion's bearing and the rack's guide (kinds/reaction_site.hpp).
  GearMesh gear_mesh() const {
    GearMesh m{rack, pinion, Slot::constant(0.0), reversed ? radius : -radius, true};
    m.pressure_angle = pressure_angle;
    return m;
  }
  /// The data a parameter may move (DistanceSpec::data_members()): a fixed pinion angle, the radius, the offset.
  static constexpr auto data_members() {
    return std::tuple{&RackPinionSpec::rack, &RackPinionSpec::pinion, &RackPinionSpec::radius, &RackPinionSpec::offset};
  }
  /// The rates of row()'s coefficients along the data's `rate` (GearSpec::row_rate()).
  detail::LinearRow row_rate(const RackPinionSpec& rate) const {
    return detail::LinearRow{
        {rate.rack, rate.pinion, Slot::constant(0)}, {0.0, reversed ? rate.radius : -rate.radius, 0.0}, rate.offset};
  }
};

/// Belt or chain between two pulleys (sprockets) of radii r1, r2 (or tooth counts), without slip: the belt's
/// speed is the same on both, so an open belt turns them the same way and a crossed belt opposite ways:
///   open:     r1 θ1 − r2 θ2 = r1 φ,      crossed:  r1 θ1 + r2 θ2 = r1 φ
///   Φ = θ1 ∓ (r2/r1) θ2 − φ,   Φt = 0,   γ = 0      (1 row, an angle of pulley 1)
///
/// Scene types `belt` and `chain` (any dimension): `between: [P1, P2]` (bodies — ψ, dimension 2 — or angle
/// coordinates), `radii: [r1, r2]` or `teeth: [z1, z2]`, `crossed: true | false` (false), `phase: φ` (0); for the
/// strands' pull on the pulleys' bearings (gear_mesh()): `tension: T0` (N, ≥ 0; a belt's installation tension, a
/// chain's slack strand's, 0 for a chain by default) and, with teeth, `pitch: p` (m, > 0): radii z p / 2π.
struct BeltSpec : LinearTransmission<BeltSpec> {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const BeltSpec&) const = default;
  static constexpr int kRows = 1;  ///< one row, an angle
  /// @copydoc DistanceSpec::kKind
  static constexpr const char* kKind = "belt";
  Slot first;            ///< θ1, pulley 1's angle (rad)
  Slot second;           ///< θ2, pulley 2's angle (rad)
  double r1 = 1.0;       ///< pulley 1's radius (or tooth count), > 0
  double r2 = 1.0;       ///< pulley 2's radius (or tooth count), > 0
  bool crossed = false;  ///< a crossed belt: the pulleys turn opposite ways
  double phase = 0.0;    ///< φ (rad)
  int dimension = 2;     ///< the scene's dimension (for the Grübler count)
  bool chain = false;    ///< written as a `chain`: its slack strand keeps `tension` (0 by default)
  bool teeth = false;    ///< r1 and r2 are tooth counts
  double pitch = 0.0;    ///< a chain's (toothed belt's) pitch (m) with teeth; 0: not stated
  double tension = std::numeric_limits<double>::quiet_NaN();  ///< T0 (N); NaN: not stated

  /// @copydoc DistanceSpec::row_unit
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kAngle; }
  /// @copydoc DistanceSpec::characteristic_length
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  template <class F>
  void for_each_slot(F&& f) const {
    f(first, Unit::kAngle), f(second, Unit::kAngle);
  }
  /// @copydoc DistanceSpec::prepare
  void prepare(const double* /*q0*/) const {
    detail::require_positive_pair(r1, r2, "belt: the radii (or tooth counts) must be positive");
    detail::require(std::isfinite(phase), "belt: phase is not finite");
    detail::require(!(first.is_coordinate() && second.is_coordinate() && first.coord() == second.coord()),
                    "belt: the two pulleys must be different angles");
    detail::require(std::isnan(tension) || (std::isfinite(tension) && tension >= 0.0),
                    "belt: tension must be a force >= 0");
    detail::require(pitch == 0.0 || (std::isfinite(pitch) && pitch > 0.0), "belt: pitch must be positive");
    detail::require(pitch == 0.0 || teeth, "belt: a pitch goes with teeth");
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {
      {"constraints", "belt", 0,
       "- {name: fan_belt, type: belt, between: [crank_pulley, fan_pulley], "
       "radii: [0.08, 0.05]}"},
      {"constraints", "chain", 0, "- {name: drive, type: chain, between: [sprocket1, sprocket2], teeth: [44, 16]}"}};
  /// @copydoc DistanceSpec::read
  template <class Fields>
  static BeltSpec read(const Fields& f) {
    f.expect({"type", "name", "between", "radii", "teeth", "crossed", "phase", "tension", "pitch"});
    BeltSpec b;
    std::tie(b.first, b.second) = f.angle_pair("between");
    std::tie(b.r1, b.r2) = f.radii_or_teeth();
    b.teeth = f.present("teeth");
    if (f.present("crossed")) b.crossed = f.boolean("crossed");
    if (f.present("phase")) b.phase = f.number("phase");
    b.chain = f.type() == "chain";
    if (b.chain) b.tension = 0.0;
    if (f.present("tension")) b.tension = f.number("tension");
    if (f.present("pitch")) b.pitch = f.number("pitch");
    b.dimension = f.dimension();
    return b;
  }

  /// @copydoc DistanceSpec::sketch
  /// A belt or chain draws its pulleys on their bodies and its path (tangents and arcs) around them.
  template <class Sketch>
  void sketch(Sketch& sk) const {
    sk.belt(first, second, r1, r2, crossed);
  }
  /// The row as a linear form (LinearTransmission evaluates it).
  detail::LinearRow row() const {
    return detail::LinearRow{{first, second, Slot::constant(0)}, {1.0, (crossed ? r2 : -r2) / r1, 0.0}, phase};
  }
  /// The strands' pull on the pulleys' bearings (kinds/reaction_site.hpp): the radii in length (unknown for tooth
  /// counts without a pitch) and the tension at rest (unknown for a belt that states none).
  GearMesh gear_mesh() const {
    GearMesh m{first, second, Slot::constant(0.0), row().w[1]};
    m.belt = true, m.chain = chain, m.crossed = crossed, m.tension = tension;
    if (!teeth) m.r1 = r1, m.r2 = r2;
    // a chain's links ride on polygons, between p/(2 tan(π/z)) and p/(2 sin(π/z)) from the centre; it travels z p
    // a turn, as a toothed belt on its pitch circle does: radii z p/2π keep the strands' pull and the row's ratio
    // (z2/z1) one
    if (teeth && pitch > 0.0)
      m.r1 = pitch * r1 / (2.0 * std::numbers::pi), m.r2 = pitch * r2 / (2.0 * std::numbers::pi);
    return m;
  }
  /// The data a parameter may move (DistanceSpec::data_members()): fixed angles, the radii and the phase.
  static constexpr auto data_members() {
    return std::tuple{&BeltSpec::first, &BeltSpec::second, &BeltSpec::r1, &BeltSpec::r2, &BeltSpec::phase};
  }
  /// The rates of row()'s coefficients along the data's `rate` (GearSpec::row_rate()).
  detail::LinearRow row_rate(const BeltSpec& rate) const {
    const double kd = (crossed ? 1.0 : -1.0) * (rate.r2 * r1 - r2 * rate.r1) / (r1 * r1);
    return detail::LinearRow{{rate.first, rate.second, Slot::constant(0)}, {0.0, kd, 0.0}, rate.phase};
  }
};

}  // namespace phiq
