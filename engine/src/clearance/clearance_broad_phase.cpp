// The broad phase of `pairs: all` (clearance_internal.hpp): the parts' boxes over a step in FCL's dynamic AABB tree,
// whose self-collision query lists the overlapping pairs without testing every pair.
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>

#include <algorithm>

#include "clearance/clearance_internal.hpp"

namespace phiq::detail {

namespace {

struct Found {
  std::vector<std::pair<Index, Index>> pairs;
};

// FCL's callback for each pair of objects whose boxes overlap: the boxes are the objects, so that is the answer.
bool record_pair(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data) {
  auto* found = static_cast<Found*>(data);
  const auto a = static_cast<Index>(reinterpret_cast<std::intptr_t>(o1->getUserData()));
  const auto b = static_cast<Index>(reinterpret_cast<std::intptr_t>(o2->getUserData()));
  found->pairs.emplace_back(std::min(a, b), std::max(a, b));
  return false;  // go on
}

}  // namespace

std::vector<std::pair<Index, Index>> overlapping_boxes(const std::vector<SweptBox>& boxes) {
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  std::vector<fcl::CollisionObjectd*> registered;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const SweptBox& b = boxes[i];
    if (b.lo.x > b.hi.x) continue;
    auto shape = std::make_shared<fcl::Boxd>(b.hi.x - b.lo.x, b.hi.y - b.lo.y, b.hi.z - b.lo.z);
    fcl::Transform3d tf = fcl::Transform3d::Identity();
    tf.translation() = fcl::Vector3d((b.lo.x + b.hi.x) / 2, (b.lo.y + b.hi.y) / 2, (b.lo.z + b.hi.z) / 2);
    objects.push_back(std::make_unique<fcl::CollisionObjectd>(shape, tf));
    objects.back()->setUserData(reinterpret_cast<void*>(static_cast<std::intptr_t>(i)));
    registered.push_back(objects.back().get());
  }
  fcl::DynamicAABBTreeCollisionManagerd manager;
  manager.registerObjects(registered);
  manager.setup();
  Found found;
  manager.collide(&found, record_pair);
  std::sort(found.pairs.begin(), found.pairs.end());
  found.pairs.erase(std::unique(found.pairs.begin(), found.pairs.end()), found.pairs.end());
  return found.pairs;
}

}  // namespace phiq::detail
