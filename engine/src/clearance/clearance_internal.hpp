// Internal to the clearance stage: which pairs a plan selects, without listing every pair of a large model, and the
// broad phase that finds the pairs worth measuring among them.
#pragma once

#include <memory>
#include <set>
#include <utility>
#include <vector>

#include "phiq/clearance.hpp"

namespace phiq::detail {

// The pairs of a ClearancePlan: its list, or every eligible pair (both with shapes, not both fixed), less skipped.
struct PairSelection {
  PairSelection(const Model& model, const std::vector<Part>& parts, const ClearancePlan& plan);
  bool all = false;
  std::vector<std::pair<Index, Index>> skipped;  // a < b, sorted, each once
  std::vector<std::vector<Index>> skipped_with;  // per part, the parts it is skipped with (a few)
  std::set<std::pair<Index, Index>> listed;      // a < b
  std::vector<bool> shaped, fixed;               // per part
  Index count = 0;                               // the pairs selected
  bool eligible(Index a, Index b) const;
  bool selects(Index a, Index b) const;
};

// An axis-aligned box (world axes) that holds a part over an interval of time.
struct SweptBox {
  kin3::V3 lo, hi;
};

// FCL's dynamic AABB tree over one box per part (those `present`), kept from one step to the next: each step moves
// the boxes and updates the tree rather than building it again.
class BroadPhase {
 public:
  explicit BroadPhase(const std::vector<bool>& present);
  ~BroadPhase();
  // The pairs of `boxes` (one per part; those not present ignored) that overlap: a < b, each once.
  std::vector<std::pair<Index, Index>> overlapping(const std::vector<SweptBox>& boxes);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace phiq::detail
