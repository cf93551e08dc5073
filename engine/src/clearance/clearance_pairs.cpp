// Which pairs of parts a clearance pass measures (phiq/clearance.hpp): the plan's own list, or every pair, less the
// pairs skipped by name and those joined by the model's constraints (adjacent_parts()).
#include <algorithm>
#include <set>

#include "phiq/clearance.hpp"
#include "phiq/mechanism_sketch.hpp"
#include "phiq/model.hpp"
#include "phiq/output_points.hpp"
#include "clearance/clearance_internal.hpp"

namespace phiq {

namespace {

std::pair<Index, Index> ordered(Index a, Index b) { return a < b ? std::pair{a, b} : std::pair{b, a}; }

// For each constraint of the model, the parts whose frames read a coordinate its rows read.
std::vector<std::vector<Index>> parts_of_constraints(const Model& model, const std::vector<Part>& parts) {
  std::vector<std::vector<Index>> parts_of_coordinate(static_cast<std::size_t>(model.num_coordinates()));
  for (std::size_t p = 0; p < parts.size(); ++p)
    for (Index j : frame_coordinates(parts[p].frame))
      if (j < model.num_coordinates())
        parts_of_coordinate[static_cast<std::size_t>(j)].push_back(static_cast<Index>(p));
  std::vector<std::set<Index>> found(model.constraints().size());
  const CscPattern& pattern = model.jacobian_pattern();
  for (Index j = 0; j < pattern.cols; ++j) {
    const auto& readers = parts_of_coordinate[static_cast<std::size_t>(j)];
    if (readers.empty()) continue;
    for (Index k = pattern.col_ptr[static_cast<std::size_t>(j)]; k < pattern.col_ptr[static_cast<std::size_t>(j) + 1];
         ++k) {
      const Index c = model.constraint_of_row(pattern.row_idx[static_cast<std::size_t>(k)]);
      found[static_cast<std::size_t>(c)].insert(readers.begin(), readers.end());
    }
  }
  std::vector<std::vector<Index>> out;
  out.reserve(found.size());
  for (const auto& s : found) out.emplace_back(s.begin(), s.end());
  return out;
}

// The parts and, last, a point: a sphere of no radius that probes which fixed part holds a ground pivot.
std::vector<Part> parts_and_probe(const std::vector<Part>& parts) {
  std::vector<Part> out = parts;
  Part probe;
  probe.shapes.emplace_back();
  probe.shapes.back().kind = ShapeKind::kSphere;
  out.push_back(std::move(probe));
  return out;
}

// Whether the fixed part `index` holds the world point `x` (inside or on its shapes, to 1 nm).
bool holds_point(const Part& p, const ClearanceGeometry& geometry, Index index, Index probe, kin3::V3 x) {
  if (!geometry.has_shapes(index)) return false;
  Pose at;
  at.at = x;
  return geometry.distance(index, part_pose(p.frame, nullptr, 0.0), probe, at).distance <= 1e-9;
}

}  // namespace

std::vector<std::pair<Index, Index>> adjacent_parts(const Model& model, const std::vector<Part>& parts) {
  std::set<std::pair<Index, Index>> adjacent;
  // parts reading a coordinate in common: natural coordinates share the point where they are jointed
  std::vector<std::vector<Index>> readers(static_cast<std::size_t>(model.num_coordinates()));
  for (std::size_t p = 0; p < parts.size(); ++p)
    for (Index j : frame_coordinates(parts[p].frame))
      if (j < model.num_coordinates()) readers[static_cast<std::size_t>(j)].push_back(static_cast<Index>(p));
  for (const auto& r : readers)
    for (std::size_t a = 0; a < r.size(); ++a)
      for (std::size_t b = a + 1; b < r.size(); ++b) adjacent.insert(ordered(r[a], r[b]));
  const std::vector<std::vector<Index>> by_constraint = parts_of_constraints(model, parts);
  // parts on the same coordinates are one body: a constraint between exactly two bodies joins their parts
  std::vector<std::vector<Index>> coordinates(parts.size());
  for (std::size_t p = 0; p < parts.size(); ++p) coordinates[p] = frame_coordinates(parts[p].frame);
  auto bodies_of = [&](const std::vector<Index>& ps) {
    std::set<std::vector<Index>> bodies;
    for (Index p : ps) bodies.insert(coordinates[static_cast<std::size_t>(p)]);
    return bodies.size();
  };
  for (const auto& ps : by_constraint)
    if (bodies_of(ps) == 2)
      for (std::size_t a = 0; a < ps.size(); ++a)
        for (std::size_t b = a + 1; b < ps.size(); ++b)
          if (coordinates[static_cast<std::size_t>(ps[a])] != coordinates[static_cast<std::size_t>(ps[b])])
            adjacent.insert(ordered(ps[a], ps[b]));
  // joints to ground: the fixed parts that hold a fixed joint of the sketch are adjacent to the part it carries
  const ClearanceGeometry geometry(parts_and_probe(parts));
  const auto probe = static_cast<Index>(parts.size());
  const Eigen::VectorXd q = model.initial_positions();
  for (const SketchJoint& j : sketch_mechanism(model).joints) {
    if (!j.fixed || j.constraint < 0) continue;
    const auto& ps = by_constraint[static_cast<std::size_t>(j.constraint)];
    if (bodies_of(ps) != 1) continue;
    const PointMotion m = evaluate_point(j.at, q.data(), nullptr, nullptr);
    const kin3::V3 x{m.r[0], m.r[1], j.at.dimension() == 3 ? m.r[2] : 0.0};
    for (std::size_t f = 0; f < parts.size(); ++f)
      if (parts[f].fixed && holds_point(parts[f], geometry, static_cast<Index>(f), probe, x))
        for (Index p : ps) adjacent.insert(ordered(p, static_cast<Index>(f)));
  }
  return {adjacent.begin(), adjacent.end()};
}

detail::PairSelection::PairSelection(const Model& model, const std::vector<Part>& parts, const ClearancePlan& plan)
    : all(plan.all) {
  for (const auto& [a, b] : plan.skip) skipped.push_back(ordered(a, b));
  if (plan.skip_adjacent)
    for (const auto& ab : adjacent_parts(model, parts)) skipped.push_back(ab);
  std::sort(skipped.begin(), skipped.end());
  skipped.erase(std::unique(skipped.begin(), skipped.end()), skipped.end());
  skipped_with.resize(parts.size());
  for (const auto& [a, b] : skipped) skipped_with[static_cast<std::size_t>(a)].push_back(b);
  for (const auto& [a, b] : plan.pairs) listed.insert(ordered(a, b));
  for (const Part& p : parts) {
    shaped.push_back(!p.shapes.empty());
    fixed.push_back(p.fixed);
  }
  if (!all) {
    for (const auto& ab : listed) count += std::binary_search(skipped.begin(), skipped.end(), ab) ? 0 : 1;
    return;
  }
  Index n = 0, nf = 0;
  for (std::size_t p = 0; p < parts.size(); ++p) n += shaped[p] ? 1 : 0, nf += shaped[p] && fixed[p] ? 1 : 0;
  count = n * (n - 1) / 2 - nf * (nf - 1) / 2;
  for (const auto& [a, b] : skipped) count -= eligible(a, b) ? 1 : 0;
}

bool detail::PairSelection::eligible(Index a, Index b) const {
  const auto ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(b);
  return a != b && shaped[ua] && shaped[ub] && !(fixed[ua] && fixed[ub]);
}

bool detail::PairSelection::selects(Index a, Index b) const {
  const auto ab = ordered(a, b);
  const auto& with = skipped_with[static_cast<std::size_t>(ab.first)];
  if (std::find(with.begin(), with.end(), ab.second) != with.end()) return false;
  return all ? eligible(a, b) : listed.count(ab) > 0;
}

std::vector<std::pair<Index, Index>> clearance_pairs(const Model& model, const std::vector<Part>& parts,
                                                     const ClearancePlan& plan) {
  const detail::PairSelection selection(model, parts, plan);
  std::vector<std::pair<Index, Index>> kept;
  if (!plan.all) {
    for (const auto& ab : selection.listed)
      if (selection.selects(ab.first, ab.second)) kept.push_back(ab);
    return kept;
  }
  for (std::size_t a = 0; a < parts.size(); ++a)
    for (std::size_t b = a + 1; b < parts.size(); ++b)
      if (selection.selects(static_cast<Index>(a), static_cast<Index>(b)))
        kept.emplace_back(static_cast<Index>(a), static_cast<Index>(b));
  return kept;
}

}  // namespace phiq
