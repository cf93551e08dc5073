// Mass properties of shapes (shapes.hpp): the primitives and the extruded polygon in closed form, a mesh by the
// divergence theorem, then the shape's placement; their sum and the parallel-axis theorem.
#include <cmath>
#include <numbers>
#include <string>

#include "parts/polygon.hpp"
#include "parts/shape_checks.hpp"
#include "phiq/shapes.hpp"
#include "phiq/text.hpp"
#include "phiq/types.hpp"

namespace phiq {

namespace {

using kin3::V3;
using Matrix3 = std::array<double, 9>;
constexpr double kPi = std::numbers::pi;

// m (|d|² 1 − d dᵀ): what the parallel-axis theorem adds to an inertia about the centre of mass when the axes pass
// through a point at −d from it.
Matrix3 point_mass_inertia(double mass, V3 d) {
  const double dd = kin3::dot(d, d);
  return {mass * (dd - d.x * d.x), -mass * d.x * d.y,       -mass * d.x * d.z,
          -mass * d.y * d.x,       mass * (dd - d.y * d.y), -mass * d.y * d.z,
          -mass * d.z * d.x,       -mass * d.z * d.y,       mass * (dd - d.z * d.z)};
}

Matrix3 add(const Matrix3& a, const Matrix3& b, double kb = 1.0) {
  Matrix3 sum;
  for (int k = 0; k < 9; ++k) sum[k] = a[k] + kb * b[k];
  return sum;
}

// In the shape's own frame: mass, centre, and the principal moments about the centre along the shape's axes.
MassProperties principal(double mass, V3 center, double ixx, double iyy, double izz) {
  MassProperties p;
  p.mass = mass, p.center = center;
  p.inertia = {ixx, 0, 0, 0, iyy, 0, 0, 0, izz};
  return p;
}

// A solid of revolution about z from its volume (per unit density), centre height, and the moments per unit mass
// about its centre: transverse (x, y) and axial (z).
MassProperties about_z(double density, double volume, double center_z, double transverse, double axial) {
  const double m = density * volume;
  return principal(m, {0, 0, center_z}, m * transverse, m * transverse, m * axial);
}

MassProperties capsule(double density, double r, double length) {
  // A cylinder of `length` and two hemispheres. A hemisphere of mass mh about its flat face's centre has 2/5 mh r²
  // about every axis through it (half a sphere's); its centroid is 3r/8 from the face, so about the capsule's
  // centre (transverse) it has 2/5 mh r² − mh (3r/8)² + mh (L/2 + 3r/8)² = mh (2/5 r² + L²/4 + 3 r L/8).
  const double mc = density * kPi * r * r * length, mh = density * 2.0 / 3.0 * kPi * r * r * r;
  const double transverse = mc * (3.0 * r * r + length * length) / 12.0 +
                            2.0 * mh * (0.4 * r * r + length * length / 4.0 + 3.0 * r * length / 8.0);
  const double axial = mc * r * r / 2.0 + 2.0 * mh * 0.4 * r * r;
  return principal(mc + 2.0 * mh, {}, transverse, transverse, axial);
}

// The prism of a polygon outline extruded over `thickness` along z, centred on z = 0. The area moments are taken
// about the outline's vertex mean (no cancellation for an outline far from the origin); the prism's inertia about
// that point is ρ t (∫y², ∫x², ∫x²+y²) on the diagonal, −ρ t ∫xy off it, plus m t²/12 for the extent in z about x
// and y; the parallel-axis theorem then moves it to the centroid.
MassProperties polygon_prism(const Shape& shape, double density) {
  detail::parts::Outline outline = detail::parts::counter_clockwise_outline(shape);
  double mx = 0.0, my = 0.0;
  for (const auto& v : outline) mx += v[0], my += v[1];
  mx /= static_cast<double>(outline.size()), my /= static_cast<double>(outline.size());
  for (auto& v : outline) v[0] -= mx, v[1] -= my;
  const detail::parts::AreaMoments a = detail::parts::area_moments(outline);
  const double t = shape.length, rt = density * t, m = rt * a.area;
  const Matrix3 about_mean{rt * a.yy + m * t * t / 12.0,
                           -rt * a.xy,
                           0,
                           -rt * a.xy,
                           rt * a.xx + m * t * t / 12.0,
                           0,
                           0,
                           0,
                           rt * (a.xx + a.yy)};
  const V3 c{a.x / a.area, a.y / a.area, 0.0};
  MassProperties p;
  p.mass = m, p.center = V3{mx, my, 0.0} + c;
  p.inertia = add(about_mean, point_mass_inertia(m, c), -1.0);
  return p;
}

MassProperties closed_mesh(const Shape& shape, double density) {
  if (!mesh_is_closed(*shape.mesh))
    throw Error(detail::parts::shape_label(shape) +
                ": the mesh is not closed (an edge not shared by exactly two triangles in opposite directions), so "
                "it bounds no volume");
  MassProperties p = mesh_mass_properties(*shape.mesh);
  if (!(p.mass > 0.0))
    throw Error(detail::parts::shape_label(shape) + ": the mesh's volume is " + significant(p.mass, 6) +
                " (its triangles face inwards: counter-clockwise seen from outside is outwards)");
  p.mass *= density;
  for (double& v : p.inertia) v *= density;
  return p;
}

// The mass properties in the shape's own frame.
MassProperties in_shape_frame(const Shape& shape, double density) {
  const double r = shape.radius, h = shape.length;
  switch (shape.kind) {
    case ShapeKind::kBox: {
      const double a = shape.size.x, b = shape.size.y, c = shape.size.z, m = density * a * b * c;
      return principal(m, {}, m * (b * b + c * c) / 12.0, m * (a * a + c * c) / 12.0, m * (a * a + b * b) / 12.0);
    }
    case ShapeKind::kCylinder:
      return about_z(density, kPi * r * r * h, 0.0, (3.0 * r * r + h * h) / 12.0, r * r / 2.0);
    case ShapeKind::kSphere:
      return about_z(density, 4.0 / 3.0 * kPi * r * r * r, 0.0, 0.4 * r * r, 0.4 * r * r);
    case ShapeKind::kCapsule:
      return capsule(density, r, h);
    case ShapeKind::kCone:  // centroid a quarter of the height above the base
      return about_z(density, kPi * r * r * h / 3.0, h / 4.0, 3.0 / 80.0 * (4.0 * r * r + h * h), 0.3 * r * r);
    case ShapeKind::kPolygon:
      return polygon_prism(shape, density);
    case ShapeKind::kMesh:
      return closed_mesh(shape, density);
    case ShapeKind::kPlane:
    case ShapeKind::kCurve:
      break;
  }
  throw Error(detail::parts::shape_label(shape) + ": has no volume, so no mass properties");
}

}  // namespace

MassProperties shape_mass_properties(const Shape& shape, double density) {
  if (!(density > 0.0) || !std::isfinite(density))
    throw Error(detail::parts::shape_label(shape) + ": density " + shortest(density) + " is not a positive number");
  if (shape.kind == ShapeKind::kPlane || shape.kind == ShapeKind::kCurve)
    throw Error(detail::parts::shape_label(shape) + ": has no volume, so no mass properties");
  detail::parts::check_shape(shape);
  const MassProperties local = in_shape_frame(shape, density);
  // In the body frame: the centre placed, the inertia turned, R I Rᵀ.
  const RotationMatrix& rot = shape.rotation;
  MassProperties placed;
  placed.mass = local.mass;
  placed.center = detail::parts::place_point(shape, local.center);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double v = 0.0;
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) v += rot[3 * i + k] * local.inertia[3 * k + l] * rot[3 * j + l];
      placed.inertia[3 * i + j] = v;
    }
  return placed;
}

MassProperties combine_mass_properties(const std::vector<MassProperties>& parts) {
  MassProperties sum;
  V3 moment;
  for (const MassProperties& p : parts) sum.mass += p.mass, moment = moment + p.mass * p.center;
  if (sum.mass == 0.0) return sum;
  sum.center = (1.0 / sum.mass) * moment;
  for (const MassProperties& p : parts)
    sum.inertia = add(sum.inertia, add(p.inertia, point_mass_inertia(p.mass, p.center - sum.center)));
  return sum;
}

std::array<double, 9> inertia_about(const MassProperties& m, kin3::V3 point) {
  return add(m.inertia, point_mass_inertia(m.mass, m.center - point));
}

MassProperties mesh_mass_properties(const TriangleMesh& mesh) {
  // The divergence theorem turns each volume integral into one over the surface; triangle by triangle that is the
  // signed tetrahedron (o, a, b, c) from a reference point o, with D = a · (b × c) six times its signed volume:
  //   ∫ 1 = D/6,   ∫ x = D/24 (a + b + c),   ∫ x xᵀ = D/120 (a aᵀ + b bᵀ + c cᵀ + s sᵀ),  s = a + b + c,
  // exact for the polyhedron. o is the vertex mean, so that a mesh far from the origin loses no digits.
  MassProperties p;
  if (mesh.vertices.empty()) return p;
  V3 o;
  for (const V3& v : mesh.vertices) o = o + v;
  o = (1.0 / static_cast<double>(mesh.vertices.size())) * o;
  double volume = 0.0;
  V3 first;
  Matrix3 second{};
  for (std::size_t k = 0; k < mesh.triangles.size(); ++k) {
    const auto& t = mesh.triangles[k];
    for (int v : t)
      if (v < 0 || static_cast<std::size_t>(v) >= mesh.vertices.size())
        throw Error("mesh_mass_properties: triangle " + std::to_string(k) + " names vertex " + std::to_string(v) +
                    " of " + std::to_string(mesh.vertices.size()));
    const V3 a = mesh.vertices[t[0]] - o, b = mesh.vertices[t[1]] - o, c = mesh.vertices[t[2]] - o, s = a + b + c;
    const double d = kin3::dot(a, kin3::cross(b, c));
    volume += d / 6.0;
    first = first + (d / 24.0) * s;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        second[3 * i + j] +=
            d / 120.0 *
            (kin3::component(a, i) * kin3::component(a, j) + kin3::component(b, i) * kin3::component(b, j) +
             kin3::component(c, i) * kin3::component(c, j) + kin3::component(s, i) * kin3::component(s, j));
  }
  p.mass = volume;
  if (volume == 0.0) {
    p.center = o;
    return p;
  }
  const V3 c = (1.0 / volume) * first;
  // second moments about the centroid, C − V c cᵀ; the inertia is tr(C) 1 − C
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) second[3 * i + j] -= volume * kin3::component(c, i) * kin3::component(c, j);
  const double trace = second[0] + second[4] + second[8];
  for (int k = 0; k < 9; ++k) p.inertia[k] = (k % 4 == 0 ? trace : 0.0) - second[k];
  p.center = o + c;
  return p;
}

}  // namespace phiq
