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

// FCL's distance (GJK, or the pair's closed form) between two placed shapes, with its nearest points.
fcl::DistanceResultd fcl_distance(const PlacedGeometry& ga, const fcl::Transform3d& ta, const PlacedGeometry& gb,
                                  const fcl::Transform3d& tb) {
  const fcl::DistanceRequestd request(true, false, 0.0, 0.0, 1e-12, fcl::GST_LIBCCD);
  fcl::DistanceResultd result;
  fcl::distance(ga.geometry.get(), ta, gb.geometry.get(), tb, request, result);
  return result;
}

bool is_mesh(const PlacedGeometry& g) { return g.geometry->getObjectType() == fcl::OT_BVH; }

// The witness points of an overlap of depth `depth` along `normal` (A to B): A moved back along −normal by the depth
// and a gap, the nearest points of the parted shapes, A's moved forward again. For convex shapes (FCL's
// primitives) the nearest points of the parted pair are the touching points of the minimum translation, so A's
// point is A's deepest point inside B along the normal, B's the deepest inside A, the depth apart, each on its own
// surface (FCL's contact position is not: for two spheres it divides the line of centres in the ratio of the
// radii, elsewhere it is a midpoint). Where the parted pair's separation turns from the normal (FCL's MPR, used
// for pairs without a closed form, gives a depth along a direction that is not always the least), the depth of the
// overlap along the new direction, T (n·v) − gap, is again an upper bound on the depth and the step is repeated
// from there while it shrinks; the depth reported is the one of the points reported. A mesh is not convex: its contact
// is taken as FCL gives it when parting it along the normal does not leave the gap expected.
PairDistance overlap_witnesses(const PlacedGeometry& ga, const fcl::Transform3d& ta, const PlacedGeometry& gb,
                               const fcl::Transform3d& tb, const fcl::Contactd& contact) {
  fcl::Vector3d n = contact.normal.normalized();
  double depth = contact.penetration_depth;
  PairDistance d;
  d.distance = -depth;
  d.point_a = v3(contact.pos + 0.5 * depth * n);
  d.point_b = v3(contact.pos - 0.5 * depth * n);
  const bool convex = !is_mesh(ga) && !is_mesh(gb);
  double least = std::numeric_limits<double>::infinity();
  for (int iteration = 0; iteration < 32; ++iteration) {
    const double gap = std::max(depth, 1e-6);
    const double moved = depth + gap;
    const fcl::Transform3d ta_parted = fcl::Translation3d(-moved * n) * ta;
    const fcl::DistanceResultd parted = fcl_distance(ga, ta_parted, gb, tb);
    // the gap between the nearest points, not GJK's distance, which libccd leaves less converged than its points
    const fcl::Vector3d separation = parted.nearest_points[1] - parted.nearest_points[0];
    const double found = separation.norm();
    if (!(parted.min_distance > 0.0) || !(found > 0.0)) break;
    const fcl::Vector3d a = parted.nearest_points[0] + moved * n, b = parted.nearest_points[1];
    const fcl::Vector3d v = separation / found;
    const double along_v = moved * n.dot(v) - found;
    if (!convex) {
      if (std::abs(found - gap) <= 1e-9 * moved) d.point_a = v3(a), d.point_b = v3(b);
      break;
    }
    if (!(along_v < least)) break;  // no longer shrinking: the least found stands
    least = along_v;
    d.distance = -along_v;  // the depth the points give (libccd's MPR depth is looser)
    d.point_a = v3(a);
    d.point_b = v3(b);
    if (n.dot(v) > 1.0 - 1e-15) break;
    n = v;
    depth = along_v;
  }
  return d;
}

// The signed distance of two placed shapes: FCL's distance (GJK) apart; in overlap the deepest of FCL's contacts
// (for primitives: the pair's closed form, else libccd's MPR refined by overlap_witnesses(); for meshes the deepest
// triangle pair), with the witness points of overlap_witnesses(). Not FCL 0.7's signed distance, whose EPA asserts
// on touching shapes (gjk_libccd-inl.h, ComputeVisiblePatch).
PairDistance shape_distance(const PlacedGeometry& ga, const fcl::Transform3d& ta, const PlacedGeometry& gb,
                            const fcl::Transform3d& tb) {
  const fcl::DistanceResultd result = fcl_distance(ga, ta, gb, tb);
  PairDistance d;
  d.distance = result.min_distance;
  d.point_a = v3(result.nearest_points[0]);
  d.point_b = v3(result.nearest_points[1]);
  if (d.distance <= 0.0) {
    fcl::CollisionRequestd creq(64, true);
    fcl::CollisionResultd cres;
    fcl::collide(ga.geometry.get(), ta, gb.geometry.get(), tb, creq, cres);
    std::size_t deepest = cres.numContacts();
    for (std::size_t i = 0; i < cres.numContacts(); ++i)
      if (deepest == cres.numContacts() ||
          cres.getContact(i).penetration_depth > cres.getContact(deepest).penetration_depth)
        deepest = i;
    // FCL's contact normal points from A to B; shapes that touch meet at the contact
    d.distance = 0.0;
    if (deepest < cres.numContacts() && cres.getContact(deepest).penetration_depth > 0.0)
      d = overlap_witnesses(ga, ta, gb, tb, cres.getContact(deepest));
    else if (deepest < cres.numContacts())
      d.point_a = d.point_b = v3(cres.getContact(deepest).pos);
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
