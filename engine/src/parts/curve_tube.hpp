// A kCurve shape drawn as a tube (shape_triangles' part for curves).
#pragma once

#include "phiq/shapes.hpp"

namespace phiq::detail::parts {

/// A closed tube of diameter `radius` (the curve's drawn width) along the polyline `points`, in the shape's frame:
/// a ring of n vertices at each point, in the plane halfway between its two segments, its frame carried along the
/// curve without twist (double reflection; Wang, Jüttler, Zheng and Liu 2008), a closed curve's remaining twist
/// spread evenly over its rings; an open curve's ends capped. Counter-clockwise seen from outside. Throws
/// phiq::Error, naming the shape, for a non-finite point or too few distinct ones (two; three when closed).
TriangleMesh curve_tube(const Shape& shape, int n);

}  // namespace phiq::detail::parts
