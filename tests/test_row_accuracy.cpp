// SweepSummary::accuracy: every delivered row is counted in one class (converged, rounding level, singular), and
// each class's worst estimated error bounds what the rows are really off the closed form, in units of the
// tolerance test (max_j |q_j − q*_j| / (tol · scale_j + 64 ulps of q_j)): the summary says how well q is known.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "test_support.hpp"

namespace phiq {
namespace {

constexpr double kNewtonTol = 1e-10;

Index sum_of_rows(const SweepAccuracy& a) { return a.converged.rows + a.rounding_level.rows + a.singular.rows; }

// |q_j − exact| in units of the tolerance test of coordinate j.
double in_tolerances(const Model& m, Index j, double q, double exact) {
  return std::fabs(q - exact) /
         (kNewtonTol * m.tolerance_scales().coordinate_scale(j) + ToleranceScales::kUlpFloor * std::fabs(q));
}

// A scissor lift of 4000 stages: its top joints, 4000 m up, are known to a few tolerances only (the rounding of Φ
// amplified along the chain; at 2000 stages they are at one or two, on either side of the line by the rounding of
// the pivot order). Rows accepted at that level are counted as such, not as converged, and the worst
// estimate bounds the real error of every coordinate checked against L_k = (0, k sin θ), R_k = (cos θ, k sin θ).
TEST(RowAccuracy, ALongChainsRowsAtTheRoundingLevelAreCountedAndBoundTheirError) {
  Scene sc = parse_scene(tools::generate_scene(test::generate_options("scissor", 4000, "natural", 0.3, 1.2, 1000)),
                         "scissor.yaml");
  sc.sweep.steps = 20;
  sc.sweep.t_end = 0.02;
  const Model& m = *sc.model;
  const Index th = m.coordinate_index("theta");
  double real = 0.0, real_m = 0.0;  // in tolerances, and in metres
  Workspace ws(m);
  SweepSummary sum;
  ASSERT_EQ(run_sweep(
                m, sc.sweep, ws,
                [&](const StepView& v) {
                  const double s = std::sin(v.q(th)), c = std::cos(v.q(th));
                  for (int level : {1, 2000, 4000}) {
                    const std::string l = std::to_string(level);
                    const Index xl = m.coordinate_index("xl" + l), yl = m.coordinate_index("yl" + l);
                    const Index xr = m.coordinate_index("xr" + l), yr = m.coordinate_index("yr" + l);
                    real = std::max({real, in_tolerances(m, xl, v.q(xl), 0.0), in_tolerances(m, yl, v.q(yl), level * s),
                                     in_tolerances(m, xr, v.q(xr), c), in_tolerances(m, yr, v.q(yr), level * s)});
                    real_m = std::max({real_m, std::fabs(v.q(xl)), std::fabs(v.q(yl) - level * s),
                                       std::fabs(v.q(xr) - c), std::fabs(v.q(yr) - level * s)});
                  }
                  return true;
                },
                &sum),
            SolveStatus::kSuccess)
      << sum.message;
  const SweepAccuracy& a = sum.accuracy;
  EXPECT_EQ(sum_of_rows(a), 21);
  EXPECT_GE(a.rounding_level.rows, 1);
  EXPECT_GT(a.rounding_level.worst_error, 2.0);
  EXPECT_LE(a.converged.worst_error, 2.0);
  EXPECT_EQ(a.singular.rows, 0);
  EXPECT_EQ(a.converged.unestimated + a.rounding_level.unestimated, 0);
  // the real error is within the worst estimate (θ is exact: the driven coordinate)
  EXPECT_GT(real, 1.0);
  EXPECT_LE(real, std::max(a.converged.worst_error, a.rounding_level.worst_error));
  // and in metres, at the coordinate the worst estimate names (a top joint: the largest floor)
  EXPECT_FALSE(a.rounding_level.worst_coordinate.empty());
  EXPECT_EQ(a.rounding_level.worst_unit, Unit::kLength);
  EXPECT_LE(real_m, a.rounding_level.worst_known_to) << a.rounding_level.worst_coordinate;
  EXPECT_GT(a.rounding_level.worst_known_to, 1e-10);  // above the tolerance test's tol · scale
}

// A chain of 100 parallelograms started on its flat position: row 0 is singular (its q̇, q̈ the branch's
// extrapolated limits; its position the placement, no solve estimated its error), every other row converged to
// the tolerance, and the parallelogram's closed form (every crank at the driven angle) is met within the estimate
// (measured 0.25 against 0.80 tolerances).
TEST(RowAccuracy, ASweepStartedOnASingularPositionCountsThatRowAsSingular) {
  Scene sc = parse_scene(tools::generate_scene(test::generate_options("nfourbar", 100, "natural", 0.0, 0.5, 50)),
                         "nfourbar.yaml");
  const Model& m = *sc.model;
  for (int threads : {1, 2}) {
    SweepOptions opt = sc.sweep;
    opt.threads = threads;
    Workspace ws(m);
    SweepSummary sum;
    double real = 0.0;  // rows after the first: crank tip i at (i + cos θ, sin θ), θ = 0.5 t
    ASSERT_EQ(run_sweep(
                  m, opt, ws,
                  [&](const StepView& v) {
                    if (v.step == 0) return true;
                    const double c = std::cos(0.5 * v.t), s = std::sin(0.5 * v.t);
                    for (int i = 0; i <= 100; ++i) {
                      const Index x = m.coordinate_index("x" + std::to_string(i));
                      const Index y = m.coordinate_index("y" + std::to_string(i));
                      real = std::max({real, in_tolerances(m, x, v.q(x), i + c), in_tolerances(m, y, v.q(y), s)});
                    }
                    return true;
                  },
                  &sum),
              SolveStatus::kSuccess)
        << sum.message;
    EXPECT_LE(real, sum.accuracy.converged.worst_error) << threads << " threads";
    const SweepAccuracy& a = sum.accuracy;
    EXPECT_EQ(sum_of_rows(a), 51);
    EXPECT_EQ(a.singular.rows, 1);
    EXPECT_EQ(a.singular.unestimated, 1);
    EXPECT_EQ(a.converged.rows, 50);
    EXPECT_EQ(a.rounding_level.rows, 0);
    EXPECT_GT(a.converged.worst_error, 0.0);
    EXPECT_LE(a.converged.worst_error, 2.0);
    EXPECT_GT(a.converged.worst_time, 0.0);
  }
}

}  // namespace
}  // namespace phiq
