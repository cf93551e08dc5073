// The parts a drawing shows (phiq/drawn_parts.hpp) in `phiq plot`'s mechanism panel, at one row: in the plane each
// shape a filled outline seen along z (a box a rectangle, a cylinder or sphere a circle, a polygon its outline, a
// mesh its convex hull, a curve a polyline of its width); in space the shapes' triangles in the isometric view,
// facing ones only, far first (painter's order), shaded by a light from above.
#pragma once

#include <Eigen/Core>

#include <array>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "part_drawing.hpp"
#include "phiq/parts.hpp"

namespace phiq::tools {

// A world point to the panel's pixels.
using ScreenOf = std::function<std::pair<double, double>(const std::array<double, 3>&)>;

// The SVG of `parts` at (q, t): a group of class `parts` holding, in the plane, a path of class `part` per shape
// (`data-part`, `data-shape`), in space a path per facing triangle (`data-part`); `opacity` for the rows before the
// last; `pixels_per_metre` sizes a curve's width.
std::string parts_svg(const std::vector<Part>& parts, const Eigen::VectorXd& q, double t, bool spatial,
                      const ScreenOf& screen, double pixels_per_metre, double opacity);

// A shape seen along z, in its part's frame (x, y): a polygon's outline, a curve's points, else the convex hull of
// its triangles (a box a rectangle, a cylinder along z a circle of kPartSegments points).
std::vector<std::array<double, 2>> shape_outline(const Shape& shape);

// Points that bound the parts at (q, t): each part's posed_bounds().
std::vector<std::array<double, 3>> parts_extent(const std::vector<Part>& parts, const std::vector<PartBox>& boxes,
                                                const Eigen::VectorXd& q, double t);

}  // namespace phiq::tools
