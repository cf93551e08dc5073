/// @file
/// The geometry of a part: shapes in a body's frame (primitives, extruded polygons, meshes read from STL and OBJ
/// files, and curves), their triangle meshes for drawing and distance queries, and their mass properties. Plain data
/// and free functions; a Part (phiq/parts.hpp) places them on a body.
///
/// Conventions: every shape has its own placement in the body's frame (`at`, `rotation`); in the shape's own frame
/// a box is centred on the origin with edges along the axes, a cylinder and a capsule have their axis along z and
/// their centre at the origin, a cone its base circle in z = 0 and its apex at z = height, a plane is z = 0 with its
/// normal +z, a polygon lies in z ∈ [−thickness/2, thickness/2], a mesh is in the file's units times `scale`.
/// Inertia tensors are about the centre of mass, in the body's axes, row-major (I[3 i + j]).
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "phiq/orientation.hpp"
#include "phiq/spatial_attachment.hpp"

namespace phiq {

/// A triangle mesh: vertices and their indices, three per triangle, counter-clockwise seen from outside (the normal
/// (b − a) × (c − a) points out of a closed mesh).
struct TriangleMesh {
  std::vector<kin3::V3> vertices;             ///< positions (m)
  std::vector<std::array<int, 3>> triangles;  ///< vertex indices
};

/// What a shape is.
enum class ShapeKind {
  kBox,       ///< `size` = edge lengths along x, y, z
  kCylinder,  ///< `radius`, `length` along z
  kSphere,    ///< `radius`
  kCapsule,   ///< a cylinder of `radius` and `length` (between the hemispheres' centres) with hemispherical ends
  kCone,      ///< `radius` of the base (in z = 0), `length` = height to the apex on +z
  kPlane,     ///< z = 0, normal +z; `size` x, y the drawn extent (a ground plane; no mass)
  kPolygon,   ///< `outline` in x, y (a simple polygon, either orientation), extruded over `length` along z (centred)
  kMesh,      ///< `mesh`, read from `file` (STL ASCII or binary, OBJ), scaled by `scale`
  kCurve,  ///< a polyline `points` (closed or not) drawn as a tube of `radius`, half its width (no mass): slots, belts,
           ///< threads
};

/// "box", "cylinder", …: the kind's name in scenes and messages.
const char* to_string(ShapeKind kind);

/// A shape in a body's frame. Sizes are in metres and positive; see the file comment for each kind's own frame.
struct Shape {
  ShapeKind kind = ShapeKind::kBox;                    ///< what the shape is, and so which of the fields below it reads
  std::string name;                                    ///< optional, for messages and the viewer
  std::optional<std::array<double, 4>> colour;         ///< RGBA in [0, 1]; none: the part's (or the viewer's default)
  kin3::V3 at;                                         ///< the shape frame's origin in the body frame (m)
  RotationMatrix rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< the shape frame's axes in the body frame (columns)
  kin3::V3 size;                                       ///< kBox: edge lengths; kPlane: drawn extent in x, y
  double radius = 0.0;                         ///< kCylinder, kSphere, kCapsule, kCone; kCurve: half the drawn width
  double length = 0.0;                         ///< kCylinder, kCapsule, kCone (height), kPolygon (thickness)
  std::vector<std::array<double, 2>> outline;  ///< kPolygon: vertices in x, y
  std::vector<kin3::V3> points;                ///< kCurve: the polyline in the shape frame
  bool closed = false;                         ///< kCurve: the last point joins the first
  std::string file;                            ///< kMesh: the file it was read from (as the scene names it)
  double scale = 1.0;                          ///< kMesh: file units to metres
  std::shared_ptr<const TriangleMesh> mesh;    ///< kMesh: the triangles in the shape frame, already scaled
};

/// Mass, centre of mass and inertia about the centre of mass, in the body's axes.
struct MassProperties {
  double mass = 0.0;                ///< kg
  kin3::V3 center;                  ///< centre of mass in the body frame (m)
  std::array<double, 9> inertia{};  ///< kg·m², about the centre of mass, body axes, row-major, symmetric
};

/// The mass properties of `shape` filled with `density` (kg/m³), in the body frame (its placement applied). Exact
/// for the primitives and the extruded polygon; for a mesh by the divergence theorem over its triangles (exact for
/// the polyhedron). Throws phiq::Error for a shape with no volume (kPlane, kCurve) and for an open mesh (see
/// mesh_is_closed()), naming the shape; so too for a density or a size that is not a positive number, a `rotation`
/// that is not a rotation, an outline that is not a simple polygon, and a mesh whose triangles face inwards.
MassProperties shape_mass_properties(const Shape& shape, double density);

/// The sum of several bodies' mass properties (parallel-axis theorem); all in one frame. Empty: zero mass.
MassProperties combine_mass_properties(const std::vector<MassProperties>& parts);

/// The inertia tensor of `m` about the point `point` (parallel-axis theorem: I_c + m (|d|² 1 − d dᵀ), d = c − point).
std::array<double, 9> inertia_about(const MassProperties& m, kin3::V3 point);

/// Volume, centroid and second moments of a closed triangle mesh by the divergence theorem (unit density). Signed:
/// a mesh whose triangles face inwards gives a negative volume and inertia; one of no volume, zero mass and its
/// vertices' mean as centre. Throws phiq::Error for a vertex index out of range.
MassProperties mesh_mass_properties(const TriangleMesh& mesh);

/// True when every edge of `mesh` is shared by exactly two triangles that traverse it in opposite directions (a
/// closed, consistently oriented surface), after merging vertices that coincide exactly.
bool mesh_is_closed(const TriangleMesh& mesh);

/// Reads a triangle mesh from an STL (ASCII or binary) or OBJ file with Assimp, joining identical vertices and
/// triangulating polygons, and multiplies it by `scale`. Throws phiq::Error, one line naming the file, for a file
/// that is missing, unreadable, of another format, or holds no triangles.
TriangleMesh load_mesh_file(const std::string& path, double scale = 1.0);

/// The triangles that draw `shape` in the body frame (its placement applied): primitives tessellated with
/// `segments` around each circle (at least 8), a polygon's outline and caps, a mesh as read; a curve as a tube of
/// its width; a plane as two triangles of its extent. Fewer than 8 segments are taken as 8. Throws phiq::Error,
/// naming the shape, for the shapes shape_mass_properties() refuses for their sizes, placement or outline.
TriangleMesh shape_triangles(const Shape& shape, int segments = 32);

}  // namespace phiq
