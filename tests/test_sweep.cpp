// run_sweep: predictors, step subdivision, failures that stop with a diagnosis, cancellation.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <thread>
#include <tuple>

#include <tbb/info.h>

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
  Index xa = b.add_coordinate("xA", 0.1), ya = b.add_coordinate("yA", 0.4), xb = b.add_coordinate("xB", 1.0 + std::cos(from)),
        yb = b.add_coordinate("yB", std::sin(from)), th4 = b.add_coordinate("theta4", from);
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
                                             "{type: expression, f: \"") + law + "\"}}\ntime: {start: 0, end: " +
                                     std::to_string(t_end) + ", steps: 4}\n",
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
// solutions stay within the tolerance of the closed form. On finer steps the cubic predictor errs by about 1e-11 m per step, so that most steps are
// accepted without a Newton step (predict()'s error budget brings one when the carried errors add up to the
// tolerance).
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
  const Index previous = iterations(Predictor::kPrevious, false, 720), secant = iterations(Predictor::kSecant, false, 720),
              parabolic = iterations(Predictor::kParabolic, false, 720);
  EXPECT_LT(parabolic, secant);
  EXPECT_LT(parabolic, previous);
  const Index linear = iterations(Predictor::kLinear, true, 720), quadratic = iterations(Predictor::kQuadratic, true, 720),
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
  std::printf("Newton iterations over 720 steps: previous %ld, secant %ld, parabolic %ld; linear %ld, quadratic %ld, "
              "cubic %ld; q̇ only: linear %ld, hermite %ld; over 2880 steps: quadratic %ld, cubic %ld, hermite %ld\n",
              static_cast<long>(previous), static_cast<long>(secant), static_cast<long>(parabolic),
              static_cast<long>(linear), static_cast<long>(quadratic), static_cast<long>(cubic),
              static_cast<long>(linear_v), static_cast<long>(hermite), static_cast<long>(fine_quadratic),
              static_cast<long>(fine_cubic), static_cast<long>(fine_hermite));
}

// The hermite predictor is the cubic through the current row (position and velocity) and the two rows before: a
// coordinate driven by a cubic law is predicted exactly once three rows are known, and its error estimate (the next, quartic term) is then zero, so those steps take no Newton iteration; a quartic law is
// not (the estimate sees the quartic term).
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
    run_sweep(m, opt, ws, [&](const StepView&) {
      per_row.push_back(ws.counters.newton_iterations - before);
      before = ws.counters.newton_iterations;
      return true;
    }, &sum);
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
  EXPECT_THROW(run_sweep(m, opt, ws, nullptr, nullptr), Error);
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
        run_sweep(m, opt, ws, [&](const StepView&) { return ++rows, true; }, nullptr);
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
    EXPECT_EQ(refusal([](SweepOptions& o) { o.max_subdivisions = -1; }),
              "SweepOptions: max_subdivisions must be >= 0");
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
        run_sweep(m, opt, ws, [&](const StepView&) { return ++rows, true; }, &sum);
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
  EXPECT_EQ(run_sweep(m, opt, ws, [&](const StepView&) { return ++rows < 5; }, &sum), SolveStatus::kCancelled);
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
  std::vector<SweepWarning> w = {at(3), at(4), at(5),             // consecutive: one stretch
                                 at(9), at(11), at(12), at(15),   // 1 and 2 quiet rows between: one stretch
                                 at(19, "ill_conditioned"),       // another kind, in its place
                                 at(19), at(22.5), at(23), at(40)};  // a sub-step alone, 3 quiet rows: new stretches
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

// ---- parallel drive steps -------------------------------------------------------------------------------------

// The same sweep in order and on `threads` threads in chunks of `chunk` steps.
struct InOrderAndParallel {
  test::Trace seq, par;
  SweepSummary ss, ps;
  SolveStatus seq_status, par_status;
};
InOrderAndParallel sweep_both(const Model& m, SweepOptions opt, int threads, Index chunk) {
  InOrderAndParallel r;
  r.seq_status = test::sweep(m, opt, &r.seq, &r.ss);
  opt.threads = threads;
  opt.chunk_steps = chunk;
  r.par_status = test::sweep(m, opt, &r.par, &r.ps);
  return r;
}

// The parallel sweep delivers the same rows as the sequential one, to the solver tolerance, whatever the thread
// count and chunk size; every chunk is accepted on this regular motion.
TEST(ParallelSweep, EqualsTheSequentialSweepForAnyThreadCount) {
  Model m = test::nfourbar_model(40, M_PI / 4, M_PI / 2);  // a quarter turn, away from singular positions
  SweepOptions opt;
  opt.steps = 300;
  test::Trace seq;
  SweepSummary ss;
  ASSERT_EQ(test::sweep(m, opt, &seq, &ss), SolveStatus::kSuccess) << ss.message;
  EXPECT_EQ(ss.threads, 1);
  EXPECT_EQ(ss.parallel_chunks, 0);
  for (int threads : {2, 3, 4}) {
    for (Index chunk : {Index{1}, Index{7}, Index{64}}) {
      opt.threads = threads;
      opt.chunk_steps = chunk;
      test::Trace par;
      SweepSummary ps;
      ASSERT_EQ(test::sweep(m, opt, &par, &ps), SolveStatus::kSuccess) << ps.message;
      EXPECT_EQ(ps.threads, threads);
      EXPECT_EQ(ps.parallel_chunks, (opt.steps + chunk - 1) / chunk) << threads << " threads, chunks of " << chunk;
      EXPECT_EQ(ps.steps_completed, opt.steps + 1);
      // positions to 1e-10 × scale each; velocities and accelerations inherit it (|q̇| ~ 1.6, |q̈| ~ 2.5)
      EXPECT_LT(test::max_difference(seq, par, 0), 1e-9) << threads << " threads, chunks of " << chunk;
      EXPECT_LT(test::max_difference(seq, par, 1), 1e-8) << threads << " threads, chunks of " << chunk;
      EXPECT_LT(test::max_difference(seq, par, 2), 1e-8) << threads << " threads, chunks of " << chunk;
      EXPECT_TRUE(ps.warnings.empty());
      EXPECT_EQ(ps.counters.velocity_solves, ss.counters.velocity_solves)
          << "each chunk but the last solves one step more, the seam its successor's first row is checked against, "
             "for its position only";
    }
  }
}

// A parallel sweep writes its held rows into recycled buffers and leaves them in the workspace for the next one
// (Workspace::spare_rows): a second sweep with the same workspace, reusing them, still delivers the sequential
// sweep's rows; buffers of another size left there are dropped, not used.
TEST(ParallelSweep, RowBuffersAreRecycledAndKeptInTheWorkspace) {
  Model m = test::nfourbar_model(40, M_PI / 4, M_PI / 2);
  const Index n = m.num_coordinates();
  SweepOptions opt;
  opt.steps = 200;
  test::Trace seq;
  ASSERT_EQ(test::sweep(m, opt, &seq), SolveStatus::kSuccess);
  opt.threads = 2;
  opt.chunk_steps = 16;
  Workspace ws(m);
  ws.spare_rows.emplace_back(Eigen::VectorXd::Constant(3, 7.0));  // not a row of this model
  for (int run = 0; run < 2; ++run) {
    ws.q = m.initial_positions();
    test::Trace par;
    SweepSummary ps;
    ASSERT_EQ(test::sweep(m, opt, &par, &ps, &ws), SolveStatus::kSuccess) << ps.message;
    EXPECT_EQ(ps.parallel_chunks, 13) << "run " << run;
    EXPECT_LT(test::max_difference(seq, par, 0), 1e-9) << "run " << run;
    EXPECT_LT(test::max_difference(seq, par, 1), 1e-8) << "run " << run;
    EXPECT_LT(test::max_difference(seq, par, 2), 1e-8) << "run " << run;
    // every delivered row's q, q̇, q̈ went back to the pool: at least one chunk's (16 rows × 3), never more
    // than the bound, all of the model's size
    EXPECT_GE(ws.spare_rows.size(), 48u) << "run " << run;
    EXPECT_LE(static_cast<double>(ws.spare_rows.size()) * 8.0 * static_cast<double>(n), Workspace::kSpareRowBytes);
    for (const Eigen::VectorXd& v : ws.spare_rows) ASSERT_EQ(v.size(), n) << "run " << run;
  }
}

// Through singular positions (a full turn of the N four-bar: the cranks are horizontal twice, where the dof jumps),
// the result must still be the sequential sweep's, however the seeds behave there.
TEST(ParallelSweep, ThroughSingularPositionsMatchesTheSequentialSweep) {
  Model m = test::nfourbar_model(10, 0.1, 2 * M_PI);
  SweepOptions opt;
  opt.steps = 400;
  const InOrderAndParallel r = sweep_both(m, opt, 2, 25);
  const test::Trace &seq = r.seq, &par = r.par;
  const SweepSummary& ps = r.ps;
  ASSERT_EQ(r.seq_status, SolveStatus::kSuccess) << r.ss.message;
  ASSERT_EQ(r.par_status, SolveStatus::kSuccess) << ps.message;
  EXPECT_GT(ps.parallel_chunks, 0);
  EXPECT_LT(test::max_difference(seq, par, 0), 1e-8);
  // near the singular positions Φq is ill-conditioned (rcond ~1e-5 a step away), which amplifies the 1e-10
  // differences of q into q̇ and q̈
  EXPECT_LT(test::max_difference(seq, par, 1), 1e-5);
  EXPECT_LT(test::max_difference(seq, par, 2), 1e-3);
  // and both stay on the parallelogram branch
  for (std::size_t k = 0; k < par.t.size(); ++k) {
    const double th = par.q[k](22);
    for (Index i = 0; i <= 10; ++i) EXPECT_NEAR(par.q[k](2 * i + 1), std::sin(th), 1e-8) << "row " << k;
  }
}

// A parallel sweep that nobody reads row by row (no callback: a sweep for its summary and its last state) keeps
// only the rows it reads again itself, each chunk's first and last, and still reports what a read sweep reports:
// the same warnings at the same times (they come from every row's sign of det Φq, through singular positions
// here), the same solves, and the sequential sweep's last state in the workspace.
TEST(ParallelSweep, WithoutACallbackOnlyEachChunksFirstAndLastRowsAreKept) {
  Model m = test::nfourbar_model(10, 0.1, 2 * M_PI);
  SweepOptions opt;
  opt.steps = 400;
  const InOrderAndParallel r = sweep_both(m, opt, 2, 50);
  ASSERT_EQ(r.par_status, SolveStatus::kSuccess) << r.ps.message;
  ASSERT_FALSE(r.ps.warnings.empty()) << "the full turn passes singular positions";
  opt.threads = 2;
  opt.chunk_steps = 50;
  Workspace ws(m);
  SweepSummary sum;
  ASSERT_EQ(run_sweep(m, opt, ws, nullptr, &sum), SolveStatus::kSuccess) << sum.message;
  EXPECT_EQ(sum.parallel_chunks, 8);
  EXPECT_EQ(sum.steps_completed, opt.steps + 1);
  ASSERT_EQ(sum.warnings.size(), r.ps.warnings.size());
  for (std::size_t i = 0; i < sum.warnings.size(); ++i) {
    EXPECT_EQ(sum.warnings[i].kind, r.ps.warnings[i].kind) << i;
    EXPECT_EQ(sum.warnings[i].t, r.ps.warnings[i].t) << i;
  }
  EXPECT_EQ(sum.counters.velocity_solves, r.ps.counters.velocity_solves);
  EXPECT_LT((ws.q - r.seq.q.back()).lpNorm<Eigen::Infinity>(), 1e-8);
  EXPECT_LT((ws.qd - r.seq.qd.back()).lpNorm<Eigen::Infinity>(), 1e-5);
  EXPECT_LT((ws.qdd - r.seq.qdd.back()).lpNorm<Eigen::Infinity>(), 1e-3);
  // q, q̇, q̈ of two rows per chunk went through the pool; a read sweep returns all 3 × 50 of a chunk's at least
  EXPECT_LE(ws.spare_rows.size(), 2u * 3u * 8u);
  Workspace read(m);
  test::Trace tr;
  ASSERT_EQ(test::sweep(m, opt, &tr, nullptr, &read), SolveStatus::kSuccess);
  EXPECT_GE(read.spare_rows.size(), 3u * 50u);
}

// Rows too wide for chunks worth their seeds: where the rows held for delivery leave room for fewer than 8 steps
// per chunk and thread, the sweep runs on as many threads as have room for 8, or in order, and says why (10⁶
// scissor stages with q, q̇, q̈ ran 100 chunks of one row and held 12 GB); with room for 8, in chunks of 8; a sweep
// without a callback holds two rows per chunk and keeps its usual chunks.
TEST(ParallelSweep, RowsTooWideForChunksOfEightStepsRunOnFewerThreadsOrInOrder) {
  Model m = test::nfourbar_model(100, M_PI / 4, M_PI / 2);
  const double row_bytes = 8.0 * static_cast<double>(3 * m.num_coordinates() + 1);  // q, q̇, q̈ and the time
  SweepOptions opt;
  opt.steps = 300;
  test::Trace seq;
  ASSERT_EQ(test::sweep(m, opt, &seq), SolveStatus::kSuccess);
  struct Run {
    test::Trace tr;
    SweepSummary sum;
  };
  // on `threads` threads with room for `rows` rows, expecting it to run on `ran` threads in `chunks` chunks
  auto run = [&](int threads, double rows, int ran, Index chunks) {
    Run r;
    opt.threads = threads;
    opt.row_buffer_bytes = static_cast<std::size_t>(rows * row_bytes);
    EXPECT_EQ(test::sweep(m, opt, &r.tr, &r.sum), SolveStatus::kSuccess) << r.sum.message;
    EXPECT_EQ(r.sum.threads, ran) << threads << " threads, " << rows << " rows";
    EXPECT_EQ(r.sum.parallel_chunks, chunks) << threads << " threads, " << rows << " rows";
    EXPECT_LT(test::max_difference(seq, r.tr, 0), 1e-9) << threads << " threads, " << rows << " rows";
    return r;
  };
  const Run s7 = run(2, 15.5, 1, 0);  // 7 rows per chunk and thread: in order
  ASSERT_EQ(s7.sum.warnings.size(), 1u);
  EXPECT_EQ(s7.sum.warnings[0].kind, "threads_reduced");
  EXPECT_EQ(s7.sum.warnings[0].t, 0.0);
  EXPECT_HAS(s7.sum.warnings[0].message, "run in order, not in parallel chunks on 2 threads");
  EXPECT_HAS(s7.sum.warnings[0].message,
             "hold 15 rows: chunks of 8 steps, the fewest that pay for a chunk's seed, for no more than one thread");
  EXPECT_HAS(s7.sum.warnings[0].message, "row_buffer_bytes");
  EXPECT_EQ(test::max_difference(seq, s7.tr, 0), 0.0);  // the sequential sweep itself
  EXPECT_EQ(test::max_difference(seq, s7.tr, 2), 0.0);

  EXPECT_TRUE(run(2, 17.5, 2, 38).sum.warnings.empty());  // 8 rows per chunk and thread: ⌈300 / 8⌉ chunks

  const Run s4 = run(4, 17.5, 2, 38);  // on 4 threads, room for 17 rows: chunks of 8 on 2 of them
  ASSERT_EQ(s4.sum.warnings.size(), 1u);
  EXPECT_HAS(s4.sum.warnings[0].message, "run in parallel chunks on 2 threads instead of 4 threads");
  EXPECT_HAS(s4.sum.warnings[0].message,
             "hold 17 rows: chunks of 8 steps, the fewest that pay for a chunk's seed, for only 2 threads");

  opt.threads = 2;
  opt.row_buffer_bytes = static_cast<std::size_t>(7.5 * 2 * row_bytes);
  Workspace ws(m);
  SweepSummary unread;
  ASSERT_EQ(run_sweep(m, opt, ws, nullptr, &unread), SolveStatus::kSuccess) << unread.message;
  EXPECT_EQ(unread.parallel_chunks, 9);  // chunks of max(16, 300 / (4 × 2)) = 37 steps
  EXPECT_TRUE(unread.warnings.empty());

  opt.row_buffer_bytes = 0;
  EXPECT_THROW(run_sweep(m, opt, ws, nullptr, nullptr), Error);
}

// A drive that leaves the reachable range: the parallel sweep reports the same failure, at the same step, as the
// sequential one, after delivering the same rows.
TEST(ParallelSweep, AFailureIsReportedAsInTheSequentialSweep) {
  // slider driven: the crank-slider with L2 = 0.3, L3 = 1 reaches x_B only in [0.7, 1.3]
  ModelBuilder b;
  auto S = Slot::coordinate;
  auto C = Slot::constant;
  Index th = b.add_coordinate("theta2", 0.5), xa = b.add_coordinate("xA", 0.26), ya = b.add_coordinate("yA", 0.14),
        xb = b.add_coordinate("xB", 1.2);
  b.add("crank", PolarSpec{{S(xa), S(ya)}, {C(0), C(0)}, 0.3, S(th)});
  b.add("rod", DistanceSpec{{S(xa), S(ya)}, {S(xb), C(0)}, 1.0});
  b.add_driver("slider", xb, MotionLaw::linear(1.2, 0.3));  // x_B = 1.2 + 0.3 t passes 1.3 at t = 1/3
  Model m = std::move(b).build();
  SweepOptions opt;
  opt.steps = 200;
  test::Trace seq, par;
  SweepSummary ss, ps;
  EXPECT_NE(test::sweep(m, opt, &seq, &ss), SolveStatus::kSuccess);
  opt.threads = 2;
  opt.chunk_steps = 10;
  EXPECT_EQ(test::sweep(m, opt, &par, &ps), ss.status);
  EXPECT_EQ(ps.message, ss.message);
  EXPECT_EQ(ps.failed_step, ss.failed_step);
  EXPECT_EQ(par.t.size(), seq.t.size());
  EXPECT_GT(ps.parallel_chunks, 0);
  EXPECT_LT(test::max_difference(seq, par, 0), 1e-9);
  EXPECT_LT(test::max_difference(seq, par, 1), 1e-6);  // approaching the dead point, q̇ grows as 1/sin
}

// The rows reach on_step on the calling thread, in order, however many threads compute them (the caller of an
// embedding simulator may keep thread-local state there); and a caller that stops the sweep gets exactly the rows
// up to the one it stopped at.
TEST(ParallelSweep, DeliversOnTheCallingThreadInOrderAndStopsWhereTheCallerSays) {
  Model m = test::nfourbar_model(20, M_PI / 4, M_PI / 2);
  SweepOptions opt;
  opt.steps = 240;
  opt.threads = 2;
  opt.chunk_steps = 8;
  const std::thread::id me = std::this_thread::get_id();
  for (Index stop_at : {Index{-1}, Index{0}, Index{5}, Index{8}, Index{9}, Index{100}}) {
    Workspace ws(m);
    std::vector<Index> seen;
    bool foreign_thread = false;
    SweepSummary sum;
    const SolveStatus st = run_sweep(
        m, opt, ws,
        [&](const StepView& v) {
          seen.push_back(v.step);
          foreign_thread = foreign_thread || std::this_thread::get_id() != me;
          return v.step != stop_at;
        },
        &sum);
    EXPECT_FALSE(foreign_thread) << "stop at " << stop_at;
    const Index last = stop_at < 0 ? opt.steps : stop_at;
    ASSERT_EQ(static_cast<Index>(seen.size()), last + 1) << "stop at " << stop_at;
    for (Index k = 0; k <= last; ++k) EXPECT_EQ(seen[static_cast<std::size_t>(k)], k);
    EXPECT_EQ(st, stop_at < 0 ? SolveStatus::kSuccess : SolveStatus::kCancelled) << sum.message;
    EXPECT_EQ(sum.steps_completed, last + 1);
  }
}

// A model large enough to be evaluated in parallel itself (more than 65536 constraints), swept in parallel chunks:
// the evaluation's tasks run inside the chunks' threads without deadlock, and the rows are the sequential ones.
TEST(ParallelSweep, LargeModelsEvaluatedInParallelInsideParallelChunks) {
  Model m = test::nfourbar_model(33000, M_PI / 4, M_PI / 2);
  ASSERT_GT(m.num_equations(), 65536);  // one row per constraint but the angle
  SweepOptions opt;
  opt.steps = 6;
  opt.t_end = 0.01;
  const InOrderAndParallel r = sweep_both(m, opt, 2, 1);
  ASSERT_EQ(r.seq_status, SolveStatus::kSuccess) << r.ss.message;
  ASSERT_EQ(r.par_status, SolveStatus::kSuccess) << r.ps.message;
  EXPECT_EQ(r.ps.parallel_chunks, 6);
  EXPECT_LT(test::max_difference(r.seq, r.par, 0), 1e-9 * 33000);  // lengths up to 3.3·10⁴ m
  EXPECT_LT(test::max_difference(r.seq, r.par, 1), 1e-7);
}

// A step callback that throws ends a parallel sweep with its exception, whatever the other threads were doing (none
// is left waiting for the thrower), and the same model sweeps again afterwards.
TEST(ParallelSweep, AnExceptionFromTheCallbackPropagates) {
  Model m = test::nfourbar_model(20, M_PI / 4, M_PI / 2);
  SweepOptions opt;
  opt.steps = 400;
  opt.threads = 2;
  opt.chunk_steps = 5;
  for (Index throw_at : {Index{0}, Index{3}, Index{57}, Index{400}}) {
    Workspace ws(m);
    Index seen = 0;
    EXPECT_THROW(run_sweep(m, opt, ws,
                           [&](const StepView& v) {
                             if (v.step == throw_at) throw std::runtime_error("stop here");
                             ++seen;
                             return true;
                           },
                           nullptr),
                 std::runtime_error);
    EXPECT_EQ(seen, throw_at);
  }
  test::Trace tr;
  EXPECT_EQ(test::sweep(m, opt, &tr), SolveStatus::kSuccess);
  EXPECT_EQ(static_cast<Index>(tr.t.size()), opt.steps + 1);
}

// threads = 0 runs on all cores, as many as the memory allows: below the room for two more workspaces the sweep runs
// in order, with a warning that says why; with room, on every core; an explicit thread count is kept whatever the
// budget. The rows are the same in every case.
TEST(ParallelSweep, AllCoresAsManyAsTheMemoryAllows) {
  Model m = test::nfourbar_model(200, M_PI / 4, M_PI / 2);
  SweepOptions opt;
  opt.steps = 200;
  opt.threads = 0;
  opt.memory_budget = 1;  // far too little for a second workspace
  test::Trace tight, roomy, forced;
  SweepSummary st, sr, sf;
  ASSERT_EQ(test::sweep(m, opt, &tight, &st), SolveStatus::kSuccess) << st.message;
  const int cores = tbb::info::default_concurrency();
  auto reduced = [](const SweepSummary& s) {
    for (const SweepWarning& w : s.warnings)
      if (w.kind == "threads_reduced") return w.message;
    return std::string();
  };
  if (cores > 1) {
    EXPECT_EQ(st.threads, 1);
    EXPECT_EQ(st.parallel_chunks, 0);
    EXPECT_NE(reduced(st).find("instead of " + std::to_string(cores)), std::string::npos) << reduced(st);
  }
  opt.memory_budget = std::size_t{1} << 40;
  ASSERT_EQ(test::sweep(m, opt, &roomy, &sr), SolveStatus::kSuccess) << sr.message;
  EXPECT_EQ(reduced(sr), "");
  if (cores > 1) {
    EXPECT_EQ(sr.threads, cores);
  }
  opt.threads = 2;
  opt.memory_budget = 1;
  ASSERT_EQ(test::sweep(m, opt, &forced, &sf), SolveStatus::kSuccess) << sf.message;
  EXPECT_EQ(sf.threads, 2);
  EXPECT_EQ(reduced(sf), "");
  EXPECT_LT(test::max_difference(tight, roomy, 0), 1e-9);
  EXPECT_LT(test::max_difference(tight, forced, 0), 1e-9);
}

}  // namespace
}  // namespace phiq
