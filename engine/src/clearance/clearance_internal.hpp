// Internal to the clearance stage: which pairs a plan selects, without listing every pair of a large model, and the
// broad phase that finds the pairs worth measuring among them.
#pragma once

#include <set>
#include <utility>
#include <vector>

#include "phiq/clearance.hpp"

namespace phiq::detail {

// The pairs of a ClearancePlan: its list, or every eligible pair (both with shapes, not both fixed), less skipped.
struct PairSelection {
  PairSelection(const Model& model, const std::vector<Part>& parts, const ClearancePlan& plan);
  bool all = false;
  std::set<std::pair<Index, Index>> skipped;  // a < b
  std::set<std::pair<Index, Index>> listed;   // a < b
  std::vector<bool> shaped, fixed;            // per part
  Index count = 0;                            // the pairs selected
  bool eligible(Index a, Index b) const;
  bool selects(Index a, Index b) const;
};

// An axis-aligned box (world axes) that holds a part over an interval of time.
struct SweptBox {
  kin3::V3 lo, hi;
};

// The pairs of `boxes` that overlap (a < b, each once), by FCL's dynamic AABB tree; parts with no box (lo > hi)
// take no part.
std::vector<std::pair<Index, Index>> overlapping_boxes(const std::vector<SweptBox>& boxes);

}  // namespace phiq::detail
