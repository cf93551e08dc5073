// The scene's `output.clearance` (models/README.md, "Clearance"): pairs listed or all, less the adjacent ones the
// constraints join; the worst clearance's sensitivities against their closed forms and against finite differences
// of the whole sweep; and bad input refused in one line naming the file and the field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// The four-bar in reference-point coordinates (O = (0, 0), C = (L1, 0)) with spheres: `pivot` at O on ground, `pin`
// at the rocker's end B, one on each link, and a `screw` head on ground far from every joint; `output` appended.
std::string clearance_scene_text(const std::string& output, int steps = 90) {
  std::ifstream in(test::model_path("seed/fourbar_reference_point.yaml"));
  std::stringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  text = text.substr(0, text.find("\ntime:"));
  return text + "\ntime: {start: 0, end: 2*pi, steps: " + std::to_string(steps) +
         "}\n"
         "parts:\n"
         "  pivot: {body: ground, shapes: [{type: sphere, radius: 0.02}]}\n"
         "  screw: {body: ground, shapes: [{type: sphere, radius: 0.02, at: [0.5, -0.6]}]}\n"
         "  crank: {shapes: [{type: sphere, radius: 0.01}]}\n"
         "  coupler: {shapes: [{type: sphere, radius: 0.01}]}\n"
         "  pin: {body: rocker, shapes: [{type: sphere, radius: 0.03, at: [0.5, 0]}]}\n"
         "  bare: {body: coupler}\n" +
         output;
}

std::string clearance_pair_names(const Scene& s, std::pair<Index, Index> ab) {
  return s.parts[static_cast<std::size_t>(ab.first)].name + "-" + s.parts[static_cast<std::size_t>(ab.second)].name;
}

// Adjacent: the links joined by revolutes (crank-coupler, coupler-pin: the rocker's part), the crank and the ground
// part that holds its pivot O; not the screw head, which holds no joint, nor the crank and the rocker.
TEST(ClearanceScene, AdjacentPartsAreThoseTheJointsJoin) {
  const Scene s = parse_scene(clearance_scene_text("output: {clearance: {pairs: all, skip: adjacent}}\n"), "c.yaml");
  std::vector<std::string> adjacent;
  for (const auto& ab : adjacent_parts(*s.model, s.parts)) adjacent.push_back(clearance_pair_names(s, ab));
  std::sort(adjacent.begin(), adjacent.end());
  // `bare` is on the coupler: adjacent to it, and to what it is jointed to
  const std::vector<std::string> expected{"coupler-bare",  "coupler-pin", "crank-bare",
                                          "crank-coupler", "pin-bare",    "pivot-crank"};
  EXPECT_EQ(adjacent, expected);
  // all pairs with shapes: 5 parts, 10 pairs, less pivot-screw (both fixed) and the 3 adjacent with shapes
  const auto pairs = clearance_pairs(*s.model, s.parts, s.clearance);
  std::vector<std::string> names;
  for (const auto& ab : pairs) names.push_back(clearance_pair_names(s, ab));
  EXPECT_EQ(pairs.size(), 6u);
  EXPECT_TRUE(test::contains(names, "screw-crank"));
  EXPECT_FALSE(test::contains(names, "pivot-screw"));
}

// The pivot O against the rocker pin B: d_min = L3 − L2 − 0.05 whatever L1 (law of cosines; the crank folded onto
// the coupler), so ∂d/∂L2 = −1, ∂d/∂L3 = 1, ∂d/∂L1 = 0; and the same against central differences of the whole
// sweep and clearance pass at L ± h.
TEST(ClearanceScene, WorstClearanceSensitivitiesMatchClosedFormsAndFiniteDifferences) {
  const std::string text = clearance_scene_text(
      "output: {sensitivities: [L1, L2, L3], clearance: {pairs: [[pivot, pin]], threshold: 0.001}}\n");
  const Scene s = parse_scene(text, "c.yaml");
  const ClearanceReport r = scene_clearance(s);
  ASSERT_EQ(r.pairs.size(), 1u);
  const ClearanceMinimum& w = r.pairs[0].worst;
  ASSERT_EQ(w.sensitivities.size(), 3u);
  EXPECT_NEAR(w.at.distance, 1.2 - 0.4 - 0.05, 1e-10);
  EXPECT_NEAR(w.sensitivities[0], 0.0, 1e-7);
  EXPECT_NEAR(w.sensitivities[1], -1.0, 1e-7);
  EXPECT_NEAR(w.sensitivities[2], 1.0, 1e-7);
  const char* names[] = {"L1", "L2", "L3"};
  const double values[] = {1.0, 0.4, 1.2};
  for (int j = 0; j < 3; ++j) {
    const double h = 1e-4;
    double d[2];
    for (int side = 0; side < 2; ++side) {
      SceneOverrides o;
      o.parameters = {{names[j], values[j] + (side ? h : -h)}};
      o.sensitivity_models = false;
      Scene moved = parse_scene(text, "c.yaml", {}, o);
      moved.sweep.sensitivities.clear();
      d[side] = scene_clearance(moved).pairs[0].worst.at.distance;
    }
    EXPECT_NEAR((d[1] - d[0]) / (2 * h), w.sensitivities[static_cast<std::size_t>(j)], 1e-6) << names[j];
  }
}

TEST(ClearanceScene, BadInputIsOneLineNamingTheField) {
  auto error = [](const std::string& clearance) {
    return test::scene_error(clearance_scene_text("output: {clearance: " + clearance + "}\n"));
  };
  std::string m = error("{pairs: [[pivot, nowhere]]}");
  EXPECT_HAS(m, "output.clearance.pairs[0][1]");
  EXPECT_HAS(m, "unknown part 'nowhere'");
  m = error("{pairs: [[pivot, bare]]}");
  EXPECT_HAS(m, "output.clearance.pairs[0][1]");
  EXPECT_HAS(m, "part 'bare' has no shape");
  m = error("{pairs: all, threshold: -0.001}");
  EXPECT_HAS(m, "output.clearance.threshold");
  EXPECT_HAS(m, "0 or more");
  m = error("{pairs: every}");
  EXPECT_HAS(m, "output.clearance.pairs");
  m = error("{pairs: all, skip: [[crank, crank]]}");
  EXPECT_HAS(m, "output.clearance.skip[0]");
  EXPECT_HAS(m, "paired with itself");
}

}  // namespace
}  // namespace phiq
