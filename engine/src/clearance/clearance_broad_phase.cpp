// The broad phase of `pairs: all` (clearance_internal.hpp): the parts' boxes over a step in FCL's dynamic AABB tree,
// whose self-collision query lists the overlapping pairs without testing every pair.
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>

#include <algorithm>

#include "clearance/clearance_internal.hpp"

namespace phiq::detail {

namespace {

constexpr double kLargestSide = 1e100;  // m: a box side whose square FCL's norms hold with room to spare

// FCL's callback for each pair of objects whose boxes overlap: the boxes are the objects, so that is the answer.
bool record_pair(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data) {
  auto* found = static_cast<std::vector<std::pair<Index, Index>>*>(data);
  const auto a = static_cast<Index>(reinterpret_cast<std::intptr_t>(o1->getUserData()));
  const auto b = static_cast<Index>(reinterpret_cast<std::intptr_t>(o2->getUserData()));
  found->emplace_back(std::min(a, b), std::max(a, b));
  return false;  // go on
}

}  // namespace

struct BroadPhase::Impl {
  std::vector<std::shared_ptr<fcl::Boxd>> shapes;               // per part present
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;  // per part present
  std::vector<Index> part;                                      // the part of each object
  fcl::DynamicAABBTreeCollisionManagerd manager;
  bool registered = false;
};

BroadPhase::BroadPhase(const std::vector<bool>& present) : impl_(std::make_unique<Impl>()) {
  for (std::size_t i = 0; i < present.size(); ++i) {
    if (!present[i]) continue;
    impl_->shapes.push_back(std::make_shared<fcl::Boxd>(1, 1, 1));
    impl_->objects.push_back(std::make_unique<fcl::CollisionObjectd>(impl_->shapes.back()));
    impl_->objects.back()->setUserData(reinterpret_cast<void*>(static_cast<std::intptr_t>(i)));
    impl_->part.push_back(static_cast<Index>(i));
  }
}

BroadPhase::~BroadPhase() = default;

std::vector<std::pair<Index, Index>> BroadPhase::overlapping(const std::vector<SweptBox>& boxes) {
  Impl& m = *impl_;
  // FCL bounds a box by the norm of its half-diagonal: a side beyond ~1e154 (a threshold of 1e300 m, a speed
  // that overflows) makes that infinite and the tree's arithmetic NaN, and its queries then read outside their
  // nodes. Boxes that large overlap everything anyway: every pair is a candidate.
  const auto huge = [](const SweptBox& b) {
    return !(b.hi.x - b.lo.x < kLargestSide && b.hi.y - b.lo.y < kLargestSide && b.hi.z - b.lo.z < kLargestSide);
  };
  if (std::any_of(m.part.begin(), m.part.end(), [&](Index p) { return huge(boxes[static_cast<std::size_t>(p)]); })) {
    std::vector<std::pair<Index, Index>> every;
    for (std::size_t i = 0; i < m.part.size(); ++i)
      for (std::size_t j = i + 1; j < m.part.size(); ++j) every.emplace_back(m.part[i], m.part[j]);
    return every;
  }
  for (std::size_t j = 0; j < m.objects.size(); ++j) {
    const SweptBox& b = boxes[static_cast<std::size_t>(m.part[j])];
    m.shapes[j]->side = fcl::Vector3d(b.hi.x - b.lo.x, b.hi.y - b.lo.y, b.hi.z - b.lo.z);
    m.shapes[j]->computeLocalAABB();
    m.objects[j]->setTranslation(fcl::Vector3d((b.lo.x + b.hi.x) / 2, (b.lo.y + b.hi.y) / 2, (b.lo.z + b.hi.z) / 2));
    m.objects[j]->computeAABB();
  }
  if (!m.registered) {
    std::vector<fcl::CollisionObjectd*> all;
    for (auto& o : m.objects) all.push_back(o.get());
    m.manager.registerObjects(all);
    m.manager.setup();
    m.registered = true;
  } else {
    m.manager.update();
  }
  std::vector<std::pair<Index, Index>> found;
  m.manager.collide(&found, record_pair);  // each overlapping pair once
  return found;
}

}  // namespace phiq::detail
