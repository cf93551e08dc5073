// A shape's label in messages and the checks of its sizes and placement (shape_checks.hpp).
#include "parts/shape_checks.hpp"

#include <algorithm>
#include <cmath>

#include "phiq/text.hpp"
#include "phiq/types.hpp"

namespace phiq {

const char* to_string(ShapeKind kind) {
  switch (kind) {
    case ShapeKind::kBox:
      return "box";
    case ShapeKind::kCylinder:
      return "cylinder";
    case ShapeKind::kSphere:
      return "sphere";
    case ShapeKind::kCapsule:
      return "capsule";
    case ShapeKind::kCone:
      return "cone";
    case ShapeKind::kPlane:
      return "plane";
    case ShapeKind::kPolygon:
      return "polygon";
    case ShapeKind::kMesh:
      return "mesh";
    case ShapeKind::kCurve:
      return "curve";
  }
  return "shape";
}

}  // namespace phiq

namespace phiq::detail::parts {

std::string shape_label(const Shape& shape) {
  std::string label = to_string(shape.kind);
  if (!shape.name.empty()) label += " '" + single_line(shape.name) + "'";
  if (shape.kind == ShapeKind::kMesh && !shape.file.empty()) label += " (" + single_line(shape.file) + ")";
  return label;
}

namespace {

void require_positive(const Shape& shape, const char* field, double value) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw Error(shape_label(shape) + ": " + field + " " + shortest(value) + " is not a positive length");
}

// Orthonormal columns to 1e-9 and no reflection: inertia R I Rᵀ and drawn normals are only right for a rotation.
void require_rotation(const Shape& shape) {
  const RotationMatrix& r = shape.rotation;
  for (double v : r)
    if (!std::isfinite(v)) throw Error(shape_label(shape) + ": rotation has a non-finite entry");
  double worst = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double rtr = r[i] * r[j] + r[3 + i] * r[3 + j] + r[6 + i] * r[6 + j];  // (Rᵀ R)_ij
      worst = std::max(worst, std::abs(rtr - (i == j ? 1.0 : 0.0)));
    }
  const double det =
      r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6]) + r[2] * (r[3] * r[7] - r[4] * r[6]);
  if (worst > 1e-9 || det < 0.0)
    throw Error(shape_label(shape) + ": rotation is not a rotation matrix (|RᵀR − 1| = " + scientific(worst, 1) +
                ", det = " + significant(det, 6) + ")");
}

}  // namespace

void check_shape(const Shape& shape) {
  if (!std::isfinite(shape.at.x) || !std::isfinite(shape.at.y) || !std::isfinite(shape.at.z))
    throw Error(shape_label(shape) + ": 'at' is not finite");
  require_rotation(shape);
  switch (shape.kind) {
    case ShapeKind::kBox:
      require_positive(shape, "size x", shape.size.x);
      require_positive(shape, "size y", shape.size.y);
      require_positive(shape, "size z", shape.size.z);
      break;
    case ShapeKind::kPlane:
      require_positive(shape, "size x", shape.size.x);
      require_positive(shape, "size y", shape.size.y);
      break;
    case ShapeKind::kSphere:
      require_positive(shape, "radius", shape.radius);
      break;
    case ShapeKind::kCylinder:
    case ShapeKind::kCapsule:
    case ShapeKind::kCone:
      require_positive(shape, "radius", shape.radius);
      require_positive(shape, "length", shape.length);
      break;
    case ShapeKind::kPolygon:
      require_positive(shape, "length (thickness)", shape.length);
      break;
    case ShapeKind::kMesh:
      if (!shape.mesh || shape.mesh->triangles.empty()) throw Error(shape_label(shape) + ": the mesh has no triangles");
      break;
    case ShapeKind::kCurve:
      require_positive(shape, "radius (width)", shape.radius);
      if (shape.points.size() < 2) throw Error(shape_label(shape) + ": a curve needs at least two points");
      break;
  }
}

}  // namespace phiq::detail::parts
