/// @file
/// Parts: the bodies of a mechanism as an engineer sees them, each a named frame that moves with q, the shapes it
/// carries in that frame (phiq/shapes.hpp) and its mass properties. A scene's `parts` section (models/README.md)
/// places them on any coordinate family: a reference-point body (its frame), natural points and vectors (an origin
/// and the directions of its axes), or expressions of the coordinates (relative angles: an origin and an angle).
/// A body with no part of its own gets a derived part where a drawing asks (drawn_parts(), phiq/drawn_parts.hpp):
/// links between the points it carries, shafts along its joints' axes, sized from the model's length scale.
///
/// Nothing here is computed during a sweep: a part's pose is evaluated from q when an output or a drawing asks.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "phiq/expression.hpp"
#include "phiq/shapes.hpp"
#include "phiq/spatial_attachment.hpp"
#include "phiq/types.hpp"

namespace phiq {

/// Where a part's frame comes from.
enum class PartFrameKind {
  kPlanarBody,   ///< a planar reference-point body (or ground): origin (x, y), rotation ψ about z
  kSpatialBody,  ///< a spatial reference-point body (or ground): origin (x, y, z), rotation R(e)
  kPoints,       ///< natural coordinates: origin a point; x along `x_toward`; y in the plane of `y_toward`
  kExpressions,  ///< expressions of q and t: origin `at`; rotation `angle` about the constant unit `axis`
};

/// A part's frame as a function of q (and t, for expressions). Pre-conditions of part_pose(): the slots' and the
/// expressions' coordinates exist in q.
struct PartFrame {
  PartFrameKind kind = PartFrameKind::kPlanarBody;  ///< where the frame comes from
  bool spatial_frame = false;  ///< kPoints: a spatial frame (y from y_toward), else planar (y = z × x)
  Frame2 planar;               ///< kPlanarBody
  Frame3 spatial;              ///< kSpatialBody
  Attachment3 origin;          ///< kPoints: the origin, a natural point
  /// kPoints: what x points along, a point (the direction from the origin to it) or a natural unit vector.
  Attachment3 x_toward;
  /// kPoints, spatial: what y points along (its part perpendicular to x); planar frames have none (y = z × x).
  Attachment3 y_toward;
  bool x_is_point = true;  ///< kPoints: x_toward is a point, else a vector
  bool y_is_point = true;  ///< kPoints: y_toward is a point, else a vector
  /// kExpressions: the origin's components (two or three).
  std::vector<std::shared_ptr<const CompiledExpression>> at;
  std::shared_ptr<const CompiledExpression> angle;  ///< kExpressions: the rotation about `axis` (none: no rotation)
  kin3::V3 axis{0, 0, 1};                           ///< kExpressions: unit length (z in the plane)
};

/// A frame's placement in the world: x_world = at + R x_body (planar frames: z = 0, R a rotation about z).
struct Pose {
  kin3::V3 at;                                         ///< origin (m)
  RotationMatrix rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< axes as columns, row-major
  /// The body point `s` in the world.
  kin3::V3 apply(kin3::V3 s) const {
    const auto& r = rotation;
    return {at.x + r[0] * s.x + r[1] * s.y + r[2] * s.z, at.y + r[3] * s.x + r[4] * s.y + r[5] * s.z,
            at.z + r[6] * s.x + r[7] * s.y + r[8] * s.z};
  }
};

/// The pose of `frame` at (q, t). A kPoints frame whose x direction vanishes (coincident points) or whose y
/// direction is parallel to x gives a NaN pose; Euler parameters are normalised (R(e/|e|)). Thread-safe.
Pose part_pose(const PartFrame& frame, const double* q, double t);

/// Where a part's mass properties came from (`phiq check` says so).
enum class MassSource {
  kNone,     ///< no mass given (a part that only draws)
  kStated,   ///< `mass`, `center_of_mass`, `inertia` in the scene
  kDensity,  ///< `density` times its shapes' volumes
};

/// A part: a named frame, its shapes, its mass.
struct Part {
  std::string name;                             ///< the part's name (the body's, for a body's part)
  std::string body;                             ///< the body it is (or the frame's description for points/expressions)
  PartFrame frame;                              ///< how its frame follows q
  std::vector<Shape> shapes;                    ///< in its frame
  std::optional<std::array<double, 4>> colour;  ///< RGBA for shapes with none of their own
  MassProperties mass;                          ///< in its frame; zero unless mass_source says otherwise
  MassSource mass_source = MassSource::kNone;   ///< where `mass` came from
  double density = 0.0;                         ///< kDensity: kg/m³
  bool derived = false;                         ///< made by phiq from the constraints (no shape in the scene)
  bool fixed = false;                           ///< its frame reads no coordinate and no time (ground)
};

/// `p` without its shapes: what its dynamics read (a mesh's triangles are not), copied without copying them.
inline Part without_shapes(const Part& p) {
  Part out;
  out.name = p.name, out.body = p.body, out.frame = p.frame, out.colour = p.colour, out.mass = p.mass;
  out.mass_source = p.mass_source, out.density = p.density, out.derived = p.derived, out.fixed = p.fixed;
  return out;
}

struct AppliedLoads;  // phiq/applied_loads.hpp

/// The loads on a mechanism's parts (the scene's `loads`): a uniform gravity acting at each part's centre of mass,
/// and the applied forces, torques and springs (phiq/applied_loads.hpp), shared: a copy costs a pointer's.
struct Loads {
  kin3::V3 gravity;                             ///< m/s², world axes, e.g. (0, −9.81, 0) in the plane
  std::shared_ptr<const AppliedLoads> applied;  ///< forces, torques, springs; null: none
};

/// The coordinates `frame` reads (its slots', its expressions'), increasing, each once.
std::vector<Index> frame_coordinates(const PartFrame& frame);
/// The same into `out` (its capacity reused: no allocation once it has held them).
void frame_coordinates(const PartFrame& frame, std::vector<Index>& out);

/// The largest coordinate index `frame` reads, −1 if none.
Index max_coordinate(const PartFrame& frame);

}  // namespace phiq
