// The minimum-norm assembly and the square solve through redundancy (engine/include/phiq/assembly.hpp): closed-form
// positions, the nearest-point property, consistent against inconsistent redundancy, and sweeps that stay exact.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <Eigen/Dense>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

TEST(Assembly, FifthBarAssemblesDropsItsRedundantRowAndSweepsExactly) {
  test::Prepared p = test::prepare("redundant/parallelogram_fifth_bar.yaml");
  const Model& full = *p.scene.model;
  const AssemblySummary& as = p.assembly;
  ASSERT_EQ(as.status, SolveStatus::kSuccess) << as.BriefReport();
  EXPECT_TRUE(as.consistent);
  EXPECT_TRUE(as.conflicts.empty());
  EXPECT_EQ(as.rank.dof, 1);
  EXPECT_EQ(as.rank.redundant, std::vector<std::string>{"A3"});
  ASSERT_EQ(p.solved->dropped_rows().size(), 1u);
  EXPECT_EQ(full.row_name(p.solved->dropped_rows()[0]), "A3[1]");
  ASSERT_NE(p.solved->symbolic(), nullptr);  // 12 kept rows for 12 coordinates: square
  const double th0 = M_PI / 3;
  const Eigen::VectorXd& q = p.q;
  EXPECT_NEAR(q(full.coordinate_index("psi3")), th0, 1e-9);
  EXPECT_NEAR(q(full.coordinate_index("xc")), std::cos(th0), 1e-9);
  EXPECT_NEAR(q(full.coordinate_index("yc")), std::sin(th0), 1e-9);
  EXPECT_NEAR(q(full.coordinate_index("psic")), 0.0, 1e-9);
  EXPECT_EQ(p.scene.sweep.steps + 1, 101);

  // The sweep on the kept rows: every crank at th0 + t, the coupler translating on a unit circle; the left-out
  // row holds at every step (consistent redundancy: sweep_prepared checks every row of the full model), and
  // velocities and accelerations are exact.
  test::sweep_prepared(p, [&](const StepView& s) {
    const double th = th0 + s.t;
    EXPECT_NEAR(s.q(full.coordinate_index("psi2")), th, 1e-9);
    EXPECT_NEAR(s.q(full.coordinate_index("psi3")), th, 1e-9);
    EXPECT_NEAR(s.q(full.coordinate_index("xc")), std::cos(th), 1e-9);
    EXPECT_NEAR((*s.qd)(full.coordinate_index("psi3")), 1.0, 1e-8);
    EXPECT_NEAR((*s.qd)(full.coordinate_index("xc")), -std::sin(th), 1e-8);
    EXPECT_NEAR((*s.qd)(full.coordinate_index("yc")), std::cos(th), 1e-8);
    EXPECT_NEAR((*s.qdd)(full.coordinate_index("xc")), -std::cos(th), 1e-7);
    EXPECT_NEAR((*s.qdd)(full.coordinate_index("yc")), -std::sin(th), 1e-7);
    EXPECT_NEAR((*s.qdd)(full.coordinate_index("psi3")), 0.0, 1e-7);
  });
}

// A planar door: one body pinned to ground twice at its hinge. With both ground points equal, the second pin is
// consistent redundancy; displaced by 1e-12 it is still consistent within the tolerance; by 1e-3 the model is
// inconsistent and both pins are named.
Scene planar_door(double offset) {
  char text[1024];
  std::snprintf(text, sizeof text, R"(phiq: 1
coordinates: {x: 0.01, y: -0.02, psi: 0.1}
bodies: {door: [x, y, psi]}
constraints:
  - {name: pin1, type: revolute, between: [{body: door, at: [0, 0]}, {body: ground, at: [0, 0]}]}
  - {name: pin2, type: revolute, between: [{body: door, at: [0, 0]}, {body: ground, at: [%.17g, 0]}]}
  - {name: tip, type: equation, expr: "0*x"}
drivers:
  - {name: motor, coordinate: psi, law: {type: linear, initial: 0.2, rate: 1}}
time: {start: 0, end: 1, steps: 10}
)",
                offset);
  return parse_scene(text, "planar_door.yaml");
}

TEST(Assembly, ConsistentAndInconsistentRedundancyAreToldApart) {
  for (double offset : {0.0, 1e-12}) {
    Scene sc = planar_door(offset);
    Eigen::VectorXd q = sc.model->initial_positions();
    AssemblySummary as;
    EXPECT_EQ(assemble(*sc.model, 0.0, {}, q, &as), SolveStatus::kSuccess) << offset << ": " << as.BriefReport();
    EXPECT_TRUE(as.consistent) << offset;
    EXPECT_EQ(as.rank.dof, 1) << offset;  // 3 coordinates, rank 2 (the zero equation adds nothing)
    EXPECT_TRUE(test::contains(as.rank.redundant, "pin2")) << offset;
    EXPECT_TRUE(test::contains(as.rank.redundant, "tip")) << offset;  // 0 = 0: always redundant, always consistent
    EXPECT_NEAR(q(2), 0.2, 1e-10);
    EXPECT_LE(std::hypot(q(0), q(1)), 1e-10);
  }
  Scene sc = planar_door(1e-3);
  Eigen::VectorXd q = sc.model->initial_positions();
  AssemblySummary as;
  ASSERT_EQ(assemble(*sc.model, 0.0, {}, q, &as), SolveStatus::kInconsistent) << as.BriefReport();
  EXPECT_FALSE(as.consistent);
  EXPECT_TRUE(test::contains(as.conflicts, "pin1"));
  EXPECT_TRUE(test::contains(as.conflicts, "pin2"));
  EXPECT_FALSE(test::contains(as.conflicts, "motor"));  // the driver is independent of the pins' conflict
  EXPECT_FALSE(test::contains(as.conflicts, "tip"));
  EXPECT_NE(as.message.find("pin2"), std::string::npos) << as.message;
  std::unique_ptr<Model> solved;
  q = sc.model->initial_positions();
  EXPECT_EQ(prepare_square(*sc.model, 0.0, {}, q, &solved, &as), SolveStatus::kInconsistent);
  EXPECT_EQ(solved, nullptr);
}

// An under-driven four-bar (no motor): the assembly lands on the position of Φ = 0 nearest to the rough placement,
// in the scaled norm: q₀ − q is orthogonal to the mechanism's motion (in range(D² Φqᵀ)).
TEST(Assembly, UnderDrivenPlacementMovesToTheNearestAssembledPosition) {
  Scene sc = load_scene(test::model_path("seed/fourbar_natural.yaml"));
  // drop the motor: the same mechanism with one free dof
  const Model& driven = *sc.model;
  std::vector<Index> motor_rows;
  for (const auto& c : driven.constraints())
    if (c.depends_on_time)
      for (int r = 0; r < c.rows; ++r) motor_rows.push_back(c.first_row + r);
  ASSERT_EQ(motor_rows.size(), 1u);
  // Assemble the full model from a placement that contradicts nothing but the closure: with the motor
  // left out of the solve through a model that has no motor row at all.
  std::string text;
  {
    std::FILE* f = std::fopen(test::model_path("seed/fourbar_natural.yaml").c_str(), "r");
    ASSERT_NE(f, nullptr);
    char buf[4096];
    std::size_t k;
    while ((k = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, k);
    std::fclose(f);
  }
  const std::size_t d = text.find("drivers:");
  ASSERT_NE(d, std::string::npos);
  const std::size_t end = text.find("\ntime:", d);
  text.erase(d, end + 1 - d);
  Scene free_sc = parse_scene(text, "fourbar_free.yaml");
  const Model& m = *free_sc.model;
  Eigen::VectorXd q0 = m.initial_positions(), q = q0;
  AssemblySummary as;
  ASSERT_EQ(assemble(m, 0.0, {}, q, &as), SolveStatus::kSuccess) << as.BriefReport();
  EXPECT_EQ(as.rank.dof, 1);  // the four-bar's own freedom, undriven
  Eigen::VectorXd phi(m.num_equations());
  m.residual(q.data(), 0.0, phi.data());
  EXPECT_LE(scaled_residual(m, phi), 1e-10);
  // Dense check of the optimality condition: the part of D⁻¹(q₀ − q) outside range(J̃ᵀ) vanishes.
  CscPattern p;
  std::vector<double> v;
  std::vector<Index> all(static_cast<std::size_t>(m.num_equations()));
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<Index>(i);
  scaled_jacobian_rows(m, q, 0.0, all, &p, &v);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(p.rows, p.cols);
  for (Index j = 0; j < p.cols; ++j)
    for (Index e = p.col_ptr[j]; e < p.col_ptr[j + 1]; ++e) J(p.row_idx[e], j) = v[static_cast<std::size_t>(e)];
  const Eigen::VectorXd w = (q0 - q).cwiseQuotient(m.tolerance_scales().coordinate_scale);
  ASSERT_GT(w.norm(), 1e-3);  // the placement really moved
  const Eigen::VectorXd in_range = J.transpose() * J.transpose().colPivHouseholderQr().solve(w);
  EXPECT_LE((w - in_range).norm(), 1e-8 * w.norm());
}

TEST(Assembly, ImpossibleGeometryIsNotAssembledAndNamesTheConstraints) {
  // A four-bar whose coupler is too long to close (crank 0.4 + coupler 3 > ground 1 + rocker 1): no assembly.
  Scene sc = parse_scene(R"(phiq: 1
coordinates: {xA: 0.3, yA: 0.3, xB: 1.5, yB: 0.5}
points: {O: [0, 0], A: [xA, yA], B: [xB, yB], C: [1, 0]}
constraints:
  - {name: crank, type: distance, points: [O, A], length: 0.4}
  - {name: coupler, type: distance, points: [A, B], length: 3}
  - {name: rocker, type: distance, points: [C, B], length: 1}
time: {start: 0, end: 0, steps: 0}
)",
                         "impossible.yaml");
  Eigen::VectorXd q = sc.model->initial_positions();
  AssemblySummary as;
  const SolveStatus st = assemble(*sc.model, 0.0, {}, q, &as);
  EXPECT_NE(st, SolveStatus::kSuccess);
  EXPECT_GT(as.residual, 0.01);  // 1.6 m are missing, spread over the three links (length scale 3 m)
  EXPECT_NE(as.message.find("coupler"), std::string::npos) << as.message;
}

TEST(Assembly, ALockedStructureWithoutAPositionIsNotCalledConsistent) {
  // The fifth-bar parallelogram with its third crank 10 % long: the twelve revolute equations (Grübler 0, rank 12)
  // have no common solution, and the driver is redundant with them. The assembly was reported "consistent" with
  // the driver named as the worst constraint; now it says the independent equations have no solution, names the
  // worst among them, and claims nothing about consistency.
  std::ifstream in(test::model_path("redundant/parallelogram_fifth_bar.yaml"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text = test::replace_first(text, "{body: crank3, at: [r, 0]}", "{body: crank3, at: [1.1*r, 0]}");
  Scene sc = parse_scene(text, "fifth_bar_long.yaml");
  Eigen::VectorXd q = sc.model->initial_positions();
  AssemblySummary as;
  EXPECT_EQ(assemble(*sc.model, 0.0, {}, q, &as), SolveStatus::kNotConverged);
  EXPECT_FALSE(as.consistent);
  EXPECT_TRUE(as.conflicts.empty());
  EXPECT_HAS(as.message, "the independent equations have no common solution near this placement");
  ASSERT_FALSE(as.worst_rows.empty());
  for (const auto& [row, residual] : as.worst_rows) EXPECT_NE(sc.model->row_name(row), "motor") << as.message;
}

// (x − 1)³ = 0 (y fixed by its own row): its Jacobian vanishes at the root, where Gauss-Newton converges linearly.
// The all-rows phase crawled there under its μ floor (1e-10, above 9 (x − 1)⁴) and spent the 100 iterations at
// 1.7e-10, which was called "no common solution"; it now hands over to the kept rows' Gauss-Newton, which assembles.
// A budget too short for that says the residual was still falling, naming the setting, and claims no inconsistency.
TEST(Assembly, AMultipleRootAssemblesAndAShortBudgetSaysTheResidualStillFell) {
  const Scene sc = parse_scene(
      "phiq: 1\ncoordinates: {x: 0.5, y: 1.0}\nconstraints:\n"
      "  - {name: triple, type: equation, expr: \"(x - 1)^3\"}\n"
      "  - {name: level, type: equation, expr: \"y - 2\"}\ntime: {start: 0, end: 0, steps: 0}\n",
      "triple.yaml");
  const Model& m = *sc.model;
  Eigen::VectorXd q = m.initial_positions();
  AssemblySummary as;
  ASSERT_EQ(assemble(m, 0.0, {}, q, &as), SolveStatus::kSuccess) << as.message;
  EXPECT_LT(as.iterations, 100);
  EXPECT_NEAR(q(m.coordinate_index("x")), 1.0, 1e-6);
  EXPECT_EQ(q(m.coordinate_index("y")), 2.0);
  AssemblyOptions shorter;
  shorter.max_iterations = 12;
  q = m.initial_positions();
  EXPECT_EQ(assemble(m, 0.0, shorter, q, &as), SolveStatus::kNotConverged);
  EXPECT_HAS(as.message, "did not reach the tolerance in 12 iterations, their residual still falling");
  EXPECT_HAS(as.message, "solver.assembly_max_iterations");
  EXPECT_TRUE(as.consistent);
}

// A time that is not finite is outside every time domain, said so without a driver's name (there is none to blame)
// and without worst constraints (Φ means nothing there).
TEST(Assembly, NonFiniteTimesAreOutsideTheTimeDomain) {
  const Scene scene = load_scene(test::model_path("seed/fourbar_natural.yaml"));
  for (double t : {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    Eigen::VectorXd q = scene.model->initial_positions();
    AssemblySummary as;
    EXPECT_EQ(assemble(*scene.model, t, assembly_options(scene.sweep.assembly), q, &as),
              SolveStatus::kOutsideTimeDomain);
    EXPECT_EQ(as.message, "t = " + format_time(t) + " is not a finite time");
    EXPECT_TRUE(as.worst_rows.empty());
  }
}

}  // namespace
}  // namespace phiq
