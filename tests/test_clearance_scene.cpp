// The scene's `output.clearance` (models/README.md, "Clearance"): pairs listed or all, less the adjacent ones the
// constraints join; the worst clearance's sensitivities against their closed forms, and every minimum's against
// finite differences of the whole sweep; and bad input refused in one line naming the file and the field.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// The four-bar in reference-point coordinates (O = (0, 0), C = (L1, 0)) with spheres: `pivot` at O on ground, `pin`
// at the rocker's end B, one on each link, and a `screw` head on ground far from every joint; `output` appended.
std::string clearance_scene_text(const std::string& output, int steps = 90) {
  return test::model_file_text("seed/fourbar_reference_point.yaml", "\ntime:") +
         "\ntime: {start: 0, end: 2*pi, steps: " + std::to_string(steps) +
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

// Central differences at L1, L2, L3 ± 1e-4 of what `measure` takes from the clearance of the scene `text` read
// there (its sweep and clearance pass solved again, without sensitivities).
template <class Measure>
std::array<double, 3> clearance_scene_differences(const std::string& text, Measure measure) {
  const char* names[] = {"L1", "L2", "L3"};
  const double values[] = {1.0, 0.4, 1.2}, h = 1e-4;
  std::array<double, 3> out{};
  for (std::size_t j = 0; j < 3; ++j) {
    double d[2];
    for (int side = 0; side < 2; ++side) {
      SceneOverrides o;
      o.parameters = {{names[j], values[j] + (side ? h : -h)}};
      o.sensitivity_models = false;
      Scene moved = parse_scene(text, "c.yaml", {}, o);
      moved.sweep.sensitivities.clear();
      d[side] = measure(scene_clearance(moved));
    }
    out[j] = (d[1] - d[0]) / (2 * h);
  }
  return out;
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
  const std::array<double, 3> fd =
      clearance_scene_differences(text, [](const ClearanceReport& moved) { return moved.pairs[0].worst.at.distance; });
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(fd[k], w.sensitivities[k], 1e-6) << "L" << k + 1;
}

// Every minimum carries its own sensitivities, not only the worst: the coupler's sphere against a ground part of
// two screw heads comes nearest the one at (1.2, 0.8) (worst, t ≈ 0.59) and, later, the one at (0.5, −0.6) (a second
// refined minimum, t ≈ 4.89); that second minimum's ∂d/∂L against central differences of it (the pair's minimum
// nearest in time) in the sweeps and clearance passes re-solved at L ± h.
TEST(ClearanceScene, EveryMinimumsSensitivitiesMatchFiniteDifferences) {
  const std::string text = clearance_scene_text(
      "  screws: {body: ground, shapes: [{type: sphere, radius: 0.02, at: [0.5, -0.6]}, {type: sphere, radius: "
      "0.02, at: [1.2, 0.8]}]}\n"
      "output: {sensitivities: [L1, L2, L3], clearance: {pairs: [[coupler, screws]], threshold: 0.001}}\n");
  const Scene s = parse_scene(text, "c.yaml");
  const ClearanceReport r = scene_clearance(s);
  std::size_t pair = 0, minimum = 0;
  bool found = false;
  for (std::size_t i = 0; i < r.pairs.size() && !found; ++i)
    for (std::size_t k = 0; k < r.pairs[i].minima.size() && !found; ++k) {
      const ClearanceMinimum& m = r.pairs[i].minima[k];
      found = m.refined && m.t != r.pairs[i].worst.t;
      if (found) pair = i, minimum = k;
    }
  ASSERT_TRUE(found) << "no pair has a refined minimum besides its worst";
  const ClearanceMinimum& m = r.pairs[pair].minima[minimum];
  EXPECT_NEAR(m.t, 4.887, 1e-3);
  EXPECT_GT(m.at.distance, r.pairs[pair].worst.at.distance + 0.1);
  ASSERT_EQ(m.sensitivities.size(), 3u);
  double gap = 0.0;  // between m and the minimum it is compared with
  const std::array<double, 3> fd = clearance_scene_differences(text, [&](const ClearanceReport& moved) {
    const std::vector<ClearanceMinimum>& minima = moved.pairs.at(pair).minima;
    const auto nearest = std::min_element(minima.begin(), minima.end(), [&](const auto& x, const auto& y) {
      return std::abs(x.t - m.t) < std::abs(y.t - m.t);
    });
    if (nearest == minima.end()) return std::nan("");  // no minimum: the comparison fails
    gap = std::max(gap, std::abs(nearest->t - m.t));
    return nearest->at.distance;
  });
  EXPECT_LT(gap, 1e-3);
  double largest = 0.0;
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_NEAR(fd[k], m.sensitivities[k], 1e-6 * (1 + std::abs(m.sensitivities[k]))) << "L" << k + 1;
    largest = std::max(largest, std::abs(m.sensitivities[k]));
  }
  EXPECT_GT(largest, 0.05);  // the lengths move this minimum: the check is not of zeros
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
