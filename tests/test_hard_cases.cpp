// Hard cases stay numerically stable (issue 5): badly scaled models — millimetres and radians mixed, lengths from
// 10^-3 to 10^3 m in one mechanism (models/hard/) — and long chains (nfourbar N = 10^3 over 1000 steps; 10^5 in
// bench_long_chain.cpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace {

using namespace phiq;

constexpr double kTol = 1e-10;  // the scenes' Newton tolerance (NewtonOptions / solver.tolerance default)

// Every row of a sweep: q, q̇, q̈ and the largest scaled residual max_i |Φ_i| / scale_i of the delivered Φ.
struct HardRows {
  test::Trace tr;
  std::vector<double> residual;
  SweepSummary sum;
  SolveStatus status = SolveStatus::kNotConverged;
};

// Sweeps `sc` with its own settings on `threads` threads, asking for Φ at every row.
HardRows sweep_hard_scene(const Scene& sc, int threads) {
  SweepOptions opt = sc.sweep;
  opt.threads = threads;
  if (opt.chunk_steps == 0) opt.chunk_steps = opt.steps;  // one chunk, in order: the rows' own work is counted
  opt.residuals = true;
  HardRows r;
  Workspace ws(*sc.model);
  r.status = run_sweep(
      *sc.model, opt, ws,
      [&](const StepView& s) {
        r.tr.t.push_back(s.t);
        r.tr.q.push_back(s.q);
        if (s.qd) r.tr.qd.push_back(*s.qd);
        if (s.qdd) r.tr.qdd.push_back(*s.qdd);
        r.residual.push_back(s.phi ? scaled_residual(*sc.model, *s.phi) : INFINITY);
        return true;
      },
      &r.sum);
  return r;
}

// No NaN or infinity anywhere, every row's every constraint within the tolerance, every time point delivered.
void expect_sound(const HardRows& r, const Scene& sc, const std::string& what) {
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << what << ": " << r.sum.message;
  ASSERT_EQ(r.tr.t.size(), static_cast<std::size_t>(sc.sweep.steps + 1)) << what;
  ASSERT_EQ(r.tr.qd.size(), r.tr.t.size()) << what;
  ASSERT_EQ(r.tr.qdd.size(), r.tr.t.size()) << what;
  for (std::size_t k = 0; k < r.tr.t.size(); ++k) {
    EXPECT_TRUE(r.tr.q[k].allFinite() && r.tr.qd[k].allFinite() && r.tr.qdd[k].allFinite()) << what << " row " << k;
    EXPECT_LE(r.residual[k], kTol) << what << " row " << k;  // NaN fails too
  }
}

bool is_angle(const std::string& name) { return name == "theta2" || name == "psi3" || name == "phi4"; }

// The four-bar in millimetres (models/hard/fourbar_mm.yaml) and in metres (fourbar_m.yaml): natural coordinates
// and angles mixed, so the mm model's Jacobian has length columns 1000× the angle columns. Each length row and
// coordinate is held relative to its own link (ToleranceScales), so the scales of the mm model are exactly 1000×
// those of the m model and every decision of the solver (convergence, modified-Newton refreshes) is the same: in
// order, the two runs take the same iterations and agree to rounding. Bounds, relative to the largest link
// (1.2 m) for lengths and to 1 rad for angles (ω = 1 rad/s, so velocities and accelerations have the same scale):
//  - in order: 1e-12 (measured 1.3e-15: rounding only; a decision taken differently would show as ~1e-10);
//  - on 2 threads: 1e-9, ten times the tolerance: parallel chunks start from seeds and may stop a Newton solve at a
//    different point within the tolerance (measured 1.3e-15 here; 3.6e-12 once through `phiq run`).
TEST(HardCases, MillimetresAgreeWithMetres) {
  const Scene m = load_scene(test::model_path("hard/fourbar_m.yaml"));
  const Scene mm = load_scene(test::model_path("hard/fourbar_mm.yaml"));
  const Model& a = *m.model;
  const Model& b = *mm.model;
  ASSERT_EQ(a.coordinate_names(), b.coordinate_names());
  ASSERT_EQ(a.num_equations(), b.num_equations());
  const Index n = a.num_coordinates();
  std::vector<double> unit(static_cast<std::size_t>(n));  // metres (or radians) per model unit of the mm scene
  for (Index j = 0; j < n; ++j) {
    const std::string& name = a.coordinate_names()[static_cast<std::size_t>(j)];
    ASSERT_EQ(a.coordinate_unit(j), is_angle(name) ? Unit::kAngle : Unit::kLength) << name;
    ASSERT_EQ(b.coordinate_unit(j), a.coordinate_unit(j)) << name;
    unit[static_cast<std::size_t>(j)] = is_angle(name) ? 1.0 : 1e-3;
    // scales: the coordinate's shortest link, 1000× in millimetres
    EXPECT_DOUBLE_EQ(b.tolerance_scales().coordinate_scale(j),
                     (is_angle(name) ? 1.0 : 1000.0) * a.tolerance_scales().coordinate_scale(j))
        << name;
  }
  for (Index i = 0; i < a.num_equations(); ++i)
    EXPECT_DOUBLE_EQ(b.tolerance_scales().row_scale(i),
                     (a.row_unit(i) == Unit::kLength ? 1000.0 : 1.0) * a.tolerance_scales().row_scale(i))
        << a.row_name(i);
  EXPECT_DOUBLE_EQ(a.tolerance_scales().row_scale(0), 0.4);  // crank[0]: its own length, not the model's 1.2 m

  for (int threads : {1, 2}) {
    const std::string what = threads == 1 ? "in order" : "on 2 threads";
    const HardRows ra = sweep_hard_scene(m, threads), rb = sweep_hard_scene(mm, threads);
    expect_sound(ra, m, "m " + what);
    expect_sound(rb, mm, "mm " + what);
    if (HasFatalFailure()) return;
    if (threads == 1) {  // scale-invariant decisions
      EXPECT_EQ(ra.sum.counters.newton_iterations, rb.sum.counters.newton_iterations);
      EXPECT_EQ(ra.sum.counters.factorizations, rb.sum.counters.factorizations);
    }
    const double bound = threads == 1 ? 1e-12 : 1e-9;
    double worst[3] = {0, 0, 0};
    ASSERT_EQ(ra.tr.t, rb.tr.t);
    for (std::size_t k = 0; k < ra.tr.t.size(); ++k)
      for (Index j = 0; j < n; ++j) {
        const double s = unit[static_cast<std::size_t>(j)], ref = s == 1.0 ? 1.0 : 1.2;
        worst[0] = std::max(worst[0], std::fabs(ra.tr.q[k](j) - s * rb.tr.q[k](j)) / ref);
        worst[1] = std::max(worst[1], std::fabs(ra.tr.qd[k](j) - s * rb.tr.qd[k](j)) / ref);
        worst[2] = std::max(worst[2], std::fabs(ra.tr.qdd[k](j) - s * rb.tr.qdd[k](j)) / ref);
      }
    std::printf("fourbar mm vs m, %s: positions %.3g, velocities %.3g, accelerations %.3g\n", what.c_str(), worst[0],
                worst[1], worst[2]);
    EXPECT_LE(worst[0], bound) << what << ": positions";
    EXPECT_LE(worst[1], bound) << what << ": velocities";
    EXPECT_LE(worst[2], bound) << what << ": accelerations";
  }
}

// models/hard/crank_slider_span.yaml: a 1 mm crank and a 1 km rod (lengths from 10^-3 to 10^3 m), θ = 2t, against
// the closed form x_B = r cos θ + √(L² − r² sin² θ) and its derivatives. With one tolerance scale for the whole
// model (its largest length, 1000 m) the crank's rows were held to 1e-7 m, a ten-thousandth of the crank:
// predicted positions were accepted without a Newton step, and the crank tip was up to 1e-4 r off (measured 1.0e-7 m
// in order, 5.3e-8 m on 2 threads). Each row is now held relative to its own link: the crank tip to 1e-10 r, the
// slider (on the 1 km rod only) to 1e-10 L.
TEST(HardCases, LengthsFromMillimetresToKilometres) {
  const Scene sc = load_scene(test::model_path("hard/crank_slider_span.yaml"));
  const Model& m = *sc.model;
  const double r = 1e-3, L = 1e3, w = 2.0;
  const Index th = m.coordinate_index("theta2"), xa = m.coordinate_index("xA"), ya = m.coordinate_index("yA"),
              xb = m.coordinate_index("xB");
  const ToleranceScales& s = m.tolerance_scales();
  EXPECT_EQ(m.length_scale(), L);
  EXPECT_EQ(s.coordinate_scale(th), 1.0);
  EXPECT_EQ(s.coordinate_scale(xa), r);  // the shortest link at A: the crank
  EXPECT_EQ(s.coordinate_scale(ya), r);
  EXPECT_EQ(s.coordinate_scale(xb), L);  // only the rod reaches B
  for (Index i = 0; i < m.num_equations(); ++i) {
    const std::string& c = m.constraints()[static_cast<std::size_t>(m.constraint_of_row(i))].name;
    EXPECT_EQ(s.row_scale(i), c == "crank" ? r : c == "rod" ? L : 1.0) << m.row_name(i);
  }

  for (int threads : {1, 2}) {
    const std::string what = threads == 1 ? "in order" : "on 2 threads";
    const HardRows run = sweep_hard_scene(sc, threads);
    expect_sound(run, sc, what);
    if (HasFatalFailure()) return;
    double e_a = 0, e_b = 0, e_v = 0, e_acc = 0;
    for (std::size_t k = 0; k < run.tr.t.size(); ++k) {
      const double t = run.tr.t[k], q = w * t, sn = std::sin(q), cs = std::cos(q);
      const double d = std::sqrt(L * L - r * r * sn * sn);
      const double x = r * cs + d;
      const double v = -r * w * sn - r * r * w * sn * cs / d;
      const double a = -r * w * w * cs - r * r * w * w * (cs * cs - sn * sn) / d -
                       std::pow(r, 4) * w * w * sn * sn * cs * cs / (d * d * d);
      const Eigen::VectorXd &Q = run.tr.q[k], &V = run.tr.qd[k], &A = run.tr.qdd[k];
      EXPECT_NEAR(Q(th), q, 1e-15 * std::max(1.0, q)) << "driven exactly";
      e_a = std::max({e_a, std::fabs(Q(xa) - r * cs), std::fabs(Q(ya) - r * sn)});
      e_b = std::max(e_b, std::fabs(Q(xb) - x));
      e_v = std::max({e_v, std::fabs(V(xa) + r * w * sn), std::fabs(V(ya) - r * w * cs), std::fabs(V(xb) - v)});
      e_acc =
          std::max({e_acc, std::fabs(A(xa) + r * w * w * cs), std::fabs(A(ya) + r * w * w * sn), std::fabs(A(xb) - a)});
    }
    std::printf(
        "crank_slider_span, %s: crank tip %.3g r, slider %.3g m, velocities %.3g r w, accelerations %.3g r w^2\n",
        what.c_str(), e_a / r, e_b, e_v / (r * w), e_acc / (r * w * w));
    // positions: each to the tolerance of its own link (crank tip measured 1e-16 r; slider 7.7e-12 m in order —
    // the assembly, then 1 ulp of 1000 m —, 2.3e-9 m at the first row of a parallel chunk)
    EXPECT_LE(e_a, kTol * r) << what;
    EXPECT_LE(e_b, kTol * L) << what;
    // velocities and accelerations: the linear solves on a Jacobian whose scaled condition is about 1 are exact to
    // rounding (measured 0; 5e-11 relative with one model-wide scale); 1e-9 of the crank's r ω, r ω²
    EXPECT_LE(e_v, 1e-9 * r * w) << what;
    EXPECT_LE(e_acc, 1e-9 * r * w * w) << what;
  }
}

// nfourbar with N = 10^3 four-bars (2 003 coordinates), a quarter turn θ = π/4 … 3π/4 in 1000 steps. The exact
// solution is the parallelogram x_i = i + cos θ, y_i = sin θ (ẋ_i = −θ̇ sin θ, ẏ_i = θ̇ cos θ, ẍ_i = −θ̇² cos θ,
// ÿ_i = −θ̇² sin θ) at every step; each step starts from the previous solutions, so a drift would show as a
// residual or a deviation growing with the steps.
struct ChainRun {
  std::vector<double> residual;   // max_i |Φ_i| / scale_i over all rows, per step (all links 1 m: metres)
  std::vector<double> deviation;  // max over the coordinates of |q − exact|, per step (m, rad)
  double deviation_v = 0.0, deviation_a = 0.0;  // max over all steps and coordinates, velocities and accelerations
  bool finite = true;
  SweepSummary sum;
};

constexpr Index kChainN = 1000, kChainSteps = 1000;

ChainRun long_chain(bool derivatives) {
  const Model m = test::nfourbar_model(kChainN, M_PI / 4, M_PI / 2);
  SweepOptions opt;
  opt.t_begin = 0.0;
  opt.t_end = 1.0;
  opt.steps = kChainSteps;
  opt.chunk_steps = kChainSteps;  // one chunk, in order: the rows' own Newton steps are counted, not chunk seeds
  opt.velocities = opt.accelerations = derivatives;
  opt.residuals = true;
  ChainRun r;
  Workspace ws(m);
  const auto exact = test::nfourbar_exact(m, M_PI / 4, M_PI / 2);
  tools::ClosedFormErrors err(*exact);
  const SolveStatus st = run_sweep(
      m, opt, ws,
      [&](const StepView& s) {
        r.finite = r.finite && s.q.allFinite() && s.phi && s.phi->allFinite() && (!s.qd || s.qd->allFinite()) &&
                   (!s.qdd || s.qdd->allFinite());
        r.residual.push_back(s.phi ? scaled_residual(m, *s.phi) : INFINITY);
        r.deviation.push_back(err.add(s.t, s.q.data(), s.qd ? s.qd->data() : nullptr, s.qdd ? s.qdd->data() : nullptr));
        return true;
      },
      &r.sum);
  r.deviation_v = err.v_error, r.deviation_a = err.a_error;
  EXPECT_EQ(st, SolveStatus::kSuccess) << r.sum.message;
  EXPECT_EQ(r.residual.size(), static_cast<std::size_t>(kChainSteps + 1));
  EXPECT_TRUE(r.finite);
  return r;
}

double max_of(const std::vector<double>& v, std::size_t from, std::size_t to) {
  return *std::max_element(v.begin() + static_cast<std::ptrdiff_t>(from), v.begin() + static_cast<std::ptrdiff_t>(to));
}

// Common to both runs (step 0 is the assembly from the exact placement; the drive steps are 1 … 1000):
//  - every row of every step within the tolerance plus its rounding floor (64 ulps of the coordinates it reads:
//    8.7e-12 m for the far cranks at x ≈ 10^3, ToleranceScales);
//  - no growth trend: the largest residual of the last 100 steps ≤ 10× that of the first 100;
//  - every coordinate within 1e-9 of the parallelogram at every step: 10× the Newton tolerance (each coordinate's
//    estimated error is within 1e-10 × its 1 m links; the exact value itself is rounded at 10^3: 1.1e-13).
void expect_no_drift(const ChainRun& r, const char* what) {
  if (r.residual.size() != static_cast<std::size_t>(kChainSteps + 1)) return;
  const double floor = kTol + ToleranceScales::kUlpFloor * static_cast<double>(kChainN + 1);
  EXPECT_LE(max_of(r.residual, 0, r.residual.size()), floor) << what;
  const double first100 = max_of(r.residual, 1, 101), last100 = max_of(r.residual, kChainSteps - 99, kChainSteps + 1);
  EXPECT_LE(last100, 10.0 * first100) << what << ": first 100 steps " << first100 << ", last 100 " << last100;
  for (std::size_t k = 0; k < r.deviation.size(); ++k) EXPECT_LE(r.deviation[k], 1e-9) << what << " step " << k;
  std::printf(
      "%s: residual step 1 %.3g, step %ld %.3g, max of steps 1-100 %.3g, of the last 100 %.3g; deviation "
      "max %.3g, velocities %.3g, accelerations %.3g; %ld Newton iterations, %ld factorisations, %.2f s\n",
      what, r.residual[1], static_cast<long>(kChainSteps), r.residual[kChainSteps], first100, last100,
      max_of(r.deviation, 0, r.deviation.size()), r.deviation_v, r.deviation_a,
      static_cast<long>(r.sum.counters.newton_iterations), static_cast<long>(r.sum.counters.factorizations),
      r.sum.solve_seconds);
}

// Positions, velocities and accelerations (the cubic predictor; Φq factorised at every solution for q̇ and q̈): the
// prediction errs by about 1e-12 m here, so most steps are accepted without a Newton step, each carrying the error
// of the one before plus its own extrapolation's (the error budget, Sweeper::predict() in
// engine/src/sweep/predictors.cpp), and a Newton step comes when that sum reaches the tolerance. So the residual of a
// step lies anywhere below the tolerance (single steps say nothing; the windows of expect_no_drift do), every position
// stays within 2 tolerances of the parallelogram (measured 9.2e-11 m), and there are a few Newton steps, not one per
// step (measured 16 in 1000). Velocities and accelerations: the linear solves along the chain, within 1e-9 of the exact
// θ̇ = π/2 rad/s motion (measured 1.4e-10 and 2.4e-10). A four-bar of a 10⁶ m ground and coupler on a 10⁻⁶ m crank and
// a 1.5·10⁻⁶ m rocker, natural coordinates, placed with B 0.4 rad of rocker off: the coupler's row, held to tol · 10⁶ m
// = 10⁻⁴ m, passes at the placement, which was taken as the first row (the rocker 0.73 rad off the closed form, exit
// 0). The placement is now taken only after a Newton step from it is within the tolerance: every row is as close to the
// closed form as double precision allows (B's x near 10⁶ m is known to an ulp, 1.2·10⁻¹⁰ m, 8·10⁻⁵ rad of the rocker).
// The badly scaled four-bar below (ground and coupler 10⁶ m, crank 10⁻⁶ m, rocker 1.5·10⁻⁶ m; crank angle t):
// how far the rocker's angle `phi` (of B − C) is from the closed form about C, free of cancellation:
// B'·A' = (L4² + |A'|² − L3²)/2 with A' = A − C and L1 = L3; the nearer of the two branches.
double badly_scaled_rocker_error(double t, double phi) {
  const double L1 = 1e6, L2 = 1e-6, L4 = 1.5e-6;
  const double ax = L2 * std::cos(t), ay = L2 * std::sin(t);
  const double k = 0.5 * (L4 * L4 + (-2 * L1 * ax + ax * ax + ay * ay));
  const double px = ax - L1, py = ay, r = std::hypot(px, py), a0 = std::atan2(py, px);
  const double c = std::acos(std::clamp(k / (L4 * r), -1.0, 1.0));
  return std::min(std::fabs(std::remainder(phi - a0 - c, 2 * M_PI)), std::fabs(std::remainder(phi - a0 + c, 2 * M_PI)));
}

TEST(HardCases, BadlyScaledFourBarIsSolvedToWhatDoublesAllowFromItsFirstRow) {
  const Scene sc = parse_scene(R"Y(phiq: 1
parameters: {L1: 1e6, L2: 1e-6, L3: 1e6, L4: 1.5e-6}
coordinates: {xA: 1e-6, yA: 0.0, xB: 1e6, yB: 1.5e-6, theta2: 0.0}
points: {O: [0, 0], A: [xA, yA], B: [xB, yB], C: [L1, 0]}
constraints:
  - {name: crank, type: distance, points: [O, A], length: L2}
  - {name: coupler, type: distance, points: [A, B], length: L3}
  - {name: rocker, type: distance, points: [C, B], length: L4}
  - {name: crank_angle, type: segment_angle, segment: [O, A], angle: theta2}
drivers:
  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 1}}
time: {start: 0, end: 2*pi, steps: 72}
)Y",
                               "badly_scaled.yaml");
  const Index xB = sc.model->coordinate_index("xB"), yB = sc.model->coordinate_index("yB");
  Workspace ws(*sc.model);
  SweepSummary sum;
  double worst = 0.0;
  const SolveStatus st = run_sweep(
      *sc.model, sc.sweep, ws,
      [&](const StepView& v) {
        worst = std::max(worst, badly_scaled_rocker_error(v.t, std::atan2(v.q[yB], v.q[xB] - 1e6)));
        return true;
      },
      &sum);
  ASSERT_EQ(st, SolveStatus::kSuccess) << sum.message;
  // B's x near 10⁶ m to an ulp (2⁻³³ m) from the coupler's row, C fixed: two ulps over the rocker bound the angle, as
  // on pins below (measured 8·10⁻⁵ rad; 1.15·10⁻⁴ since rows at their rounding are left out of Newton's steps)
  EXPECT_LE(worst, 2 * std::ldexp(1.0, -33) / 1.5e-6);
}

// The same four-bar with the coupler a body on two pins (x3, y3, ψ3; each pin's arm 5·10⁵ m) and in relative
// coordinates (a loop of angles). A pin's row is held to tol · 5·10⁵ m = 5·10⁻⁵ m, so a residual of 10⁻⁷ m there
// (10⁻¹³ of its scale) passes, and it puts the rocker 0.1 rad off; the merit ½ Σ (Φ_i / scale_i)² is meanwhile the
// rocker row's rounding (10⁻¹⁰ m of 1.5·10⁻⁶ m), so a Newton step that corrects that error did not halve it and the
// solve stopped there as at its rounding level (exit 0, the rocker 0.107 rad from the closed form at t = 0, "326
// row(s) known only to 5.96e+08 tolerances"). Newton now goes on where the next step from its trial point is a
// quarter of the step or less (the step corrected an error). What doubles allow: B's x near 10⁶ m is held to its
// ulp, 2⁻³³ m = 1.16·10⁻¹⁰ m; with Φ's rounding of a few such ulps amplified by Φq⁻¹ (about 1 here: B moves along
// the rocker's circle by about what the coupler's row is off), B is known to a couple of ulps, i.e. the rocker's
// angle to 2 · 1.16·10⁻¹⁰ / 1.5·10⁻⁶ = 1.6·10⁻⁴ rad (measured 6.4·10⁻⁵ pinned, 4.9·10⁻⁵ relative; the pinned form was
// 0.107 before, the relative 1.7·10⁻⁴). The summary says how well in metres (or radians), at the coordinate.
TEST(HardCases, BadlyScaledFourBarOnPinsAndInLoopAnglesIsSolvedToWhatDoublesAllow) {
  const std::string parameters = "phiq: 1\nparameters: {L1: 1e6, L2: 1e-6, L3: 1e6, L4: 1.5e-6}\n";
  const std::string drive = R"Y(drivers:
  - {name: motor, coordinate: DRIVEN, law: {type: linear, initial: 0, rate: 1}}
time: {start: 0, end: 2*pi, steps: 360}
)Y";
  auto driven = [&](const std::string& name) {
    std::string d = drive;
    d.replace(d.find("DRIVEN"), 6, name);
    return d;
  };
  const Scene pinned = parse_scene(
      parameters +
          R"Y(coordinates: {theta2: 0.0, xA: 1e-6, yA: 0.0, x3: 0.5e6, y3: 0.5e-6, psi3: 1e-12, xB: 1e6, yB: 1.1e-6}
points: {O: [0, 0], A: [xA, yA], B: [xB, yB], C: [L1, 0]}
bodies: {coupler: [x3, y3, psi3]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}
  - {name: A, type: revolute, between: [{body: coupler, at: [-L3/2, 0]}, {point: A}]}
  - {name: B, type: revolute, between: [{body: coupler, at: [L3/2, 0]}, {point: B}]}
  - {name: rocker, type: distance, points: [C, B], length: L4}
)Y" + driven("theta2"),
      "pinned.yaml");
  const Scene loop = parse_scene(parameters + R"Y(coordinates: {psi2: 0.0, psi3: 1e-12, psi4: -2.3}
constraints:
  - name: loop
    type: loop
    links:
      - {length: L2, angles: [psi2]}
      - {length: L3, angles: [psi2, psi3]}
      - {length: L4, angles: [psi2, psi3, psi4]}
    closure: [L1, 0]
)Y" + driven("psi2"),
                                 "loop.yaml");
  const double ulp = std::nextafter(1e6, 2e6) - 1e6;  // 2⁻³³ m
  ASSERT_DOUBLE_EQ(ulp, std::ldexp(1.0, -33));
  const double allowed = 2 * ulp / 1.5e-6;
  for (const Scene* sc : {&pinned, &loop}) {
    const Model& m = *sc->model;
    const bool pins = sc == &pinned;
    const Index a = m.coordinate_index(pins ? "xB" : "psi2"), b = m.coordinate_index(pins ? "yB" : "psi3");
    const Index c = pins ? -1 : m.coordinate_index("psi4");
    Workspace ws(m);
    SweepSummary sum;
    double worst = 0.0, worst_t = 0.0;
    const SolveStatus st = run_sweep(
        m, sc->sweep, ws,
        [&](const StepView& v) {
          // the rocker's angle: of B − C, or the loop's last link (from B to C) turned by π
          const double phi = pins ? std::atan2(v.q[b], v.q[a] - 1e6) : v.q[a] + v.q[b] + v.q[c] + M_PI;
          const double e = badly_scaled_rocker_error(v.t, phi);
          if (e > worst) worst = e, worst_t = v.t;
          return true;
        },
        &sum);
    ASSERT_EQ(st, SolveStatus::kSuccess) << sum.message;
    EXPECT_LE(worst, allowed) << (pins ? "pinned" : "loop") << " at t = " << worst_t;
    // every estimate of a row known only to its rounding level names its coordinate and says it in its own unit
    const RowClassAccuracy& r = sum.accuracy.rounding_level;
    if (r.rows > 0) {
      ASSERT_FALSE(r.worst_coordinate.empty());
      EXPECT_EQ(r.worst_unit, m.coordinate_unit(m.coordinate_index(r.worst_coordinate)));
      // of the order of what the rocker's angle is off, as a length at B (its 1.5·10⁻⁶ m arm) or an angle
      // (measured ±1.1e-10 m at yB pinned, ±1.7e-4 rad at psi4 in the loop, for 6.4e-5 and 4.9e-5 rad)
      const double arm = r.worst_unit == Unit::kLength ? 1.5e-6 : 1.0;
      EXPECT_GE(r.worst_known_to, 0.1 * worst * arm) << r.worst_coordinate;
      EXPECT_LE(r.worst_known_to, 10 * allowed * arm) << r.worst_coordinate;
    }
    for (const SweepWarning& w : sum.warnings)
      if (w.kind == "slow_convergence") {
        EXPECT_NE(w.message.find("' known to ±"), std::string::npos) << w.message;
        EXPECT_TRUE(w.message.find(" m, ") != std::string::npos || w.message.find(" rad, ") != std::string::npos)
            << w.message;
      }
  }
}

TEST(HardCases, LongChainDoesNotDrift) {
  const ChainRun r = long_chain(true);
  expect_no_drift(r, "nfourbar 10^3, q v a");
  if (r.residual.size() != static_cast<std::size_t>(kChainSteps + 1)) return;
  EXPECT_LE(max_of(r.deviation, 0, r.deviation.size()), 2 * kTol);
  EXPECT_GE(r.sum.counters.newton_iterations, 5);
  EXPECT_LE(r.sum.counters.newton_iterations, kChainSteps / 10);
  EXPECT_LE(r.deviation_v, 1e-9);
  EXPECT_LE(r.deviation_a, 1e-9);
}

// Positions only (what the scene asks for when it lists no derivatives; bench_long_chain.cpp at N = 10^5): the
// secant predictor and modified Newton, which stops as soon as the estimated error is within the tolerance, so a
// step's residual lies anywhere between rounding and the tolerance (one step against another says nothing); the
// windows of 100 steps and the deviation at every step do.
TEST(HardCases, LongChainPositionsOnlyDoNotDrift) {
  const ChainRun r = long_chain(false);
  expect_no_drift(r, "nfourbar 10^3, q only");
}

// A scissor lift of 2000 stages asked for a tolerance of 1e-16, below what doubles resolve on it: its joints reach
// 600 m, and Newton's corrections of the top stages are the rounding of Φ amplified along the chain (the same
// happens at the default tolerance from about 10^5 stages, bench/README.md). Newton stops at that rounding level
// instead of refactorising in search of a contraction that cannot come: the sweep succeeds, warns once per stretch
// of such rows, naming the coordinate and how well it is known, costs hardly more factorisations than at the
// default tolerance (1e-10, where no row warns), and its positions, velocities and accelerations are as close to
// the closed form L_k = (0, k sin θ), R_k = (cos θ, k sin θ) as the default's (measured: 1.2e-10 and 1.1e-10 m at the
// top, 600 m up, with the quadratic predictor; 2.1e-10 m at the default with the cubic one, whose rows take one Newton
// step each: the top joints are at their rounding level, about 1.2 tolerances, which a step's error estimate does not
// see).
TEST(HardCases, LongChainBelowItsRoundingLevelStopsThereAndSaysSo) {
  Scene sc = parse_scene(tools::generate_scene(test::generate_options("scissor", 2000, "natural", 0.3, 1.2, 1000)),
                         "scissor.yaml");
  sc.sweep.steps = 20;
  sc.sweep.t_end = 0.02;
  const Model& m = *sc.model;
  const auto& names = m.coordinate_names();
  auto index_of = [&](const std::string& n) {
    return static_cast<Index>(std::find(names.begin(), names.end(), n) - names.begin());
  };
  const Index th = index_of("theta");
  ASSERT_LT(th, m.num_coordinates());
  auto deviation = [&](const HardRows& r) {  // from the closed form, at the bottom, the middle and the top
    double worst = 0.0;
    for (std::size_t k = 0; k < r.tr.t.size(); ++k) {
      const Eigen::VectorXd& q = r.tr.q[k];
      const double s = std::sin(q(th)), c = std::cos(q(th));
      for (Index level : {Index{1}, Index{1000}, Index{2000}}) {
        const std::string l = std::to_string(level);
        worst = std::max({worst, std::fabs(q(index_of("xl" + l))), std::fabs(q(index_of("yl" + l)) - level * s),
                          std::fabs(q(index_of("xr" + l)) - c), std::fabs(q(index_of("yr" + l)) - level * s)});
      }
    }
    return worst;
  };
  // q̇ and q̈ against the closed form's derivatives (θ̇ = 0.9 rad/s, θ̈ = 0), relative to the top joints' speed
  // (2000 · 0.9 · cos θ ≈ 1.7e3 m/s) and acceleration (2000 · 0.81 · sin θ ≈ 480 m/s² at the start)
  auto derivative_deviation = [&](const HardRows& r) {
    double worst = 0.0;
    for (std::size_t k = 0; k < r.tr.qd.size() && k < r.tr.qdd.size(); ++k) {
      const double s = std::sin(r.tr.q[k](th)), c = std::cos(r.tr.q[k](th)), w = r.tr.qd[k](th);
      for (Index level : {Index{1}, Index{1000}, Index{2000}}) {
        const std::string l = std::to_string(level);
        const double kl = static_cast<double>(level);
        worst = std::max({worst, std::fabs(r.tr.qd[k](index_of("yl" + l)) - kl * c * w) / (2000 * 0.9),
                          std::fabs(r.tr.qd[k](index_of("xr" + l)) + s * w) / (2000 * 0.9),
                          std::fabs(r.tr.qdd[k](index_of("yl" + l)) + kl * s * w * w) / (2000 * 0.81),
                          std::fabs(r.tr.qdd[k](index_of("xr" + l)) + c * w * w) / (2000 * 0.81)});
      }
    }
    return worst;
  };

  const HardRows usual = sweep_hard_scene(sc, 1);
  ASSERT_EQ(usual.status, SolveStatus::kSuccess) << usual.sum.message;
  EXPECT_TRUE(usual.sum.warnings.empty());
  sc.sweep.newton.tolerance = 1e-16;
  const HardRows r = sweep_hard_scene(sc, 1);
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.sum.message;
  int rounding = 0;
  for (const SweepWarning& w : r.sum.warnings) {
    EXPECT_EQ(w.kind, "slow_convergence") << w.message;
    if (w.message.find("rounding level") == std::string::npos) continue;
    ++rounding;
    EXPECT_NE(w.message.find("' known to ±"), std::string::npos) << w.message;  // in the coordinate's unit
    EXPECT_NE(w.message.find(" m, which is how well"), std::string::npos) << w.message;
  }
  EXPECT_GE(rounding, 1);
  EXPECT_LE(r.sum.warnings.size(), 10u) << "once per stretch of rows, not at every row";
  // A stop after a rounding-level step keeps the factorisation it started from for q̇ and q̈, and the rows after a
  // stop end their solves at the first step within the level it measured (NewtonOptions::known_to) instead of
  // measuring it again: 21 factorisations and 23 Newton iterations against 21 and 19 at the default tolerance
  // (24 and 30 when every row measured it; 29 factorisations when such rows refactorised at their last point). The
  // derivatives are as accurate as the default's (measured 4.8e-10 and 6.7e-10 of the top joints' speed and
  // acceleration; 6.8e-10 when they refactorised)
  EXPECT_LE(r.sum.counters.factorizations, usual.sum.counters.factorizations + 1);
  EXPECT_LE(r.sum.counters.newton_iterations, usual.sum.counters.newton_iterations + 6);
  EXPECT_LE(deviation(usual), 3e-10);  // measured 0.9–2.1e-10 at one row, 6e-11 or less at the others
  EXPECT_LE(deviation(r), 3e-10);
  EXPECT_LE(derivative_deviation(usual), 1.5e-9);
  EXPECT_LE(derivative_deviation(r), 1.5e-9);

  // From the previous row's position (no extrapolation) every row takes several steps with the factorisation it
  // reuses; the level the rows carry (known_to) is also what such a matrix needs to reach, so it is not refreshed
  // for failing to reach 1 tolerance, which no step can here: 22 factorisations for 21 rows (measured; 29 when
  // the target was 1 tolerance), 80 Newton iterations either way, and positions as close to the closed form.
  {
    const Predictor usual_predictor = sc.sweep.predictor;
    sc.sweep.predictor = Predictor::kPrevious;
    const HardRows p = sweep_hard_scene(sc, 1);
    sc.sweep.predictor = usual_predictor;
    ASSERT_EQ(p.status, SolveStatus::kSuccess) << p.sum.message;
    EXPECT_GE(p.sum.counters.newton_iterations, 3 * sc.sweep.steps) << "several reused steps a row";
    EXPECT_LE(p.sum.counters.factorizations, sc.sweep.steps + 2);
    EXPECT_LE(deviation(p), 3e-10);
  }

  // A rounding level is taken as measured (PositionSummary::rounding_measured, what a sweep carries to its next
  // rows in NewtonOptions::known_to) only from a step that started where a step of the same solve had arrived: a
  // first step is the start's own error as well (from a converged row here, the rounding alone, but a solve
  // cannot tell), and from a start 10⁻⁶ m off, the second step is the rounding.
  {
    Workspace ws(m);
    NewtonOptions o = sc.sweep.newton;
    o.start_error = INFINITY;  // a step from the start, as from a prediction
    // solves the last row of the sweep again from its position moved by `off` m in every coordinate
    auto solve_from = [&](double off) {
      ws.q = r.tr.q.back();
      ws.q.array() += off;
      PositionSummary ps;
      EXPECT_EQ(solve_position(m, r.tr.t.back(), o, ws, &ps), SolveStatus::kSuccess) << ps.message;
      EXPECT_GT(ps.rounding_level, 0.0);
      return ps;
    };
    EXPECT_FALSE(solve_from(0.0).rounding_measured);
    const PositionSummary off = solve_from(1e-6);
    EXPECT_GE(off.iterations, 1);
    EXPECT_TRUE(off.rounding_measured);
    // with the factorisation reused (modified Newton), a stop at the rounding level keeps the contraction it saw
    // with that matrix, for the next solve's first step (an overestimate: its last step is the rounding)
    o.jacobian_update = JacobianUpdate::kWhenSlow;
    ws.newton_contraction = -1.0;
    solve_from(1e-6);
    EXPECT_GE(ws.newton_contraction, 0.0);
  }

  // In parallel chunks: a chunk's first row (from its seed) and the previous chunk's seam differ by the rounding
  // level, thousands of tolerances here, not by the 100 tolerances the seam check allows a regular solve; the check
  // allows 10× the rounding level such stops report, so every chunk is accepted (before, the rest ran in order).
  sc.sweep.chunk_steps = 5;
  const HardRows p = sweep_hard_scene(sc, 2);
  ASSERT_EQ(p.status, SolveStatus::kSuccess) << p.sum.message;
  for (const SweepWarning& w : p.sum.warnings) EXPECT_NE(w.kind, "parallel_fallback") << w.message;
  EXPECT_EQ(p.sum.parallel_chunks, 4);
  EXPECT_LE(deviation(p), 3e-10);              // as the sequential sweep (measured 1.7–1.8e-10)
  EXPECT_LE(derivative_deviation(p), 1.5e-9);  // measured 8.1e-10
  std::printf(
      "deviation from the closed form: tolerance 1e-10 %.3g, 1e-16 (rounding-level stops) %.3g, in parallel "
      "chunks %.3g; q̇, q̈ relative %.3g, %.3g, %.3g; factorisations %ld, %ld\n",
      deviation(usual), deviation(r), deviation(p), derivative_deviation(usual), derivative_deviation(r),
      derivative_deviation(p), static_cast<long>(usual.sum.counters.factorizations),
      static_cast<long>(r.sum.counters.factorizations));
}

// What a workspace carries between sweeps (the LU's pivot order, the Newton contraction) may move the last bits of
// rows at their rounding level (engine/README.md, Threads and reproducibility); a fresh workspace on one thread
// repeats the sweep to the bit. The 2000-stage lift at a tolerance below its rounding, where every row ends at the
// level its last bits set: q, q̇ and q̈ of every row identical in two sweeps, each from a fresh workspace.
TEST(HardCases, AFreshWorkspaceOnOneThreadRepeatsASweepToTheBit) {
  Scene sc = parse_scene(tools::generate_scene(test::generate_options("scissor", 2000, "natural", 0.3, 1.2, 1000)),
                         "scissor.yaml");
  sc.sweep.steps = 20;
  sc.sweep.t_end = 0.02;
  sc.sweep.newton.tolerance = 1e-16;
  const HardRows a = sweep_hard_scene(sc, 1), b = sweep_hard_scene(sc, 1);
  ASSERT_EQ(a.status, SolveStatus::kSuccess) << a.sum.message;
  ASSERT_EQ(b.status, SolveStatus::kSuccess) << b.sum.message;
  EXPECT_FALSE(a.sum.warnings.empty()) << "rows at their rounding level";
  ASSERT_EQ(a.tr.q.size(), b.tr.q.size());
  for (std::size_t k = 0; k < a.tr.q.size(); ++k) {
    ASSERT_TRUE(a.tr.q[k] == b.tr.q[k]) << "row " << k;
    ASSERT_TRUE(a.tr.qd[k] == b.tr.qd[k]) << "row " << k;
    ASSERT_TRUE(a.tr.qdd[k] == b.tr.qdd[k]) << "row " << k;
  }
  EXPECT_EQ(a.sum.counters.newton_iterations, b.sum.counters.newton_iterations);
  EXPECT_EQ(a.sum.counters.factorizations, b.sum.counters.factorizations);
}
}  // namespace
