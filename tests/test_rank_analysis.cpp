// Rank and redundancy (engine/include/phiq/rank_analysis.hpp): exact counts and names on mechanisms whose
// redundancy is known from geometry, per configuration, independent of units, with the near-miss reported.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// The exact position of models/redundant/parallelogram_fifth_bar.yaml at crank angle th: every crank frame at its
// pivot with psi = th, the coupler's left end at the first crank's tip, psi = 0.
Eigen::VectorXd fifth_bar_exact(const Model& m, double th, double r = 1.0, double d = 1.0) {
  Eigen::VectorXd q(m.num_coordinates());
  auto set = [&](const char* n, double v) { q(m.coordinate_index(n)) = v; };
  for (int i = 1; i <= 3; ++i) {
    const std::string k = std::to_string(i);
    set(("x" + k).c_str(), (i - 1) * d);
    set(("y" + k).c_str(), 0.0);
    set(("psi" + k).c_str(), th);
  }
  set("xc", r * std::cos(th));
  set("yc", r * std::sin(th));
  set("psic", 0.0);
  return q;
}

Scene fifth_bar() { return load_scene(test::model_path("redundant/parallelogram_fifth_bar.yaml")); }

TEST(RankAnalysis, ParallelogramWithFifthBarHasOneRedundantEquationAndOneDof) {
  Scene sc = fifth_bar();
  const Model& m = *sc.model;
  const RankReport r = analyse_rank(m, fifth_bar_exact(m, M_PI / 3), 0.0);
  EXPECT_EQ(r.coordinates, 12);
  EXPECT_EQ(r.equations, 13);
  EXPECT_EQ(r.kinematic_equations, 12);
  EXPECT_EQ(r.driver_equations, 1);
  EXPECT_EQ(r.rank, 11);
  EXPECT_EQ(r.dof, 1);
  EXPECT_EQ(r.driven_rank, 12);
  EXPECT_EQ(r.driven_dof, 0);
  // Greedy in model order: A3's x row still fixes crank 3's angle; its y row is what the parallelogram implies.
  ASSERT_EQ(r.redundant_rows.size(), 1u);
  EXPECT_EQ(m.row_name(r.redundant_rows[0]), "A3[1]");
  EXPECT_EQ(r.redundant, std::vector<std::string>{"A3"});
  EXPECT_EQ(r.independent_rows.size(), 12u);
  EXPECT_TRUE(r.dense_checked);
  EXPECT_EQ(r.dense_rank, 12);
  EXPECT_FALSE(r.uncertain) << r.message;
  // The redundant row is a combination of the independent rows (to rounding), which the fit confirms.
  const auto c = combinations_of(m, fifth_bar_exact(m, M_PI / 3), 0.0, r.independent_rows, r.redundant_rows);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_LT(c[0].fit_residual, 1e-12);
  EXPECT_FALSE(c[0].basis.empty());
}

TEST(RankAnalysis, RedundancyHoldsAlongTheMotionButNotOffIt) {
  Scene sc = fifth_bar();
  const Model& m = *sc.model;
  for (double th : {0.3, 1.0, 2.0, 2.8}) {
    const RankReport r = analyse_rank(m, fifth_bar_exact(m, th), 0.0);
    EXPECT_EQ(r.rank, 11) << th;
    EXPECT_EQ(r.dof, 1) << th;
  }
  // Off the mechanism's motion (crank 3 turned by 0.3 rad) the same equations are independent: rank is a property of
  // the configuration.
  Eigen::VectorXd q = fifth_bar_exact(m, 1.0);
  q(m.coordinate_index("psi3")) += 0.3;
  const RankReport off = analyse_rank(m, q, 0.0);
  EXPECT_EQ(off.rank, 12);
  EXPECT_EQ(off.dof, 0);
  EXPECT_EQ(off.driven_rank, 12);
  EXPECT_EQ(off.redundant_rows.size(), 1u);  // now the driver: the 12 kinematic rows fix everything
  EXPECT_EQ(off.redundant, std::vector<std::string>{"motor"});
}

// A planar four-bar whose rank drops at one configuration only: the parallelogram at its flat (change) point.
const char* kParallelogram = R"(
phiq: 1
coordinates: {x1: 0, y1: 0, psi1: 1, x2: 1, y2: 0, psi2: 1, xc: 0.5, yc: 0.8, psic: 0}
bodies: {crank1: [x1, y1, psi1], crank2: [x2, y2, psi2], coupler: [xc, yc, psic]}
constraints:
  - {name: O1, type: revolute, between: [{body: crank1, at: [0, 0]}, {body: ground, at: [0, 0]}]}
  - {name: O2, type: revolute, between: [{body: crank2, at: [0, 0]}, {body: ground, at: [L, 0]}]}
  - {name: A1, type: revolute, between: [{body: crank1, at: [R, 0]}, {body: coupler, at: [0, 0]}]}
  - {name: A2, type: revolute, between: [{body: crank2, at: [R, 0]}, {body: coupler, at: [L, 0]}]}
drivers:
  - {name: motor, coordinate: psi1, law: {type: linear, initial: 0, rate: 1}}
time: {start: 0, end: 1, steps: 10}
)";

Scene parallelogram(double unit) {
  // the same mechanism in metres (unit 1) or millimetres (unit 1000): lengths scale, angles do not
  std::string text =
      "parameters: {L: " + std::to_string(unit) + ", R: " + std::to_string(unit) + "}\n" + kParallelogram;
  Scene sc = parse_scene(text, "parallelogram.yaml");
  return sc;
}

Eigen::VectorXd parallelogram_at(const Model& m, double th, double unit) {
  Eigen::VectorXd q(m.num_coordinates());
  q << 0, 0, th, unit, 0, th, unit * std::cos(th), unit * std::sin(th), 0;
  return q;
}

TEST(RankAnalysis, RankDropsOnlyAtTheChangePointWhateverTheUnits) {
  for (double unit : {1.0, 1000.0}) {
    Scene sc = parallelogram(unit);
    const Model& m = *sc.model;
    const RankReport general = analyse_rank(m, parallelogram_at(m, 1.0, unit), 0.0);
    EXPECT_EQ(general.rank, 8) << unit;
    EXPECT_EQ(general.dof, 1) << unit;
    EXPECT_TRUE(general.redundant_rows.empty()) << unit;
    EXPECT_FALSE(general.uncertain) << general.message;
    // Flat: cranks and coupler on the x axis. Both cranks' vertical motion is one constraint too few: the
    // kinematic rank drops to 7 (2 freedoms): with every link horizontal the x rows fix x only, and A2's x row is O2 +
    // A1 − O1.
    const RankReport flat = analyse_rank(m, parallelogram_at(m, 0.0, unit), 0.0);
    EXPECT_EQ(flat.rank, 7) << unit;
    EXPECT_EQ(flat.dof, 2) << unit;
    EXPECT_EQ(flat.driven_dof, 1) << unit;
    ASSERT_EQ(flat.redundant_rows.size(), 1u) << unit;
    EXPECT_EQ(m.row_name(flat.redundant_rows[0]), "A2[0]") << unit;
    EXPECT_EQ(flat.dense_rank, 8) << unit;
  }
}

// Two equations x + y = 0 and x + (1 + e) y = 0: dependent for e = 0, numerically dependent for tiny e, clearly
// independent for large e, and a near miss in between (reported, not guessed).
RankReport two_lines(double e) {
  char text[512];
  std::snprintf(text, sizeof text,
                "phiq: 1\ncoordinates: {x: 0, y: 0}\nconstraints:\n"
                "  - {name: first, type: equation, expr: \"x + y\"}\n"
                "  - {name: second, type: equation, expr: \"x + (1 + %.17g) * y\"}\n"
                "time: {start: 0, end: 0, steps: 0}\n",
                e);
  const Scene sc = parse_scene(text, "two_lines.yaml");
  return analyse_rank(*sc.model, Eigen::VectorXd::Zero(2), 0.0);
}

TEST(RankAnalysis, NearDependenceIsToldApartOrReportedUncertain) {
  const RankReport exact = two_lines(1e-14);
  EXPECT_EQ(exact.rank, 1);
  EXPECT_EQ(exact.redundant, std::vector<std::string>{"second"});
  EXPECT_FALSE(exact.uncertain) << exact.message;
  const RankReport clear = two_lines(1e-2);
  EXPECT_EQ(clear.rank, 2);
  EXPECT_FALSE(clear.uncertain) << clear.message;
  const RankReport near = two_lines(1e-7);  // within 100× of the tolerance 1e-8
  EXPECT_TRUE(near.uncertain);
  EXPECT_NE(near.message.find("tolerance"), std::string::npos) << near.message;
}

}  // namespace
}  // namespace phiq
