// run_sweep in order: predictors, step subdivision, failures that stop with a diagnosis, bad settings and time
// grids refused, cancellation, warnings once per stretch. The parallel sweep is test_sweep_parallel.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

#include "phiq/phiq.hpp"
#include "test_support.hpp"
#include "sweep/warning_stretches.hpp"

namespace phiq {
namespace {

auto S = Slot::coordinate;
auto C = Slot::constant;

// Crank-rocker four-bar in natural coordinates (O=(0,0), C=(1,0); a=0.4, b=1.2, c=1.0), driven by the rocker angle
// theta4 of segment C→B. The rocker can only swing between θ4 = acos(0.28) (crank and coupler stretched out,
// |OB| = 1.6) and acos(−0.68) (folded, |OB| = 0.8).
Model rocker_driven(double from, double rate) {
  ModelBuilder b;
  Index xa = b.add_coordinate("xA", 0.1), ya = b.add_coordinate("yA", 0.4),
        xb = b.add_coordinate("xB", 1.0 + std::cos(from)), yb = b.add_coordinate("yB", std::sin(from)),
        th4 = b.add_coordinate("theta4", from);
  Point2 O{C(0), C(0)}, A{S(xa), S(ya)}, B{S(xb), S(yb)}, Cc{C(1), C(0)};
  b.add("crank", DistanceSpec{O, A, 0.4});
  b.add("coupler", DistanceSpec{A, B, 1.2});
  b.add("rocker", DistanceSpec{Cc, B, 1.0});
  b.add("rocker_angle", SegmentAngleSpec{Cc, B, S(th4)});
  b.add_driver("rocker_motor", th4, MotionLaw::linear(from, rate));
  return std::move(b).build();
}

TEST(Sweep, DriveBeyondTheReachableRangeStopsWithADiagnosis) {
  const double limit = std::acos(-0.68);  // 2.3462 rad
  Model m = rocker_driven(1.5, 1.0);
  SweepOptions opt;
  opt.t_end = 1.1;  // θ4 up to 2.6 rad
  opt.steps = 110;
  test::Trace tr;
  SweepSummary sum;
  EXPECT_NE(test::sweep(m, opt, &tr, &sum), SolveStatus::kSuccess);
  // every delivered row is inside the range, and the run stopped at the first step beyond it
  ASSERT_FALSE(tr.t.empty());
  EXPECT_LE(1.5 + tr.t.back(), limit + 1e-12);
  EXPECT_GT(1.5 + sum.failed_time, limit);
  EXPECT_LT(1.5 + sum.failed_time, limit + 0.01 + 1e-12);
  EXPECT_EQ(sum.failed_step, static_cast<Index>(tr.t.size()));
  EXPECT_NE(sum.message.find("step " + std::to_string(sum.failed_step)), std::string::npos) << sum.message;
  EXPECT_NE(sum.message.find("t = "), std::string::npos) << sum.message;
  // the diagnosis names constraints
  EXPECT_NE(sum.message.find("'"), std::string::npos) << sum.message;
}

TEST(Sweep, ALawNotDefinedAheadStopsNamingTheDriver) {
  // A slider driven by x = √(1 − t) (undefined beyond t = 1) and by x = exp(t) (beyond the largest double past
  // t = 709.78): the sweep stops at the last time it can reach, naming the driver whose law is not defined, not
  // "a dead point" or "the drive leaves the reachable range" (what the failure was reported as).
  for (const auto& [law, t_end, t_star] : {std::tuple{"sqrt(1 - t)", 2.0, 1.0}, std::tuple{"exp(t)", 720.0, 709.78}}) {
    const Scene sc = parse_scene(std::string("coordinates: {x: 1}\ndrivers:\n  - {name: push, coordinate: x, law: "
                                             "{type: expression, f: \"") +
                                     law + "\"}}\ntime: {start: 0, end: " + std::to_string(t_end) + ", steps: 4}\n",
                                 "law.yaml");
    Workspace ws(*sc.model);
    SweepSummary sum;
    EXPECT_EQ(run_sweep(*sc.model, sc.sweep, ws, nullptr, &sum), SolveStatus::kNonFinite) << law;
    EXPECT_HAS(sum.message, "'push' is not finite at t = ");
    EXPECT_HAS(sum.message, "(its law or equation is not defined there, or overflows)");
    EXPECT_EQ(sum.message.find("dead point"), std::string::npos) << sum.message;
    EXPECT_GT(sum.failed_time, t_star) << sum.message;
  }
}

TEST(Sweep, TableOutsideItsRangeIsRefusedBeforeSolving) {
  ModelBuilder b;
  Index x = b.add_coordinate("x", 0.0);
  b.add_driver("lift", x, MotionLaw::table({0.0, 1.0, 2.0}, {0.0, 0.5, 0.7}));
  Model m = std::move(b).build();
  SweepOptions opt;
  opt.t_end = 3.0;
  opt.steps = 3;
  test::Trace tr;
  SweepSummary sum;
  EXPECT_EQ(test::sweep(m, opt, &tr, &sum), SolveStatus::kOutsideTimeDomain);
  EXPECT_TRUE(tr.t.empty());
  EXPECT_NE(sum.message.find("'lift'"), std::string::npos) << sum.message;
  EXPECT_NE(sum.message.find("t = 3"), std::string::npos) << sum.message;
}

Model crank_slider() { return test::crank_slider_model(); }

double slider_x(double th) { return 0.3 * std::cos(th) + std::sqrt(1.0 - 0.09 * std::sin(th) * std::sin(th)); }

TEST(Sweep, FailedStepsAreSubdividedAndTheSweepContinues) {
  Model m = crank_slider();
  SweepOptions opt;
  opt.t_end = M_PI;
  opt.steps = 6;  // 30° steps
  opt.velocities = opt.accelerations = false;
  opt.predictor = Predictor::kPrevious;
  opt.newton.max_iterations = 3;  // too few for a 30° jump from the previous position
  test::Trace tr;
  SweepSummary sum;
  ASSERT_EQ(test::sweep(m, opt, &tr, &sum), SolveStatus::kSuccess) << sum.message;
  EXPECT_GT(sum.subdivisions, 0);
  ASSERT_EQ(tr.t.size(), 7u);
  for (std::size_t k = 0; k < tr.t.size(); ++k) EXPECT_NEAR(tr.q[k](3), slider_x(tr.t[k]), 1e-9);
}

// SweepOptions::newton.known_to is a floor under the rounding level a sweep carries (NewtonOptions::known_to): with
// the quadratic predictor on 0.5° rows and full Newton, a row's first step (about 10³ tolerances) lands within the
// residual's tolerance but needs a second to show it; with a floor above those steps, each row ends after its
// first, reported as its rounding level (and warned of).
TEST(Sweep, TheCallersKnownToIsAFloorUnderTheLevelTheSweepCarries) {
  Model m = crank_slider();
  auto run = [&](double known_to) {
    SweepOptions opt;
    opt.t_end = M_PI;
    opt.steps = 360;
    opt.predictor = Predictor::kQuadratic;
    opt.newton.jacobian_update = JacobianUpdate::kEveryIteration;
    opt.newton.known_to = known_to;
    opt.chunk_steps = opt.steps;  // one chunk, in order: the rows' own Newton steps are counted, not chunk seeds
    test::Trace tr;
    SweepSummary sum;
    EXPECT_EQ(test::sweep(m, opt, &tr, &sum), SolveStatus::kSuccess) << sum.message;
    return sum;
  };
  const SweepSummary plain = run(0.0), floored = run(1e12);
  EXPECT_GE(plain.counters.newton_iterations, 2 * 360 - 10);
  EXPECT_TRUE(plain.warnings.empty());
  EXPECT_LE(floored.counters.newton_iterations, 360 + 10);
  ASSERT_FALSE(floored.warnings.empty());
  EXPECT_EQ(floored.warnings[0].kind, "slow_convergence");
  EXPECT_HAS(floored.warnings[0].message, "within the level q can be known to here");
}

TEST(Sweep, PredictorsReachTheSameSolutions) {
  Model m = crank_slider();
  for (Predictor p : {Predictor::kPrevious, Predictor::kSecant, Predictor::kParabolic, Predictor::kLinear,
                      Predictor::kHermite, Predictor::kQuadratic, Predictor::kCubic}) {
    SweepOptions opt;
    opt.t_begin = 0.5;  // not 0: the secant's first extrapolation once read an empty state here (fuzzer)
    opt.t_end = 2 * M_PI;
    opt.steps = 72;
    opt.predictor = p;
    test::Trace tr;
    SweepSummary sum;
    ASSERT_EQ(test::sweep(m, opt, &tr, &sum), SolveStatus::kSuccess) << to_string(p) << sum.message;
    // The tolerance (1e-10 × the rod's 1 m) bounds the *estimated* error θ/(1−θ)|Δq| of the last Newton step, not
    // the error itself: measured up to 0.97e-10 (model-wide length scale) and 1.02e-10 (per-link scales).
    for (std::size_t k = 0; k < tr.t.size(); ++k) EXPECT_NEAR(tr.q[k](3), slider_x(tr.t[k]), 2e-10) << to_string(p);
  }
}

// Each order of extrapolation saves Newton iterations, with positions only (the parabola against the previous
// position and the secant), with q̇ only (linear → hermite) and with q̇, q̈ (linear → quadratic → cubic), and the
// solutions stay within the tolerance of the closed form. On finer steps the cubic predictor errs by about 1e-11 m per
// step, so that most steps are accepted without a Newton step (predict()'s error budget brings one when the carried
// errors add up to the tolerance).
TEST(Sweep, BetterPredictorsNeedFewerNewtonIterations) {
  Model m = crank_slider();
  auto iterations = [&](Predictor p, bool derivatives, Index steps, bool accelerations = true) {
    SweepOptions opt;
    opt.t_end = 2 * M_PI;
    opt.steps = steps;
    opt.predictor = p;
    opt.velocities = derivatives;
    opt.accelerations = derivatives && accelerations;
    test::Trace tr;
    SweepSummary sum;
    EXPECT_EQ(test::sweep(m, opt, &tr, &sum), SolveStatus::kSuccess);
    for (std::size_t k = 0; k < tr.t.size(); ++k) EXPECT_NEAR(tr.q[k](3), slider_x(tr.t[k]), 2e-10) << to_string(p);
    return sum.counters.newton_iterations;
  };
  const Index previous = iterations(Predictor::kPrevious, false, 720),
              secant = iterations(Predictor::kSecant, false, 720),
              parabolic = iterations(Predictor::kParabolic, false, 720);
  EXPECT_LT(parabolic, secant);
  EXPECT_LT(parabolic, previous);
  const Index linear = iterations(Predictor::kLinear, true, 720),
              quadratic = iterations(Predictor::kQuadratic, true, 720),
              cubic = iterations(Predictor::kCubic, true, 720);
  EXPECT_LT(quadratic, linear);
  EXPECT_LT(cubic, quadratic);
  const Index fine_quadratic = iterations(Predictor::kQuadratic, true, 2880),
              fine_cubic = iterations(Predictor::kCubic, true, 2880);
  EXPECT_LT(fine_cubic, 2880 / 2);  // most steps without a Newton step
  EXPECT_LT(fine_cubic, fine_quadratic / 2);
  // velocities only: the cubic tangent to q̇ against q + h q̇ (O(h⁴) against O(h²))
  const Index linear_v = iterations(Predictor::kLinear, true, 720, false),
              hermite = iterations(Predictor::kHermite, true, 720, false),
              fine_hermite = iterations(Predictor::kHermite, true, 2880, false);
  EXPECT_LT(hermite, linear_v * 11 / 20);  // about half: like the cubic predictor at this step
  EXPECT_LT(hermite, cubic * 21 / 20);
  EXPECT_LT(hermite, parabolic / 2);  // q̇ makes the positions' extrapolation one order better
  // On fine steps about every other step needs no Newton step (the cubic: nearly all): the hermite prediction
  // weighs the errors of three rows, by |−3/2| + 3 + |−1/2| = 5 at equal steps, where the cubic's carries its
  // current row's only, so the carried errors reach the tolerance sooner.
  EXPECT_LT(fine_hermite, 2880 * 3 / 5);
  std::printf(
      "Newton iterations over 720 steps: previous %ld, secant %ld, parabolic %ld; linear %ld, quadratic %ld, "
      "cubic %ld; q̇ only: linear %ld, hermite %ld; over 2880 steps: quadratic %ld, cubic %ld, hermite %ld\n",
      static_cast<long>(previous), static_cast<long>(secant), static_cast<long>(parabolic), static_cast<long>(linear),
      static_cast<long>(quadratic), static_cast<long>(cubic), static_cast<long>(linear_v), static_cast<long>(hermite),
      static_cast<long>(fine_quadratic), static_cast<long>(fine_cubic), static_cast<long>(fine_hermite));
}

// The hermite predictor is the cubic through the current row (position and velocity) and the two rows before: a
// coordinate driven by a cubic law is predicted exactly once three rows are known, and its error estimate (the next,
// quartic term) is then zero, so those steps take no Newton iteration; a quartic law is not (the estimate sees the
// quartic term).
TEST(Sweep, HermitePredictorIsExactForCubicMotion) {
  auto sweep = [](std::vector<double> coefficients) {
    ModelBuilder b;
    const Index x = b.add_coordinate("x", coefficients[0]);
    b.add_driver("law", x, MotionLaw::polynomial(coefficients));
    Model m = std::move(b).build();
    SweepOptions opt;
    opt.t_end = 2.0;
    opt.steps = 13;
    opt.velocities = true;
    opt.accelerations = false;
    opt.predictor = Predictor::kHermite;
    opt.newton.jacobian_update = JacobianUpdate::kEveryIteration;
    std::vector<Index> per_row;
    Workspace ws(m);
    SweepSummary sum;
    Index before = 0;
    (void)run_sweep(
        m, opt, ws,
        [&](const StepView&) {  // its status is sum.status, checked below
          per_row.push_back(ws.counters.newton_iterations - before);
          before = ws.counters.newton_iterations;
          return true;
        },
        &sum);
    EXPECT_EQ(sum.status, SolveStatus::kSuccess) << sum.message;
    return per_row;
  };
  const std::vector<Index> cubic = sweep({0.3, -1.0, 0.5, 0.25});
  ASSERT_EQ(cubic.size(), 14u);
  // rows 0 … 3: the assembly, then too few rows for the cubic and its estimate; from row 4 on, none
  for (std::size_t k = 4; k < cubic.size(); ++k) EXPECT_EQ(cubic[k], 0) << "row " << k;
  const std::vector<Index> quartic = sweep({0.3, -1.0, 0.5, 0.25, 2.0});
  Index quartic_steps = 0;
  for (std::size_t k = 4; k < quartic.size(); ++k) quartic_steps += quartic[k];
  EXPECT_GE(quartic_steps, 5) << "the quartic term is 2 h⁴-sized: seen by the estimate";
}

// The predictors' names, and what auto resolves to for what a sweep computes.
TEST(Sweep, PredictorNamesAndTheAutomaticChoice) {
  for (Predictor p : {Predictor::kAuto, Predictor::kPrevious, Predictor::kSecant, Predictor::kParabolic,
                      Predictor::kLinear, Predictor::kHermite, Predictor::kQuadratic, Predictor::kCubic}) {
    Predictor back = Predictor::kPrevious;
    EXPECT_TRUE(predictor_from_string(to_string(p), &back));
    EXPECT_EQ(back, p);
  }
  Predictor unchanged = Predictor::kSecant;
  EXPECT_FALSE(predictor_from_string("quartic", &unchanged));
  EXPECT_EQ(unchanged, Predictor::kSecant);
  EXPECT_EQ(effective_predictor(Predictor::kAuto, true, true), Predictor::kCubic);
  EXPECT_EQ(effective_predictor(Predictor::kAuto, true, false), Predictor::kHermite);
  EXPECT_EQ(effective_predictor(Predictor::kAuto, false, false), Predictor::kParabolic);
  EXPECT_EQ(effective_predictor(Predictor::kSecant, true, true), Predictor::kSecant);
  EXPECT_TRUE(predictor_needs_accelerations(Predictor::kCubic));
  EXPECT_TRUE(predictor_needs_velocities(Predictor::kCubic));
  EXPECT_FALSE(predictor_needs_velocities(Predictor::kParabolic));
  EXPECT_TRUE(predictor_needs_velocities(Predictor::kHermite));
  EXPECT_FALSE(predictor_needs_accelerations(Predictor::kHermite));
  // a sweep refuses a predictor whose derivatives it does not compute
  Model m = crank_slider();
  SweepOptions opt;
  opt.accelerations = false;
  opt.predictor = Predictor::kCubic;
  Workspace ws(m);
  EXPECT_THROW((void)run_sweep(m, opt, ws, nullptr, nullptr), Error);
}

// Bad settings are refused before the sweep starts, naming the field: an infinite drive tolerance used to pass as
// a successful sweep of the unmoved start, bad drive settings were found only after the assembly had delivered row
// 0 (on 2 threads, by a worker), a negative max_subdivisions and an unknown predictor passed unnoticed.
TEST(Sweep, SettingsNoSweepCanHonourAreRefusedBeforeTheFirstRow) {
  Model m = crank_slider();
  for (int threads : {1, 2}) {
    auto refusal = [&](auto&& edit) -> std::string {
      SweepOptions opt;
      opt.threads = threads;
      opt.chunk_steps = 10;
      edit(opt);
      Workspace ws(m);
      Index rows = 0;
      try {
        (void)run_sweep(
            m, opt, ws, [&](const StepView&) { return ++rows, true; }, nullptr);  // throws: the test
      } catch (const Error& e) {
        EXPECT_EQ(rows, 0) << e.what();
        return e.what();
      }
      return "accepted";
    };
    EXPECT_EQ(refusal([](SweepOptions& o) { o.newton.tolerance = INFINITY; }),
              "SweepOptions::newton: tolerance must be > 0 and finite");
    EXPECT_EQ(refusal([](SweepOptions& o) { o.newton.max_contraction = 2.0; }),
              "SweepOptions::newton: max_contraction must be in (0, 1)");
    EXPECT_EQ(refusal([](SweepOptions& o) { o.assembly.max_iterations = -1; }),
              "SweepOptions::assembly: max_iterations must be >= 0");
    EXPECT_EQ(refusal([](SweepOptions& o) { o.max_subdivisions = -1; }), "SweepOptions: max_subdivisions must be >= 0");
    EXPECT_EQ(refusal([](SweepOptions& o) { o.predictor = static_cast<Predictor>(99); }),
              "SweepOptions: predictor is not a Predictor");
    EXPECT_EQ(refusal([](SweepOptions& o) { o.max_subdivisions = 0; }), "accepted");
  }
}

// A time grid whose steps do not move time is refused before anything is solved (the scene loader refuses it at
// `time.end`): t_begin = t_end with steps > 0 and steps below the rounding of the times made the predictors divide
// by a zero spacing, and failed as "starting point has non-finite coordinates"; a span that overflows
// (−1e308 to 1e308) failed at "t = -nan". A short span well above the rounding, and steps = 0, are swept.
TEST(Sweep, ATimeGridWhoseStepsDoNotMoveTimeIsRefused) {
  Model m = crank_slider();
  for (int threads : {1, 2}) {
    auto refusal = [&](double t_begin, double t_end, Index steps, Index* rows_out = nullptr) -> std::string {
      SweepOptions opt;
      opt.threads = threads;
      opt.chunk_steps = 2;
      opt.t_begin = t_begin, opt.t_end = t_end, opt.steps = steps;
      Workspace ws(m);
      Index rows = 0;
      SweepSummary sum;
      try {
        (void)run_sweep(
            m, opt, ws, [&](const StepView&) { return ++rows, true; }, &sum);  // throws: the test
      } catch (const Error& e) {
        EXPECT_EQ(rows, 0) << e.what();
        return e.what();
      }
      if (rows_out) *rows_out = rows;
      return sum.status == SolveStatus::kSuccess ? "swept" : sum.message;
    };
    EXPECT_EQ(refusal(0.5, 0.5, 10), "SweepOptions: t_end equals t_begin but steps > 0");
    EXPECT_EQ(refusal(1.0, 1.0 + 4e-16, 10),
              "SweepOptions: 10 steps from t = 1 to 1 are 4.44e-17 s each, below the rounding of the times (8 ulps: "
              "1.78e-15 s): they would not move time");
    EXPECT_EQ(refusal(-1e308, 1e308, 4), "SweepOptions: the span from t = -1e+308 to 1e+308 is not a finite number");
    Index rows = 0;
    EXPECT_EQ(refusal(0.5, 0.5, 0, &rows), "swept");
    EXPECT_EQ(rows, 1);
    EXPECT_EQ(refusal(1.0, 1.0 + 1e-9, 10, &rows), "swept");
    EXPECT_EQ(rows, 11);
    EXPECT_EQ(refusal(1.0 + 1e-9, 1.0, 10, &rows), "swept");
    EXPECT_EQ(rows, 11);
  }
}

TEST(Sweep, PositionOnlySweepDoesNoVelocityOrAccelerationWork) {
  Model m = crank_slider();
  SweepOptions opt;
  opt.t_end = 1.0;
  opt.steps = 10;
  opt.velocities = opt.accelerations = false;
  test::Trace tr;
  SweepSummary sum;
  ASSERT_EQ(test::sweep(m, opt, &tr, &sum), SolveStatus::kSuccess);
  EXPECT_EQ(sum.counters.velocity_solves, 0);
  EXPECT_EQ(sum.counters.acceleration_solves, 0);
  EXPECT_EQ(sum.counters.phi_t_evaluations, 0);
  EXPECT_EQ(sum.counters.gamma_evaluations, 0);
  EXPECT_TRUE(tr.qd.empty());
  // with velocities and accelerations: exactly one solve of each per row
  opt.velocities = opt.accelerations = true;
  test::Trace tr2;
  ASSERT_EQ(test::sweep(m, opt, &tr2, &sum), SolveStatus::kSuccess);
  EXPECT_EQ(sum.counters.velocity_solves, 11);
  EXPECT_EQ(sum.counters.acceleration_solves, 11);
  EXPECT_EQ(sum.counters.gamma_evaluations, 11);
}

TEST(Sweep, CallbackCanStopTheSweep) {
  Model m = crank_slider();
  Workspace ws(m);
  SweepOptions opt;
  opt.steps = 50;
  int rows = 0;
  SweepSummary sum;
  EXPECT_EQ(run_sweep(
                m, opt, ws, [&](const StepView&) { return ++rows < 5; }, &sum),
            SolveStatus::kCancelled);
  EXPECT_EQ(rows, 5);
}

TEST(Sweep, ReverseTimeAndSingleStepSweeps) {
  Model m = crank_slider();
  SweepOptions opt;
  opt.t_begin = 1.0;
  opt.t_end = 0.0;
  opt.steps = 10;
  test::Trace tr;
  ASSERT_EQ(test::sweep(m, opt, &tr), SolveStatus::kSuccess);
  EXPECT_DOUBLE_EQ(tr.t.front(), 1.0);
  EXPECT_DOUBLE_EQ(tr.t.back(), 0.0);
  EXPECT_NEAR(tr.q.back()(3), 1.3, 1e-10);  // the tolerance (1e-10 × the 1 m rod)
  opt.steps = 0;
  test::Trace one;
  ASSERT_EQ(test::sweep(m, opt, &one), SolveStatus::kSuccess);
  ASSERT_EQ(one.t.size(), 1u);
  // no step: the one row is the position at t_begin (it was labelled and solved at t_end)
  EXPECT_EQ(one.t[0], 1.0);
  EXPECT_NEAR(one.q[0](3), tr.q.front()(3), 1e-12);
}

// A warning that recurs is said once per stretch of rows (detail::once_per_stretch, run_sweep's slow_convergence):
// consecutive rows and rows up to two quiet rows apart join one stretch, whose first warning says how far it went
// and, with quiet rows in it, how many of its rows warned; a sub-step's warning stands alone; other kinds keep their
// place.
TEST(Sweep, ARecurringWarningIsSaidOncePerStretchOfRows) {
  SweepOptions opt;
  opt.t_begin = 1.0, opt.t_end = 2.0, opt.steps = 100;  // rows 0.01 apart
  auto at = [&](double row, const char* kind = "slow_convergence") {
    return SweepWarning{1.0 + row / 100.0, kind, std::string("w") + std::to_string(static_cast<int>(row * 10))};
  };
  std::vector<SweepWarning> w = {at(3),
                                 at(4),
                                 at(5),  // consecutive: one stretch
                                 at(9),
                                 at(11),
                                 at(12),
                                 at(15),                     // 1 and 2 quiet rows between: one stretch
                                 at(19, "ill_conditioned"),  // another kind, in its place
                                 at(19),
                                 at(22.5),
                                 at(23),
                                 at(40)};  // a sub-step alone, 3 quiet rows: new stretches
  detail::once_per_stretch(w, "slow_convergence", opt);
  ASSERT_EQ(w.size(), 7u);
  EXPECT_EQ(w[0].message, "w30; the same at the next 2 rows, to t = 1.05");
  EXPECT_EQ(w[1].message, "w90; the same at 3 of the next 6 rows, to t = 1.15");
  EXPECT_EQ(w[2].kind, "ill_conditioned");
  EXPECT_EQ(w[3].message, "w190");
  EXPECT_EQ(w[4].message, "w225");
  EXPECT_EQ(w[5].message, "w230");
  EXPECT_EQ(w[6].message, "w400");
  EXPECT_DOUBLE_EQ(w[4].t, 1.225);
}

}  // namespace
}  // namespace phiq
