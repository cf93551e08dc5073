// ClearanceGeometry (phiq/clearance.hpp): each part's shapes as FCL collision geometries in the part's frame, built
// once, and the signed distance between two parts as the smallest over their shapes' pairs.
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include <cmath>
#include <limits>

#include "phiq/clearance.hpp"
#include "phiq/types.hpp"

namespace phiq {

namespace detail {

using FclGeometry = std::shared_ptr<fcl::CollisionGeometryd>;

// One shape of a part: its FCL geometry and where its own frame lies in the part's frame.
struct PlacedGeometry {
  FclGeometry geometry;
  fcl::Transform3d in_part = fcl::Transform3d::Identity();
};

}  // namespace detail

namespace {

using detail::FclGeometry;
using detail::PlacedGeometry;

fcl::Matrix3d to_matrix(const RotationMatrix& r) {
  fcl::Matrix3d m;
  m << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
  return m;
}

fcl::Transform3d to_transform(const Pose& p) {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.linear() = to_matrix(p.rotation);
  tf.translation() = fcl::Vector3d(p.at.x, p.at.y, p.at.z);
  return tf;
}

// A BVH of the shape's triangles, in the part's frame (shape_triangles() applies the placement).
FclGeometry bvh_of(const Shape& s) {
  const TriangleMesh m = shape_triangles(s);
  auto model = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
  std::vector<fcl::Vector3d> vertices;
  vertices.reserve(m.vertices.size());
  for (const kin3::V3& v : m.vertices) vertices.emplace_back(v.x, v.y, v.z);
  std::vector<fcl::Triangle> triangles;
  triangles.reserve(m.triangles.size());
  for (const auto& t : m.triangles)
    triangles.emplace_back(static_cast<std::size_t>(t[0]), static_cast<std::size_t>(t[1]),
                           static_cast<std::size_t>(t[2]));
  model->beginModel();
  model->addSubModel(vertices, triangles);
  model->endModel();
  model->computeLocalAABB();
  return model;
}

// The shape as FCL's primitive where it has one (in the shape's own frame), else as a BVH in the part's frame.
PlacedGeometry placed(const Shape& s) {
  PlacedGeometry g;
  g.in_part.linear() = to_matrix(s.rotation);
  g.in_part.translation() = fcl::Vector3d(s.at.x, s.at.y, s.at.z);
  switch (s.kind) {
    case ShapeKind::kBox:
      g.geometry = std::make_shared<fcl::Boxd>(s.size.x, s.size.y, s.size.z);
      break;
    case ShapeKind::kSphere:
      g.geometry = std::make_shared<fcl::Sphered>(s.radius);
      break;
    case ShapeKind::kCylinder:
      g.geometry = std::make_shared<fcl::Cylinderd>(s.radius, s.length);
      break;
    case ShapeKind::kCapsule:
      g.geometry = std::make_shared<fcl::Capsuled>(s.radius, s.length);
      break;
    case ShapeKind::kCone:
      // FCL's cone is centred on its axis' midpoint; phiq's has its base in z = 0
      g.geometry = std::make_shared<fcl::Coned>(s.radius, s.length);
      g.in_part = g.in_part * fcl::Translation3d(0, 0, s.length / 2);
      break;
    default:
      g.geometry = bvh_of(s);
      g.in_part = fcl::Transform3d::Identity();
  }
  g.geometry->computeLocalAABB();
  return g;
}

// The radius about the part's origin that holds the shape: its local AABB's corners, transformed.
double shape_reach(const PlacedGeometry& g) {
  const fcl::AABBd& box = g.geometry->aabb_local;
  double r = 0.0;
  for (int c = 0; c < 8; ++c) {
    const fcl::Vector3d corner((c & 1) ? box.max_[0] : box.min_[0], (c & 2) ? box.max_[1] : box.min_[1],
                               (c & 4) ? box.max_[2] : box.min_[2]);
    r = std::max(r, (g.in_part * corner).norm());
  }
  return r;
}

kin3::V3 v3(const fcl::Vector3d& v) { return {v[0], v[1], v[2]}; }

}  // namespace

struct ClearanceGeometry::Impl {
  std::vector<std::vector<detail::PlacedGeometry>> parts;
  std::vector<double> radius;
};

ClearanceGeometry::ClearanceGeometry(const std::vector<Part>& parts) : impl_(std::make_unique<Impl>()) {
  for (const Part& p : parts) {
    std::vector<PlacedGeometry> shapes;
    double r = 0.0;
    for (const Shape& s : p.shapes) {
      shapes.push_back(placed(s));
      r = std::max(r, shape_reach(shapes.back()));
    }
    impl_->parts.push_back(std::move(shapes));
    impl_->radius.push_back(r);
  }
}

ClearanceGeometry::~ClearanceGeometry() = default;
ClearanceGeometry::ClearanceGeometry(ClearanceGeometry&&) noexcept = default;
ClearanceGeometry& ClearanceGeometry::operator=(ClearanceGeometry&&) noexcept = default;

double ClearanceGeometry::bounding_radius(Index part) const { return impl_->radius[static_cast<std::size_t>(part)]; }

std::pair<kin3::V3, kin3::V3> ClearanceGeometry::world_box(Index part, const Pose& pose) const {
  const double inf = std::numeric_limits<double>::infinity();
  fcl::Vector3d lo(inf, inf, inf), hi(-inf, -inf, -inf);
  const fcl::Transform3d tf = to_transform(pose);
  for (const PlacedGeometry& g : impl_->parts[static_cast<std::size_t>(part)]) {
    const fcl::Transform3d t = tf * g.in_part;
    // the box's centre moved, its half extents through |R|
    const fcl::AABBd& box = g.geometry->aabb_local;
    const fcl::Vector3d centre = t * box.center();
    const fcl::Vector3d half = t.linear().cwiseAbs() * (0.5 * (box.max_ - box.min_));
    lo = lo.cwiseMin(centre - half);
    hi = hi.cwiseMax(centre + half);
  }
  return {v3(lo), v3(hi)};
}

bool ClearanceGeometry::has_shapes(Index part) const { return !impl_->parts[static_cast<std::size_t>(part)].empty(); }

namespace {

// The signed distance of two placed shapes: FCL's distance (GJK) apart; in overlap the deepest of FCL's contacts
// (exact for primitives: EPA or the pair's own test; for meshes the deepest triangle pair), its witness points
// either side of the contact point along the contact normal. Not FCL 0.7's signed distance, whose EPA asserts on
// touching shapes (gjk_libccd-inl.h, ComputeVisiblePatch).
PairDistance shape_distance(const PlacedGeometry& ga, const fcl::Transform3d& ta, const PlacedGeometry& gb,
                            const fcl::Transform3d& tb) {
  fcl::DistanceRequestd request(true, false, 0.0, 0.0, 1e-12, fcl::GST_LIBCCD);
  fcl::DistanceResultd result;
  fcl::distance(ga.geometry.get(), ta, gb.geometry.get(), tb, request, result);
  PairDistance d;
  d.distance = result.min_distance;
  d.point_a = v3(result.nearest_points[0]);
  d.point_b = v3(result.nearest_points[1]);
  if (d.distance <= 0.0) {
    fcl::CollisionRequestd creq(64, true);
    fcl::CollisionResultd cres;
    fcl::collide(ga.geometry.get(), ta, gb.geometry.get(), tb, creq, cres);
    double depth = 0.0;
    for (std::size_t i = 0; i < cres.numContacts(); ++i) {
      const fcl::Contactd& c = cres.getContact(i);
      if (c.penetration_depth < depth && i > 0) continue;
      depth = c.penetration_depth;
      // FCL's contact normal points from A to B
      d.point_a = v3(c.pos + 0.5 * depth * c.normal);
      d.point_b = v3(c.pos - 0.5 * depth * c.normal);
    }
    d.distance = -depth;
  }
  const kin3::V3 ab = d.point_b - d.point_a;
  const double len = norm(ab);
  if (len > 0.0) d.normal = (d.distance < 0.0 ? -1.0 / len : 1.0 / len) * ab;
  return d;
}

}  // namespace

PairDistance ClearanceGeometry::distance(Index a, const Pose& pose_a, Index b, const Pose& pose_b) const {
  const fcl::Transform3d ta = to_transform(pose_a), tb = to_transform(pose_b);
  PairDistance best;
  best.distance = std::numeric_limits<double>::infinity();
  for (const PlacedGeometry& ga : impl_->parts[static_cast<std::size_t>(a)])
    for (const PlacedGeometry& gb : impl_->parts[static_cast<std::size_t>(b)]) {
      const PairDistance d = shape_distance(ga, ta * ga.in_part, gb, tb * gb.in_part);
      if (d.distance < best.distance) best = d;
    }
  return best;
}

}  // namespace phiq
