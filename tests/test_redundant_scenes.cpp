// The redundant scenes of issue 3 through the engine's own path — minimum-norm assembly, rank analysis, the square
// solve on the independent rows (prepare_square) and the drive sweep — against closed forms, exact counts and the
// residual of every row, the left-out ones included. (tests/test_spatial_scenes.cpp checks the same scenes
// independently of the engine's solvers, with a dense SVD.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

using test::prepare;
using test::Prepared;
template <class Check>
void sweep(Prepared& p, Check check) {
  test::sweep_prepared(p, check);
}

TEST(RedundantScenes, CrankSlider3dHasGrublerMinusTwoMovesWithOneDofAndIsTheCrankSlider) {
  Prepared p = prepare("redundant/crank_slider_3d.yaml");
  ASSERT_EQ(p.assembly.status, SolveStatus::kSuccess) << p.assembly.BriefReport();
  const RankReport& r = p.assembly.rank;
  EXPECT_EQ(r.grubler, std::optional<Index>(-2));
  EXPECT_EQ(r.dof, 1);
  EXPECT_EQ(r.driven_dof, 0);
  EXPECT_EQ(r.redundant_rows.size(), 3u);  // 24 equations of rank 21
  EXPECT_TRUE(p.assembly.consistent);
  const Model& m = *p.scene.model;
  const Index xs = m.coordinate_index("slider_x"), ys = m.coordinate_index("slider_y"),
              zs = m.coordinate_index("slider_z");
  const double L2 = 0.3, L3 = 1.0;
  sweep(p, [&](const StepView& s) {
    // θ = 2t; x_B = L2 cos θ + √(L3² − L2² sin² θ); its rates by differentiation
    const double th = 2.0 * s.t, w = 2.0, sn = std::sin(th), cs = std::cos(th);
    const double root = std::sqrt(L3 * L3 - L2 * L2 * sn * sn);
    const double x = L2 * cs + root;
    const double dx_dth = -L2 * sn - L2 * L2 * sn * cs / root;
    const double d2x_dth2 =
        -L2 * cs - L2 * L2 * (cs * cs - sn * sn) / root - L2 * L2 * L2 * L2 * sn * sn * cs * cs / (root * root * root);
    EXPECT_NEAR(s.q(xs), x, 1e-9) << s.t;
    EXPECT_NEAR(s.q(ys), 0.0, 1e-9);
    EXPECT_NEAR(s.q(zs), 0.0, 1e-9);
    EXPECT_NEAR((*s.qd)(xs), w * dx_dth, 1e-8) << s.t;
    EXPECT_NEAR((*s.qdd)(xs), w * w * d2x_dth2, 1e-7) << s.t;
  });
}

TEST(RedundantScenes, DoorOnThreeHingesTurnsWithOneDofAndItsRedundantHingesListed) {
  Prepared p = prepare("redundant/door_three_hinges.yaml");
  ASSERT_EQ(p.assembly.status, SolveStatus::kSuccess) << p.assembly.BriefReport();
  const RankReport& r = p.assembly.rank;
  EXPECT_EQ(r.coordinates, 7);
  EXPECT_EQ(r.dof, 1);
  EXPECT_EQ(r.grubler, std::optional<Index>(-9));
  EXPECT_EQ(r.rank, 6);
  EXPECT_EQ(r.kinematic_equations, 16);  // 3 hinges × 5 + the Euler normalisation
  EXPECT_EQ(r.redundant_rows.size(), 10u);
  EXPECT_TRUE(test::contains(r.redundant, "hinge2"));
  EXPECT_TRUE(test::contains(r.redundant, "hinge3"));
  EXPECT_FALSE(test::contains(r.redundant, "hinge1"));  // greedy in scene order: the first hinge is kept whole
  // the door turns about z with the driver: e = (cos(φ/2), 0, 0, sin(φ/2)), φ = t
  const Model& m = *p.scene.model;
  const Index e0 = m.coordinate_index("door_e0"), e3 = m.coordinate_index("door_e3");
  sweep(p, [&](const StepView& s) { EXPECT_NEAR(std::atan2(s.q(e3), s.q(e0)) * 2.0, s.t, 1e-9) << s.t; });
}

TEST(RedundantScenes, MisalignedDoorIsInconsistentWithTheThirdHingeAmongTheConflicts) {
  Prepared p = prepare("redundant/door_misaligned.yaml");
  EXPECT_EQ(p.assembly.status, SolveStatus::kInconsistent) << p.assembly.BriefReport();
  EXPECT_FALSE(p.assembly.consistent);
  EXPECT_TRUE(test::contains(p.assembly.conflicts, "hinge3"));
  EXPECT_EQ(p.solved, nullptr);
  EXPECT_NE(p.assembly.message.find("hinge3"), std::string::npos) << p.assembly.message;
}

TEST(RedundantScenes, RedundantDriversThatPartAfterTheStartAreNamedAsInconsistent) {
  // Two drivers of the door's hinge at rates 1 and 1.001 agree at t = 0, where the model is assembled and the
  // second is left out as consistent; at the first step it no longer holds while the others do. That was reported
  // as "no assembly beyond t = 0 … the drive leaves the reachable range, or the mechanism passes a singular
  // position"; it is the redundant constraints' inconsistency, named, with the kInconsistent status.
  for (const std::string& extra :
       {std::string("  - {name: open2, joint: hinge1, law: {type: linear, initial: 0, rate: 1.001}}\n"),
        std::string("  - {name: open2, joint: hinge1, law: {type: linear, initial: 0, rate: -1}}\n")}) {
    std::ifstream in(test::model_path("redundant/door_three_hinges.yaml"));
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t at = text.find("time:");
    ASSERT_NE(at, std::string::npos);
    text.insert(at, extra);
    Scene sc = parse_scene(text, "door_two_drivers.yaml");
    SquareScene square;
    ASSERT_EQ(prepare_scene(*sc.model, sc.sweep.t_begin, sc.sweep.assembly, &square), SolveStatus::kSuccess)
        << square.assembly.message;
    const Model& m = square.model(*sc.model);
    Workspace ws(m);
    ws.q = square.start;
    SweepSummary sum;
    EXPECT_EQ(run_sweep(m, sc.sweep, ws, nullptr, &sum), SolveStatus::kInconsistent) << sum.message;
    EXPECT_EQ(sum.failed_step, 1);
    EXPECT_HAS(sum.message, "stop holding where the others hold ('open2'): the redundant constraints are inconsistent");
    EXPECT_EQ(sum.message.find("reachable range"), std::string::npos) << sum.message;
  }
}

TEST(RedundantScenes, BricardHasGrublerZeroOneDofOneRedundantEquationAndIsDrivenAtTolerance) {
  Prepared p = prepare("benchmarks/bricard.yaml");
  ASSERT_EQ(p.assembly.status, SolveStatus::kSuccess) << p.assembly.BriefReport();
  const RankReport& r = p.assembly.rank;
  EXPECT_EQ(r.grubler, std::optional<Index>(0));
  EXPECT_EQ(r.dof, 1);
  EXPECT_EQ(r.redundant_rows.size(), 1u);
  EXPECT_EQ(r.driven_dof, 0);
  EXPECT_FALSE(r.uncertain) << r.message;
  // The square configuration is exact at t = 0: the assembly does not move it.
  EXPECT_LE(p.assembly.moved, 1e-12);
  // Driven through 1 rad of J1; velocities equal the central differences of the positions (an independent check
  // of the velocity solve through the left-out row).
  Eigen::VectorXd prev, prev_qd;
  double prev_t = 0.0;
  sweep(p, [&](const StepView& s) {
    if (prev.size()) {
      const double h = s.t - prev_t;
      const Eigen::VectorXd fd = (s.q - prev) / h, mid = 0.5 * (*s.qd + prev_qd);
      EXPECT_LE((fd - mid).cwiseAbs().maxCoeff(), 1e-3) << s.t;  // O(h²) with h = 0.02
    }
    prev = s.q, prev_qd = *s.qd, prev_t = s.t;
  });
}

}  // namespace
}  // namespace phiq
