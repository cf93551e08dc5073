/// @file
/// Joints of natural coordinates: a named natural point shared by two bodies, or held by ground in a component (a
/// fixed point, a slider's point on a constant line), has no constraint row of its own, so its reaction comes from
/// splitting the equations at the point among the bodies (phiq/joint_reactions.hpp writes it).
///
/// A body is a part whose frame is of natural points (`frame: {origin: P, x: Q}`, phiq/parts.hpp) and reads a
/// coordinate. Each constraint whose natural-point coordinates all belong to some body's frame is that body's (the
/// one with the fewest such coordinates: a crank's bar [O, A] and its segment angle, not the coupler [A, B] that
/// also holds A); the others (none, or several bodies' points) act at the joints. Cut at a joint point P into a
/// copy per body, body b's copy balances
///
///     R_b + Q_b(P) − Σ_{c of b} (Φq,cᵀ λ_c)(P) = 0,
///
/// Q_b the generalized forces of b's parts and of the loads on b alone, so R_b, the force the rest of the mechanism
/// exerts on b at P, is read off the row's multipliers. A component of P that is constant has no row: its copy's
/// equation needs ∂Φ_c/∂P there, which b's constraints give by their invariance under translations of all their
/// points (true of distances, dot products, segment angles; a coordinate's equation `xA − a cos θ` is read as
/// written relative to the fixed point), and Q_b there by differentiating b's parts and loads with that component
/// made a coordinate. A body with two points constant along one axis shares that component's load between them in a
/// way the points do not determine: NaN. The moment at a point joint is zero (points carry forces only); shared
/// unit vectors (a spatial revolute in natural coordinates) are not split. A spring from b to another moving body
/// is b's load at its own end, the far end read at its place from slots of its own (NaturalJoints::mirrors, or
/// far_points on a frame of expressions), so that its pull along the far body's points reaches no body's balance. A
/// torsional spring on a coordinate of its own (a segment_angle's) acts through that constraint's multiplier, its
/// body's; one whose angle reads the points does not say which bodies it turns, and a part on a frame of expressions
/// that reads the points moves with them as none of their bodies: the scene's reader refuses both with natural
/// reactions (their loads, or its mass, would sit in the joints' reactions).
#pragma once

#include <string>
#include <vector>

#include "phiq/applied_loads.hpp"
#include "phiq/kinds/reaction_site.hpp"
#include "phiq/parts.hpp"

namespace phiq {

/// A body of natural coordinates (file comment): its frame, and what acts on it alone.
struct NaturalBody {
  std::string name;  ///< the part's
  /// Its index among the parts find_natural_joints() was given (unknown: the largest size_t), where a sweep's Q has
  /// already computed its part's weight and inertia.
  std::size_t part = static_cast<std::size_t>(-1);
  PartFrame frame;  ///< its frame (PartFrameKind::kPoints), as the model reads it
  /// Its part's mass properties when it has mass, else zero and kNone. Its part as its own Q takes it is
  /// natural_body_parts(): not kept here (a copy of each part, ~700 bytes, 14 MB at 2·10⁴ bodies, that a sweep
  /// whose joints read the whole model's Q never reads).
  MassProperties mass;
  MassSource mass_source = MassSource::kNone;  ///< see mass
  Loads loads;  ///< gravity and the applied loads on this part alone (their frames promoted likewise)
  /// The frame's points (origin, and x, y toward when they are points), each component's slot with the constants
  /// promoted: coordinate n + k for NaturalJoints::promoted[k], so that Q differentiates along them.
  std::vector<Attachment3> points;
  /// The slots its loads read beyond its frame (n + k: a spring's far end, NaturalJoints::mirrors or far_points).
  std::vector<Index> load_slots;
};

/// Whether body `b`'s part has mass (its own Q counts it).
inline bool natural_body_has_mass(const NaturalBody& b) {
  return b.mass_source != MassSource::kNone && b.mass.mass > 0.0;
}

/// Body `b`'s part as its own Q takes it, into `out` (its storage reused): none when it has no mass, else one
/// part named as the body, with its mass properties, on its frame with its points promoted (NaturalBody::points).
void natural_body_parts(const NaturalBody& b, std::vector<Part>& out);

/// A joint at a named natural point (file comment).
struct NaturalJoint {
  std::string name;                 ///< the point's
  Attachment3 point;                ///< its slots (r[0], r[1] and, in space, r[2])
  std::vector<std::size_t> bodies;  ///< the bodies whose frames hold it, in part order: its reaction is on the first
};

/// The bodies and joints of a model's natural coordinates, and the promoted coordinates' values.
struct NaturalJoints {
  std::vector<NaturalBody> bodies;   ///< the moving parts with frames of points
  std::vector<NaturalJoint> joints;  ///< the named points two bodies share or ground holds in a component
  /// The constants made coordinates n + k (k in order): their values, appended to q where the bodies' Q is taken.
  std::vector<double> promoted;
  /// Promoted coordinates that copy a model coordinate at every row (a spring's far end on another body), not a
  /// constant: promoted[slot] is then unused, q, q̇ and q̈ are the coordinate's.
  struct Mirror {
    std::size_t slot = 0;  ///< k, the promoted coordinate n + k
    Index coordinate = 0;  ///< the model coordinate it copies
  };
  std::vector<Mirror> mirrors;  ///< see Mirror
  /// A spring's far end on a frame of expressions, which reads q through expressions of its own: its world point at
  /// the promoted coordinates n + slot, n + slot + 1 (and + 2 in space), their q, q̇ and q̈ the point's motion at
  /// every row (promoted[] there unused), and the spring's end moved to them.
  struct FarPoint {
    std::size_t slot = 0;  ///< the first promoted coordinate
    PartFrame frame;       ///< the far part's frame (PartFrameKind::kExpressions)
    kin3::V3 at;           ///< the end, in that frame
  };
  std::vector<FarPoint> far_points;  ///< see FarPoint
  bool spatial = false;              ///< dimension 3: six values per joint, else three
};

/// The natural joints of `parts` (the scene's, in order) under `loads`, among `points` (the scene's named natural
/// points, planar ones with z constant 0), for a model of `coordinates` coordinates. A point is a joint when two
/// moving kPoints parts' frames hold it, or one does and a component of it is constant.
NaturalJoints find_natural_joints(const std::vector<Part>& parts, const Loads& loads,
                                  const std::vector<std::pair<std::string, Attachment3>>& points, Index coordinates,
                                  bool spatial);

/// Per coordinate of a model of `coordinates`, whether a body of `joints` holds it in a point: a torsional spring whose
/// angle reads one pushes the points without saying which of their bodies it turns, which a point's reaction cannot
/// hold (the file comment).
std::vector<char> point_coordinates(const NaturalJoints& joints, Index coordinates);

/// Where natural joint `j`'s reaction acts, and the axes it is written along where they are asked for
/// (OutputEfforts::reactions_in_joint_axes): the joint's point, and the axes of the frame of the body it is reported
/// on (its first; x toward the frame's x point: along a bar and across it). Only `point` and `axes` are set.
/// Pre-condition: j < joints.joints.size(); q the model's coordinates.
ReactionSite natural_reaction_site(const NaturalJoints& joints, std::size_t j, const double* q, double t);

}  // namespace phiq
