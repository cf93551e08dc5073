// What every drawing of a scene's parts shares (phiq/drawn_parts.hpp: the .glb, the HTML viewer, the SVG): the
// slots a part's frame reads, a shape's triangles ready to light, its colour, a rotation as a quaternion, and the
// part's reach from its origin (for the drawings' extent).
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

// The largest distance from the part's origin to a vertex of its shapes (0 without shapes).
double part_reach(const Part& part);

}  // namespace phiq::tools
