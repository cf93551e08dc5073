// Stepper (engine/include/phiq/stepper.hpp, engine/src/sweep/stepper.cpp): the caller's clock stepped with the
// sweep's predictors and diagnostics. Over a sweep's grid it must give run_sweep's rows and work, to the bit; at
// times of any spacing and direction, the closed form; at singular positions, run_sweep's warnings; a failed step
// must leave the state as it was.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// x_B, ẋ_B, ẍ_B of the crank-slider at θ = 2t: x_B = r cos θ + √(L² − r² sin² θ), differentiated in θ twice, times
// θ̇ = 2 and θ̇² = 4.
struct SliderExact {
  double x, v, a;
};
SliderExact slider_exact(double t) {
  const double r = 0.3, L = 1.0, th = 2 * t, s = std::sin(th), c = std::cos(th);
  const double D = std::sqrt(L * L - r * r * s * s);
  const double dx = -r * s - r * r * s * c / D;
  const double ddx = -r * c - r * r * (c * c - s * s) / D - std::pow(r, 4) * s * s * c * c / (D * D * D);
  return {r * c + D, 2 * dx, 4 * ddx};
}

StepperOptions stepper_options(const SweepOptions& o) {
  StepperOptions s;
  static_cast<SolverSettings&>(s) = o;
  s.velocities = o.velocities, s.accelerations = o.accelerations;
  return s;
}

std::vector<SweepWarning> of_kind(const std::vector<SweepWarning>& all, const std::string& kind) {
  std::vector<SweepWarning> out;
  for (const SweepWarning& w : all)
    if (w.kind == kind) out.push_back(w);
  return out;
}

// (1) Over run_sweep's grid the stepper is run_sweep in order: the same Sweeper, started afresh from the same
// placement, asked the same times. Rows, work and summary are the same, to the bit and the count; the hand loop the
// README showed before over the same times (solve_position, solve_velocity, solve_acceleration) does nearly three
// times the Newton iterations and four times the factorisations.
TEST(Stepper, OnASweepsGridGivesItsRowsBitForBitWithItsWork) {
  const Model model = test::readme_crank_slider();
  SweepOptions o;
  o.t_begin = 0, o.t_end = 1, o.steps = 100, o.threads = 1;
  o.chunk_steps = o.steps;  // in order: one chunk (a sweep in chunks starts each from a seed of its own)
  test::Trace tr;
  SweepSummary swept;
  ASSERT_EQ(test::sweep(model, o, &tr, &swept), SolveStatus::kSuccess) << swept.message;

  Stepper stepper(model, stepper_options(o));
  EXPECT_FALSE(stepper.started());
  EXPECT_TRUE(std::isnan(stepper.time()));
  for (Index k = 0; k <= o.steps; ++k) {
    StepSummary ss;
    ASSERT_EQ(stepper.step(o.time_of(k), &ss), SolveStatus::kSuccess) << ss.message;
    EXPECT_EQ(ss.assembled, k == 0);
    EXPECT_TRUE(ss.moved);
    EXPECT_EQ(stepper.time(), tr.t[k]);
    EXPECT_TRUE(test::same_bits(stepper.q(), tr.q[k])) << "row " << k;
    EXPECT_TRUE(test::same_bits(stepper.qd(), tr.qd[k])) << "row " << k;
    EXPECT_TRUE(test::same_bits(stepper.qdd(), tr.qdd[k])) << "row " << k;
  }
  const SweepSummary& s = stepper.summary();
  EXPECT_EQ(s.status, SolveStatus::kSuccess);
  EXPECT_EQ(s.steps_completed, 101);
  EXPECT_EQ(s.counters.newton_iterations, swept.counters.newton_iterations);
  EXPECT_EQ(s.counters.factorizations, swept.counters.factorizations);
  EXPECT_EQ(s.counters.residual_evaluations, swept.counters.residual_evaluations);
  EXPECT_EQ(s.counters.velocity_solves, swept.counters.velocity_solves);
  EXPECT_EQ(s.counters.acceleration_solves, swept.counters.acceleration_solves);
  EXPECT_EQ(s.assembly.iterations, swept.assembly.iterations);
  // one Newton iteration for the assembly (the placement is exact at t = 0), 101 for the 100 steps, and one
  // factorisation per row (for q̇ and q̈ at the solution, which the next step's modified Newton reuses)
  EXPECT_EQ(s.assembly.iterations, 1);
  EXPECT_EQ(s.counters.newton_iterations, 102);
  EXPECT_EQ(s.counters.factorizations, 101);
  EXPECT_EQ(s.accuracy.converged.rows, swept.accuracy.converged.rows);
  EXPECT_EQ(s.accuracy.converged.worst_error, swept.accuracy.converged.worst_error);
  EXPECT_EQ(s.warnings.size(), swept.warnings.size());
  EXPECT_EQ(s.min_rcond, swept.min_rcond);

  // The hand loop over the same times, as engine/README.md showed it before the Stepper.
  Workspace ws(model);
  for (Index k = 0; k <= o.steps; ++k) {
    const double t = o.time_of(k);
    ASSERT_EQ(solve_position(model, t, NewtonOptions{}, ws), SolveStatus::kSuccess);
    ASSERT_EQ(solve_velocity(model, t, ws), SolveStatus::kSuccess);
    ASSERT_EQ(solve_acceleration(model, t, ws), SolveStatus::kSuccess);
  }
  EXPECT_EQ(ws.counters.newton_iterations, 300);
  EXPECT_EQ(ws.counters.factorizations, 401);
}

// (2) Times the caller chooses: spacing growing as k² (steps from 0.01 to 0.59 s, θ up to 18 rad), then back down
// with another spacing, crossing the times of the way up. Every state is the closed form's.
TEST(Stepper, NonUniformTimesForwardAndBackMatchTheClosedForm) {
  const Model model = test::readme_crank_slider();
  Stepper stepper(model);
  std::vector<double> times;
  for (int k = 0; k <= 30; ++k) times.push_back(0.01 * k * k);
  for (int j = 1; 9.0 - 0.013 * j * j >= 0.0; ++j) times.push_back(9.0 - 0.013 * j * j);
  double worst_x = 0, worst_v = 0, worst_a = 0;
  for (const double t : times) {
    StepSummary ss;
    ASSERT_EQ(stepper.step(t, &ss), SolveStatus::kSuccess) << ss.message;
    const SliderExact e = slider_exact(t);
    worst_x = std::max(worst_x, std::fabs(stepper.q()(3) - e.x));
    worst_v = std::max(worst_v, std::fabs(stepper.qd()(3) - e.v));
    worst_a = std::max(worst_a, std::fabs(stepper.qdd()(3) - e.a));
  }
  EXPECT_LT(worst_x, 1e-9);
  EXPECT_LT(worst_v, 1e-9);
  EXPECT_LT(worst_a, 1e-9);
  EXPECT_EQ(stepper.summary().steps_completed, static_cast<Index>(times.size()));
  // the predictor still pays on steps this long (up to 1.18 rad of crank): less work than the three solves per step
  Workspace ws(model);
  for (const double t : times)
    ASSERT_TRUE(solve_position(model, t, NewtonOptions{}, ws) == SolveStatus::kSuccess &&
                solve_velocity(model, t, ws) == SolveStatus::kSuccess &&
                solve_acceleration(model, t, ws) == SolveStatus::kSuccess);
  // (195 Newton iterations and 139 factorisations against 247 and 282)
  EXPECT_LT(stepper.summary().counters.newton_iterations, ws.counters.newton_iterations);
  EXPECT_LT(stepper.summary().counters.factorizations, ws.counters.factorizations / 2);

  // A step of zero length re-delivers the state: no work, nothing counted.
  const Eigen::VectorXd q = stepper.q();
  const WorkCounters before = stepper.workspace().counters;
  StepSummary ss;
  ASSERT_EQ(stepper.step(stepper.time(), &ss), SolveStatus::kSuccess);
  EXPECT_FALSE(ss.moved);
  EXPECT_EQ(stepper.workspace().counters.newton_iterations, before.newton_iterations);
  EXPECT_EQ(stepper.summary().steps_completed, static_cast<Index>(times.size()));
  EXPECT_TRUE(test::same_bits(stepper.q(), q));
  // A step that would not move time is a programming error.
  EXPECT_THROW((void)stepper.step(std::nextafter(stepper.time(), 1.0)), Error);
  EXPECT_THROW((void)stepper.step(NAN), Error);
}

// (3) Singular positions: nfourbar (10 loops) landing on its flat positions at t = 1/4, 3/4 (bifurcation rows, the
// branch's own derivatives), and 2 loops crossing them between steps (reported by the signs of Φq's blocks): the
// stepper's warnings are run_sweep's, word for word, on the grid; on times of its own it warns at the same crossings.
TEST(Stepper, SingularPositionsWarnAsRunSweep) {
  const double w = 2 * M_PI;
  struct Case {
    Index n;
    double th0;
    Index steps;
    std::vector<double> at;  // where the bifurcation warnings are
  };
  for (const Case& c : {Case{10, M_PI / 2, 360, {0.25, 0.75}}, Case{2, 0.3, 1000, {0.453, 0.953}}}) {
    SCOPED_TRACE("N = " + std::to_string(c.n));
    const Model model = test::nfourbar_model(c.n, c.th0, w);
    SweepOptions o;
    o.t_begin = 0, o.t_end = 1, o.steps = c.steps, o.threads = 1;
    o.chunk_steps = o.steps;  // in order
    test::Trace tr;
    SweepSummary swept;
    ASSERT_EQ(test::sweep(model, o, &tr, &swept), SolveStatus::kSuccess) << swept.message;
    Stepper stepper(model, stepper_options(o));
    for (Index k = 0; k <= o.steps; ++k) {
      StepSummary ss;
      ASSERT_EQ(stepper.step(o.time_of(k), &ss), SolveStatus::kSuccess) << ss.message;
      ASSERT_TRUE(test::same_bits(stepper.q(), tr.q[k])) << "row " << k;
      ASSERT_TRUE(test::same_bits(stepper.qd(), tr.qd[k])) << "row " << k;
    }
    const auto bif = of_kind(stepper.summary().warnings, "bifurcation");
    const auto bif_swept = of_kind(swept.warnings, "bifurcation");
    ASSERT_EQ(bif.size(), c.at.size());
    ASSERT_EQ(bif_swept.size(), c.at.size());
    for (std::size_t j = 0; j < bif.size(); ++j) {
      EXPECT_NEAR(bif[j].t, c.at[j], 1e-12);
      EXPECT_EQ(bif[j].t, bif_swept[j].t);
      EXPECT_EQ(bif[j].message, bif_swept[j].message);
    }
    EXPECT_EQ(stepper.summary().singular_positions, swept.singular_positions);
    EXPECT_EQ(stepper.summary().accuracy.singular.rows, swept.accuracy.singular.rows);
  }
  // 2 loops, steps of 0.0037 s and 0.0061 s alternately: each crossing (t = 0.45225…, 0.95225…) is reported once,
  // at the first step after it, and every row is the parallelogram.
  const double th0 = 0.3;
  const Model model = test::nfourbar_model(2, th0, w);
  const auto exact = test::nfourbar_exact(model, th0, w);
  tools::ClosedFormErrors err(*exact);
  Stepper stepper(model);
  std::vector<double> times;
  for (double t = 0; t <= 1.0; t += times.size() % 2 ? 0.0061 : 0.0037) {
    times.push_back(t);
    ASSERT_EQ(stepper.step(t), SolveStatus::kSuccess) << stepper.summary().message;
    err.add(t, stepper.q().data(), nullptr, nullptr);
  }
  EXPECT_LT(err.q_error, 1e-8);
  const auto bif = of_kind(stepper.summary().warnings, "bifurcation");
  ASSERT_EQ(bif.size(), 2u);
  for (std::size_t j = 0; j < 2; ++j) {
    const double crossing = (M_PI * static_cast<double>(j + 1) - th0) / w;
    const auto after = std::upper_bound(times.begin(), times.end(), crossing);
    ASSERT_NE(after, times.end());
    EXPECT_EQ(bif[j].t, *after);
    EXPECT_HAS(bif[j].message, "the determinants of an even number of Φq's diagonal blocks");
  }
}

// (4) A failed step leaves the state as it was, and a step from there succeeds: a time outside a table driver's
// domain, and a rocker driven beyond its dead point (sub-steps converge towards it before one fails: the stepper
// returns to the state before the step, not to the last sub-step).
TEST(Stepper, AFailedStepKeepsTheStateAndTheNextStepSucceeds) {
  {
    const Model model = test::readme_crank_slider(0.3, 1.0, MotionLaw::table({0.0, 1.0, 2.0}, {0.0, 2.0, 4.0}));
    Stepper stepper(model);
    ASSERT_EQ(stepper.step(0.5), SolveStatus::kSuccess) << stepper.summary().message;
    ASSERT_EQ(stepper.step(0.7), SolveStatus::kSuccess) << stepper.summary().message;
    const Eigen::VectorXd q = stepper.q(), qd = stepper.qd();
    StepSummary ss;
    EXPECT_EQ(stepper.step(2.5, &ss), SolveStatus::kOutsideTimeDomain);
    EXPECT_EQ(ss.message, "t = 2.5: driver 'motor' is defined on [0, 2] only");
    EXPECT_FALSE(ss.moved);
    EXPECT_EQ(stepper.summary().failed_time, 2.5);
    EXPECT_EQ(stepper.time(), 0.7);
    EXPECT_TRUE(test::same_bits(stepper.q(), q));
    EXPECT_TRUE(test::same_bits(stepper.qd(), qd));
    ASSERT_EQ(stepper.step(1.5, &ss), SolveStatus::kSuccess) << ss.message;
    EXPECT_TRUE(ss.message.empty());
    EXPECT_EQ(stepper.summary().status, SolveStatus::kSuccess);
    EXPECT_NEAR(stepper.q()(3), slider_exact(1.5).x, 1e-9);
    EXPECT_EQ(stepper.summary().steps_completed, 3);
  }
  test::Prepared p = test::prepare("hard/crank_rocker_rocker_driven.yaml");
  ASSERT_NE(p.solved, nullptr) << p.assembly.BriefReport();
  Stepper stepper(*p.solved);
  stepper.restart(p.q);
  for (const double t : {0.0, 0.1, 0.2, 0.3, 0.4})
    ASSERT_EQ(stepper.step(t), SolveStatus::kSuccess) << stepper.summary().message;
  const Eigen::VectorXd q = stepper.q(), qd = stepper.qd(), qdd = stepper.qdd();
  const Index psi = p.solved->coordinate_index("psi");
  StepSummary ss;
  EXPECT_NE(stepper.step(0.6, &ss), SolveStatus::kSuccess);
  EXPECT_HAS(ss.message,
             "t = 0.6: no assembly beyond t = 0.4359375 (sub-steps down to t = 0.43671875 tried): a dead point near "
             "t = 0.436");
  EXPECT_HAS(ss.message, "dead point");
  EXPECT_GT(ss.subdivisions, 0);
  EXPECT_TRUE(ss.warnings.empty());
  EXPECT_EQ(stepper.time(), 0.4);
  EXPECT_TRUE(test::same_bits(stepper.q(), q));
  EXPECT_TRUE(test::same_bits(stepper.qd(), qd));
  EXPECT_TRUE(test::same_bits(stepper.qdd(), qdd));
  ASSERT_EQ(stepper.step(0.43, &ss), SolveStatus::kSuccess) << ss.message;
  EXPECT_NEAR(stepper.q()(psi), 2.2 + 0.43, 1e-12);
  EXPECT_EQ(stepper.summary().steps_completed, 6);
}

// (5) restart() after a jump of the caller's clock: the next step assembles from the new placement (the predictor's
// history forgotten), and the summary keeps counting. A moved stepper goes on where it was.
TEST(Stepper, RestartAssemblesAgainFromThePlacement) {
  const Model model = test::readme_crank_slider();
  Stepper first(model);
  for (const double t : {0.0, 0.1, 0.2}) ASSERT_EQ(first.step(t), SolveStatus::kSuccess);
  Stepper stepper = std::move(first);
  ASSERT_EQ(stepper.step(0.3), SolveStatus::kSuccess);
  EXPECT_NEAR(stepper.q()(3), slider_exact(0.3).x, 1e-9);
  const Index iterations = stepper.summary().counters.newton_iterations;

  // the caller jumps to t = 2 (θ = 4 rad) and places the slider roughly there
  Eigen::VectorXd placement(4);
  placement << 4.0, 0.3 * std::cos(4.0) + 0.01, 0.3 * std::sin(4.0) - 0.01, slider_exact(2.0).x + 0.02;
  stepper.restart(placement);
  EXPECT_FALSE(stepper.started());
  EXPECT_TRUE(test::same_bits(stepper.q(), placement));
  StepSummary ss;
  ASSERT_EQ(stepper.step(2.0, &ss), SolveStatus::kSuccess) << ss.message;
  EXPECT_TRUE(ss.assembled);
  EXPECT_GT(stepper.summary().assembly.iterations, 1);
  EXPECT_EQ(ss.counters.newton_iterations, stepper.summary().assembly.iterations);
  EXPECT_EQ(stepper.summary().counters.newton_iterations, iterations + ss.counters.newton_iterations);
  EXPECT_NEAR(stepper.q()(3), slider_exact(2.0).x, 1e-9);
  ASSERT_EQ(stepper.step(2.01, &ss), SolveStatus::kSuccess) << ss.message;
  EXPECT_FALSE(ss.assembled);
  EXPECT_NEAR(stepper.qd()(3), slider_exact(2.01).v, 1e-9);
  EXPECT_EQ(stepper.summary().steps_completed, 6);
  EXPECT_THROW(stepper.restart(Eigen::VectorXd(3)), Error);
}

// Settings no step can honour are refused when the stepper is made, as run_sweep refuses them.
TEST(Stepper, RefusesSettingsNoStepCanHonour) {
  const Model model = test::readme_crank_slider();
  StepperOptions o;
  o.max_subdivisions = -1;
  EXPECT_THROW(Stepper s(model, o), Error);
  o = StepperOptions{};
  o.accelerations = false;
  o.predictor = Predictor::kCubic;
  EXPECT_THROW(Stepper s(model, o), Error);
  o = StepperOptions{};
  o.expected_step = 0.0;
  EXPECT_THROW(Stepper s(model, o), Error);
}

}  // namespace
}  // namespace phiq
