/// @file
/// Where a joint's reaction acts (phiq/joint_reactions.hpp): a kind that joins two bodies states it with a member
/// `ReactionSite reaction_site(const double* q) const` and the number of values its reaction has,
/// `static constexpr int kReactionWidth` (3 in the plane, 6 in space: ConstraintBlock::reaction_width()), and its
/// reaction (the force and moment its multipliers exert) can then be written (`output.reactions`, models/README.md).
/// Kinds without them have none.
#pragma once

#include <cmath>
#include <limits>
#include <numbers>

#include "phiq/spatial_attachment.hpp"
#include "phiq/types.hpp"

namespace phiq {

/// The body a joint's reaction is reported on and the point its moment is taken about.
struct ReactionSite {
  kin3::V3 point;        ///< the joint's point in world axes (m): the moment is about it
  bool spatial = false;  ///< the body is `frame3` (a spatial body), else `frame2` (a planar one)
  Frame2 frame2;         ///< the planar body (x, y, ψ; a natural point: ψ constant)
  Frame3 frame3;         ///< the spatial body (x, y, z, e0…e3; a natural point: e constant)
  /// The joint's own axes x, y, z as unit vectors in world axes, in which a reaction may be written instead
  /// (OutputEfforts::reactions_in_joint_axes): the reported body's axes at a planar pin, x along the slide and y
  /// across it at a planar prismatic pair, the reported side's joint frame at a spatial joint (z its axis, x its
  /// reference direction). (A natural point's are its part's frame's: natural_reaction_site().)
  kin3::V3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
};

/// A gear pair, a rack and pinion, or a belt, as its teeth (strands) push its members (GearSpec::gear_mesh(),
/// RackPinionSpec::gear_mesh(), OutputEfforts::meshes, add_gear_mesh_forces()): its row relates coordinates
/// alone, (θ1 − θc) + k (θ2 − θc) − φ or x + k θ − c, so its multiplier λ turns the members by torques (and pushes
/// a rack along its travel); the teeth push at the pitch point, which loads the members' bearings as well.
struct GearMesh {
  Slot first;                          ///< θ1, gear 1's angle; a rack's travel x
  Slot second;                         ///< θ2, gear 2's angle; the pinion's angle θ
  Slot carrier = Slot::constant(0.0);  ///< θc, the carrier's angle (a constant 0 without one, or for a rack)
  double k = 1.0;     ///< the row's ratio: r2/r1 external, −r2/r1 internal; a rack's −r (r when reversed)
  bool rack = false;  ///< a rack and pinion
  /// The teeth's pressure angle α (rad): their push has, besides the force along the pitch line that turns the
  /// gears, tan α of it across, which parts them (not a belt's)
  double pressure_angle = 0.0;
  /// A belt or chain (BeltSpec::gear_mesh()): its two strands pull its pulleys' centres toward each other, with
  /// tensions T0 ∓ ΔT/2 (a belt's, T0 its installation tension) or T0 and T0 + |ΔT| (a chain's, T0 its slack
  /// strand's), where ΔT = τ1/r1 is what the row's torque on pulley 1 takes.
  bool belt = false;
  bool chain = false;    ///< a chain: its slack strand keeps `tension`
  bool crossed = false;  ///< the strands cross between the pulleys
  double r1 = 0.0;       ///< pulley 1's radius (m); 0: not known (tooth counts without a pitch)
  double r2 = 0.0;       ///< pulley 2's radius (m)
  double tension = std::numeric_limits<double>::quiet_NaN();  ///< T0 (N); NaN: a belt that states none
  /// Whether a belt's or chain's strands can be drawn and their tension told: its radii in length and T0 known.
  bool strands_known() const { return r1 > 0.0 && r2 > 0.0 && std::isfinite(tension); }
};

/// @cond internal
namespace detail {
/// The teeth's pressure angle α (rad) of a gear or rack: 20°, ISO 53's, unless the scene says (0 for friction wheels).
constexpr double kPressureAngle = 20.0 * std::numbers::pi / 180.0;
/// Whether α is one: finite, in [0, π/2).
constexpr bool is_pressure_angle(double alpha) {
  return alpha >= 0.0 && alpha < std::numbers::pi / 2;  // (false for NaN)
}
/// Whether a planar frame moves (reads a coordinate): a joint reports on its first side that does.
inline bool frame_moves(const Frame2& f) { return f.x.is_coordinate() || f.y.is_coordinate() || f.psi.is_coordinate(); }
/// The same for a spatial frame.
inline bool frame_moves(const Frame3& f) {
  for (const Slot* s : {&f.x, &f.y, &f.z, &f.e0, &f.e1, &f.e2, &f.e3})
    if (s->is_coordinate()) return true;
  return false;
}
}  // namespace detail
/// @endcond

}  // namespace phiq
