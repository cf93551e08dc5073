// solve_velocity / solve_acceleration check that q solves the position problem (DerivativeOptions::tolerance):
// kPositionNotSolved with the worst constraint named where it does not, no Φ evaluation where the workspace knows
// q is solve_position's solution, one otherwise, and the same bits as an unchecked solve where it does.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

TEST(Derivatives, UnsolvedPositionIsAFailureNamingTheWorstConstraint) {
  const Model m = test::crank_slider_model(2.0, 0.0);
  Workspace ws(m);  // q: the rough placement, not a solution
  // the worst row, as the test measures it (|Φ_i| / scale_i)
  Eigen::VectorXd phi(m.num_equations());
  m.residual(ws.q.data(), 0.5, phi.data());
  Index worst = 0;
  for (Index i = 0; i < phi.size(); ++i)
    if (std::fabs(phi(i)) / m.tolerance_scales().row_scale(i) >
        std::fabs(phi(worst)) / m.tolerance_scales().row_scale(worst))
      worst = i;
  ASSERT_GT(std::fabs(phi(worst)) / m.tolerance_scales().row_scale(worst), 1e-3);

  const WorkCounters before = ws.counters;
  LinearSummary ls;
  EXPECT_EQ(solve_velocity(m, 0.5, ws, &ls), SolveStatus::kPositionNotSolved);
  EXPECT_EQ(ls.status, SolveStatus::kPositionNotSolved);
  EXPECT_EQ(
      ls.message.rfind(
          "q does not solve the position problem at t = 0.5: constraint '" + m.row_name(worst) + "' residual ", 0),
      0u)
      << ls.message;
  EXPECT_HAS(ls.message, "> tolerance 1e-10");
  EXPECT_EQ(ls.message.find('\n'), std::string::npos);
  EXPECT_TRUE(ws.qd.isZero(0.0));  // left as it was
  EXPECT_EQ(ws.counters.residual_evaluations, before.residual_evaluations + 1);
  EXPECT_EQ(ws.counters.factorizations, before.factorizations);  // refused before the factorisation
  EXPECT_EQ(ws.counters.velocity_solves, before.velocity_solves);

  EXPECT_EQ(solve_acceleration(m, 0.5, ws, &ls), SolveStatus::kPositionNotSolved);
  EXPECT_HAS(ls.message, "q does not solve the position problem at t = 0.5");
  EXPECT_STREQ(to_string(SolveStatus::kPositionNotSolved), "position not solved");
}

TEST(Derivatives, TheToleranceIsTheCallersChoice) {
  const Model m = test::crank_slider_model(2.0, 0.0);
  Workspace ws(m);
  ASSERT_EQ(solve_position(m, 0.3, {}, ws), SolveStatus::kSuccess);
  ws.q(3) += 1e-8;  // xB off by 1e-8 m: the rod (1 m) holds to 1e-8, not to 1e-10
  LinearSummary ls;
  EXPECT_EQ(solve_velocity(m, 0.3, ws, &ls), SolveStatus::kPositionNotSolved);
  EXPECT_HAS(ls.message, "constraint 'rod' residual ");
  EXPECT_HAS(ls.message, " > tolerance 1e-10 ");
  DerivativeOptions loose;
  loose.tolerance = 1e-6;
  EXPECT_EQ(solve_velocity(m, 0.3, loose, ws, &ls), SolveStatus::kSuccess) << ls.message;
  EXPECT_EQ(solve_acceleration(m, 0.3, loose, ws, &ls), SolveStatus::kSuccess) << ls.message;
  // infinity: no test at all
  ws.q(3) += 0.1;
  DerivativeOptions none;
  none.tolerance = std::numeric_limits<double>::infinity();
  const Index evaluations = ws.counters.residual_evaluations;
  EXPECT_EQ(solve_velocity(m, 0.3, none, ws, &ls), SolveStatus::kSuccess);
  EXPECT_EQ(ws.counters.residual_evaluations, evaluations);
  for (double bad : {0.0, -1e-10, std::numeric_limits<double>::quiet_NaN()}) {
    DerivativeOptions o;
    o.tolerance = bad;
    EXPECT_THROW((void)solve_velocity(m, 0.3, o, ws), Error) << bad;
  }
}

// The public sequence solve_position → solve_velocity → solve_acceleration: the check costs one Φ evaluation where
// the factors are not at the solution (full Newton factorises where its last step starts), none where solve_position
// left Φq evaluated there (jacobian_with_residual) or factorised there, and none for the acceleration that follows.
TEST(Derivatives, TheCheckCostsOneResidualAtMostAndChangesNoBits) {
  const Model m = test::crank_slider_model(2.0, 0.0, LinearSolverKind::kKlu);
  for (bool fused : {false, true}) {
    Workspace ws(m), unchecked(m);
    NewtonOptions o;
    o.jacobian_with_residual = fused;
    ASSERT_EQ(solve_position(m, 0.0, o, ws), SolveStatus::kSuccess);
    ASSERT_EQ(solve_position(m, 0.0, o, unchecked), SolveStatus::kSuccess);
    for (double t : {0.05, 0.1, 0.15}) {
      ASSERT_EQ(solve_position(m, t, o, ws), SolveStatus::kSuccess);
      ASSERT_EQ(solve_position(m, t, o, unchecked), SolveStatus::kSuccess);
      const bool known = ws.factorized_at_solution || ws.has_jacobian;
      const WorkCounters before = ws.counters;
      LinearSummary ls;
      ASSERT_EQ(solve_velocity(m, t, ws, &ls), SolveStatus::kSuccess) << ls.message;
      EXPECT_EQ(ws.counters.residual_evaluations - before.residual_evaluations, known ? 0 : 1) << fused << " " << t;
      ASSERT_EQ(solve_acceleration(m, t, ws, &ls), SolveStatus::kSuccess) << ls.message;
      EXPECT_EQ(ws.counters.residual_evaluations - before.residual_evaluations, known ? 0 : 1);
      if (fused) {
        EXPECT_TRUE(known) << t;
      }

      DerivativeOptions none;
      none.tolerance = std::numeric_limits<double>::infinity();
      ASSERT_EQ(solve_velocity(m, t, none, unchecked), SolveStatus::kSuccess);
      ASSERT_EQ(solve_acceleration(m, t, none, unchecked), SolveStatus::kSuccess);
      EXPECT_TRUE(test::same_bits(ws.q, unchecked.q));
      EXPECT_TRUE(test::same_bits(ws.qd, unchecked.qd));
      EXPECT_TRUE(test::same_bits(ws.qdd, unchecked.qdd));
      EXPECT_EQ(ws.counters.factorizations, unchecked.counters.factorizations);
    }
  }
}

// A q the caller sets to a solution itself (no solve_position): checked once, then velocity and acceleration agree
// with the closed form of the crank-slider.
TEST(Derivatives, CallersOwnSolvedPositionPassesTheCheck) {
  const double omega = 2.0, t = 0.4, th = omega * t;
  const Model m = test::crank_slider_model(omega, 0.0);
  Workspace ws(m);
  const double s = std::sin(th), c = std::cos(th);
  ws.q << th, 0.3 * c, 0.3 * s, 0.3 * c + std::sqrt(1.0 - 0.09 * s * s);
  LinearSummary ls;
  ASSERT_EQ(solve_velocity(m, t, ws, &ls), SolveStatus::kSuccess) << ls.message;
  EXPECT_NEAR(ws.qd(0), omega, 1e-14);
  EXPECT_NEAR(ws.qd(1), -0.3 * s * omega, 1e-12);
}

}  // namespace
}  // namespace phiq
