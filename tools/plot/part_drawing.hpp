// What every drawing of a scene's parts shares (phiq/drawn_parts.hpp: the .glb, the HTML viewer, the SVG): the
// slots a part's frame reads, a shape's triangles ready to light, its colour, a rotation as a quaternion, and the
// part's box in its own frame (for the drawings' extent).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "phiq/parts.hpp"
#include "phiq/types.hpp"

namespace phiq::tools {

// Segments of every circle in the drawings' triangles (shape_triangles()).
constexpr int kPartSegments = 32;

// The slots the frames of `parts` read: bodies' frames, natural points and vectors, expressions' coordinates.
std::vector<Slot> part_reads(const std::vector<Part>& parts);

// A shape's triangles (in its part's frame) with a normal at each vertex: a vertex is split where faces meet at more
// than 40° (a box's 8 corners are 24 vertices, a cylinder of n segments 4 n + 2), so that curved surfaces shade
// smoothly and edges stay sharp; the triangles are shape_triangles()'s, in their order.
struct LitMesh {
  std::vector<float> pos, nrm;     // x, y, z per vertex
  std::vector<std::uint32_t> idx;  // three per triangle, counter-clockwise from outside
};
LitMesh lit_mesh(const TriangleMesh& mesh);

// RGBA of `shape`: its own colour, else its part's, else a steel blue (derived parts: a light grey).
std::array<double, 4> shape_colour(const Part& part, const Shape& shape);
// "#rrggbb" of a colour (alpha left out).
std::string hex_colour(const std::array<double, 4>& rgba);

// The unit quaternion (x, y, z, w), w ≥ 0, of a rotation matrix (Shepperd's method: the largest of the four
// candidates, accurate to rounding for every rotation).
std::array<double, 4> quaternion(const RotationMatrix& r);

// What bounds the part's shapes in its own frame: the least and greatest x, y, z of their vertices, and the largest
// distance of one from the origin (all 0 without shapes).
struct PartBox {
  kin3::V3 lo, hi;
  double reach = 0.0;
};
PartBox part_box(const Part& part);

// Two points (least, greatest x, y, z) bounding the part at `pose`, appended to `out`: per axis the tighter of its
// box's posed corners (a link turned to any angle: not a circle of its length about its origin) and its origin ±
// its reach (a disc turned 45°: not its box's diagonal).
void posed_bounds(const PartBox& box, const Pose& pose, std::vector<std::array<double, 3>>& out);

}  // namespace phiq::tools
