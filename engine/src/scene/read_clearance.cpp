// `output.clearance` (scene_reader.hpp, models/README.md "Clearance"): the pairs of parts whose distance along the
// motion `phiq clearance` measures, which pairs to skip, and the clearance they must keep.
#include "scene/scene_reader.hpp"

namespace phiq::detail::scene {

namespace {

// The part named by the scalar `c`, which must carry a shape.
Index part_named(const Cursor& c, const std::vector<Part>& parts) {
  const std::string name = c.name();
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (parts[i].name != name) continue;
    if (parts[i].shapes.empty()) c.fail("part '" + name + "' has no shape to measure a clearance from");
    return static_cast<Index>(i);
  }
  c.fail("unknown part '" + name + "' (a named entry of `parts`)");
}

// [[A, B], …]: pairs of parts with shapes, each once.
std::vector<std::pair<Index, Index>> part_pairs(const Cursor& c, const std::vector<Part>& parts) {
  if (!c.is_sequence()) c.fail("a list of pairs of parts [[A, B], ...]");
  std::vector<std::pair<Index, Index>> out;
  for (const Cursor& item : c.items()) {
    if (!item.is_sequence() || item.size() != 2) item.fail("a pair of parts is [A, B]");
    const Index a = part_named(item.at(0), parts), b = part_named(item.at(1), parts);
    if (a == b) item.fail("a part is paired with itself");
    const std::pair<Index, Index> ab{std::min(a, b), std::max(a, b)};
    if (std::find(out.begin(), out.end(), ab) != out.end()) item.fail("pair listed twice");
    out.push_back(ab);
  }
  return out;
}

}  // namespace

void SceneReader::read_clearance(const Cursor& c, Scene& scene) const {
  if (!c.present()) return;
  if (!c.is_map())
    c.fail("clearance is a map {pairs: [[A, B], ...] | all, skip: adjacent | [[A, B], ...], threshold: D}");
  c.expect_map({"pairs", "skip", "threshold"});
  ClearancePlan& plan = scene.clearance;
  plan.requested = true;
  const Cursor pairs = c.require("pairs");
  if (pairs.is_scalar()) {
    if (pairs.text() != "all") pairs.fail("pairs is all or a list of pairs of parts [[A, B], ...]");
    plan.all = true;
  } else {
    plan.pairs = part_pairs(pairs, scene.parts);
  }
  if (auto s = c.field("skip"); s.present()) {
    if (s.is_scalar()) {
      if (s.text() != "adjacent") s.fail("skip is adjacent or a list of pairs of parts [[A, B], ...]");
      plan.skip_adjacent = true;
    } else {
      plan.skip = part_pairs(s, scene.parts);
    }
  }
  if (auto t = c.field("threshold"); t.present()) {
    plan.threshold = number(t);
    if (!(plan.threshold >= 0.0)) t.fail("the threshold is a distance (m), 0 or more");
  }
}

}  // namespace phiq::detail::scene
