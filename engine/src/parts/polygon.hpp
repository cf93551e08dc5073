// A kPolygon shape's outline: checked simple, turned counter-clockwise, its area moments, and its triangles (the
// caps of its extrusion).
#pragma once

#include <array>
#include <vector>

#include "phiq/shapes.hpp"

namespace phiq::detail::parts {

/// A polygon's vertices in x, y.
using Outline = std::vector<std::array<double, 2>>;

/// The outline of `shape` counter-clockwise (reversed when it is given clockwise). Throws phiq::Error, naming the
/// shape, for fewer than three vertices, a non-finite one, two consecutive equal ones, an outline that crosses or
/// touches itself (not a simple polygon), or a zero area.
Outline counter_clockwise_outline(const Shape& shape);

/// The area moments of a simple polygon about the origin of its coordinates: ∫1, ∫x, ∫y, ∫x², ∫y², ∫xy dA (signed:
/// positive for a counter-clockwise outline). Exact, from Green's theorem edge by edge.
struct AreaMoments {
  double area = 0.0;                    ///< ∫ dA
  double x = 0.0, y = 0.0;              ///< ∫ x dA, ∫ y dA
  double xx = 0.0, yy = 0.0, xy = 0.0;  ///< ∫ x² dA, ∫ y² dA, ∫ x y dA
};
AreaMoments area_moments(const Outline& outline);

/// Triangles covering a simple counter-clockwise polygon, counter-clockwise, by ear clipping: indices into
/// `outline`, every outline edge an edge of exactly one triangle (a vertex on a straight run between its neighbours
/// is clipped as a triangle of zero area, so that the caps of an extrusion meet its sides edge for edge).
std::vector<std::array<int, 3>> polygon_triangles(const Outline& ccw, const Shape& shape);

}  // namespace phiq::detail::parts
