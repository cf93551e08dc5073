// What every function of shapes.hpp checks and applies first: a shape's name in messages, its sizes and placement
// validated, and the placement that takes a point of the shape's frame to the body's.
#pragma once

#include <string>

#include "phiq/shapes.hpp"

namespace phiq::detail::parts {

/// The shape as a message names it: "box 'lid'", "mesh 'hull' (hull.stl)", or the kind alone when it has no name.
std::string shape_label(const Shape& shape);

/// Throws phiq::Error, one line naming the shape, when a size its kind reads is not positive and finite, its
/// placement is not finite or `rotation` not a rotation (orthonormal to 1e-9, determinant +1), a mesh has no
/// triangles, a curve fewer than two points. The polygon's outline is checked where it is read (polygon.hpp).
void check_shape(const Shape& shape);

/// The point `local` of the shape's frame in the body's frame: at + R local.
inline kin3::V3 place_point(const Shape& shape, kin3::V3 local) {
  const RotationMatrix& r = shape.rotation;
  return kin3::V3{shape.at.x + r[0] * local.x + r[1] * local.y + r[2] * local.z,
                  shape.at.y + r[3] * local.x + r[4] * local.y + r[5] * local.z,
                  shape.at.z + r[6] * local.x + r[7] * local.y + r[8] * local.z};
}

}  // namespace phiq::detail::parts
