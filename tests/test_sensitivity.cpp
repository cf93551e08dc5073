// Sensitivities to design parameters (phiq/sensitivity.hpp): ∂q/∂p, ∂q̇/∂p, ∂q̈/∂p against closed forms (the
// crank-slider's slider, differentiated exactly by nested dual numbers; the redundant parallelogram), against
// central differences of two re-solved sweeps (planar, spatial, redundant scenes), over thread counts, in
// positions-only sweeps (same bits of q as without them), and the scene's refusals.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "cli_test_support.hpp"
#include "phiq/parsed_scene.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

using test::model_path;
using test::sweep;
using test::Trace;

// Forward-mode dual numbers, nested for mixed higher derivatives: Dual<Dual<double>> carries ∂/∂a, ∂/∂b and
// ∂²/∂a∂b exactly. Only what the closed forms below use.
template <class T>
struct Dual {
  T v{}, d{};
};
template <class T> Dual<T> operator+(Dual<T> a, Dual<T> b) { return {a.v + b.v, a.d + b.d}; }
template <class T> Dual<T> operator-(Dual<T> a, Dual<T> b) { return {a.v - b.v, a.d - b.d}; }
template <class T> Dual<T> operator*(Dual<T> a, Dual<T> b) { return {a.v * b.v, a.d * b.v + a.v * b.d}; }
template <class T> Dual<T> operator/(Dual<T> a, Dual<T> b) { return {a.v / b.v, (a.d * b.v - a.v * b.d) / (b.v * b.v)}; }
inline double sqrt_(double x) { return std::sqrt(x); }
inline double sin_(double x) { return std::sin(x); }
inline double cos_(double x) { return std::cos(x); }
template <class T> Dual<T> sqrt_(Dual<T> a) {
  const T r = sqrt_(a.v);
  return {r, a.d / (r + r)};
}
template <class T> Dual<T> sin_(Dual<T> a) { return {sin_(a.v), a.d * cos_(a.v)}; }
template <class T> Dual<T> cos_(Dual<T> a) { return {cos_(a.v), T{} - a.d * sin_(a.v)}; }

// The slider of the notes' crank-slider: x_B = L2 cos θ + √(L3² − L2² sin² θ).
template <class T>
T slider(T theta, T l2, T l3) {
  const T s = sin_(theta);
  return l2 * cos_(theta) + sqrt_(l3 * l3 - l2 * l2 * s * s);
}

using D1 = Dual<double>;
using D2 = Dual<D1>;
using D3 = Dual<D2>;

// ∂x_B/∂L, ∂²x_B/∂θ∂L and ∂³x_B/∂θ²∂L at (θ, L2, L3), `which` = 2 for L2, 3 for L3: θ carries the two inner
// directions, L the outer one.
std::array<double, 3> slider_derivatives(double theta, double l2, double l3, int which) {
  auto constant = [](double x) { return D3{D2{D1{x, 0}, D1{0, 0}}, D2{D1{0, 0}, D1{0, 0}}}; };
  const D3 th{D2{D1{theta, 1}, D1{1, 0}}, D2{D1{0, 0}, D1{0, 0}}};
  D3 a = constant(l2), b = constant(l3);
  (which == 2 ? a : b).d = D2{D1{1, 0}, D1{0, 0}};
  const D3 x = slider(th, a, b);
  return {x.d.v.v, x.d.v.d, x.d.d.d};
}

// x_B's derivatives in θ alone, x′, x″, x‴ at (θ, L2, L3): θ carries all three directions.
std::array<double, 3> slider_theta_derivatives(double theta, double l2, double l3) {
  auto constant = [](double x) { return D3{D2{D1{x, 0}, D1{0, 0}}, D2{D1{0, 0}, D1{0, 0}}}; };
  const D3 th{D2{D1{theta, 1}, D1{1, 0}}, D2{D1{1, 0}, D1{0, 0}}};
  const D3 x = slider(th, constant(l2), constant(l3));
  return {x.d.v.v, x.d.d.v, x.d.d.d};
}

// ∂x_B/∂L, ∂ẋ_B/∂L, ∂ẍ_B/∂L of kCrankSlider (L2 = 0.3, L3 = 1) at time t: θ = 2t, θ̈ = 0, so 1, 2 and 4 times the
// θ-derivatives above.
std::array<double, 3> slider_sensitivities(double t, int which) {
  const auto d = slider_derivatives(2.0 * t, 0.3, 1.0, which);
  return {d[0], 2.0 * d[1], 4.0 * d[2]};
}

const char* kCrankSlider = R"(phiq: 1
name: crank_slider
parameters: {L2: 0.3, L3: 1.0}
coordinates: {theta2: 0.0, xA: 0.28, yA: 0.03, xB: 1.25}
points: {O: [0, 0], A: [xA, yA], B: [xB, 0]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}
  - {name: rod, type: distance, points: [A, B], length: L3}
drivers:
  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 2}}
time: {start: 0, end: pi, steps: 90}
output: {velocities: true, accelerations: true, sensitivities: [L2, {parameter: L3, step: 1e-3}]}
)";

// Every delivered row's sensitivities, with the row's time and state.
struct SensitivityTrace {
  Trace rows;
  std::vector<std::vector<double>> s;
  SweepSummary summary;
};

SensitivityTrace sweep_sensitivities(const Model& model, const SweepOptions& o, const Eigen::VectorXd* start = nullptr) {
  SensitivityTrace r;
  Workspace ws(model);
  if (start) ws.q = *start;
  const Index size = SensitivityLayout{model.num_coordinates()}.size(o.sensitivities.size());
  const SolveStatus st = run_sweep(model, o, ws, [&](const StepView& v) {
    r.rows.t.push_back(v.t);
    r.rows.q.push_back(v.q);
    if (v.qd) r.rows.qd.push_back(*v.qd);
    if (v.qdd) r.rows.qdd.push_back(*v.qdd);
    EXPECT_NE(v.sensitivities, nullptr);
    if (v.sensitivities) r.s.emplace_back(v.sensitivities, v.sensitivities + size);
    return true;
  }, &r.summary);
  EXPECT_EQ(st, SolveStatus::kSuccess) << r.summary.message;
  return r;
}

TEST(Sensitivity, CrankSliderAgainstTheClosedFormAndItsTimeDerivatives) {
  const Scene s = parse_scene(kCrankSlider, "crank_slider.yaml");
  ASSERT_EQ(s.sweep.sensitivities.size(), 2u);
  EXPECT_DOUBLE_EQ(s.sweep.sensitivities[0].step, 3e-4);  // 10⁻³ |p|
  EXPECT_DOUBLE_EQ(s.sweep.sensitivities[1].step, 1e-3);  // as given
  const SensitivityTrace r = sweep_sensitivities(*s.model, s.sweep);
  ASSERT_EQ(r.s.size(), 91u);
  const Index n = s.model->num_coordinates(), xb = s.model->coordinate_index("xB");
  const Index th = s.model->coordinate_index("theta2");
  const SensitivityLayout layout{n};
  double worst = 0.0;
  for (std::size_t k = 0; k < r.s.size(); ++k) {
    const double theta = 2.0 * r.rows.t[k];
    for (int which : {2, 3}) {
      const std::size_t j = which == 2 ? 0 : 1;
      const auto exact = slider_derivatives(theta, 0.3, 1.0, which);
      // θ = 2t: ∂ẋ_B/∂L = 2 ∂²x_B/∂θ∂L, ∂ẍ_B/∂L = 4 ∂³x_B/∂θ²∂L (θ̈ = 0)
      const double got[3] = {r.s[k][layout.offset(j, 0) + xb], r.s[k][layout.offset(j, 1) + xb],
                             r.s[k][layout.offset(j, 2) + xb]};
      const double want[3] = {exact[0], 2.0 * exact[1], 4.0 * exact[2]};
      for (int o = 0; o < 3; ++o) {
        EXPECT_NEAR(got[o], want[o], 1e-9) << "t = " << r.rows.t[k] << ", L" << which << ", order " << o;
        worst = std::max(worst, std::fabs(got[o] - want[o]));
      }
      // the driven crank angle does not move with a length
      for (int o = 0; o < 3; ++o) EXPECT_NEAR(r.s[k][layout.offset(j, o) + th], 0.0, 1e-12);
    }
  }
  EXPECT_GT(worst, 0.0);  // (compared for real: the sweep's rows are not the closed form's bits)
  // One solve per parameter, order and row, each with the row's own factorisation: no more factorisations than
  // the same sweep without sensitivities.
  EXPECT_EQ(r.summary.counters.sensitivity_solves, 91 * 2 * 3);
  SweepOptions plain = s.sweep;
  plain.sensitivities.clear();
  const SensitivityTrace p = [&] {
    SensitivityTrace t;
    Workspace ws(*s.model);
    (void)run_sweep(*s.model, plain, ws, [](const StepView&) { return true; }, &t.summary);
    return t;
  }();
  EXPECT_EQ(r.summary.counters.factorizations, p.summary.counters.factorizations);
  EXPECT_EQ(p.summary.counters.sensitivity_solves, 0);
}

// A caller's sensitivities (SceneOverrides::sensitivities: `phiq batch --sensitivity`, Python's run_batch) replace
// the scene's own: the same sweep as sensitivities_of() on the scene read without them, at the overrides' values;
// a bad request is refused naming its source; without models they are listed, checked.
TEST(Sensitivity, TheCallersRequestsReplaceTheScenesOwn) {
  SceneOverrides o;
  o.parameters = {{"L2", 0.25}};
  o.sensitivities = {{"L3", 2e-3}};
  o.sensitivities_source = "cases.csv";
  ParsedScene tree(kCrankSlider, "crank_slider.yaml");
  const Scene asked = tree.read(o);
  ASSERT_EQ(asked.sweep.sensitivities.size(), 1u);
  EXPECT_EQ(asked.sweep.sensitivities[0].name, "L3");
  EXPECT_EQ(asked.sweep.sensitivities[0].step, 2e-3);  // the request's, not the scene's entry's 1e-3
  SceneOverrides plain;
  plain.parameters = o.parameters;
  Scene then = tree.read(plain);
  then.sweep.sensitivities = sensitivities_of(then, {{"L3", 2e-3}}, "--sensitivity");
  const SensitivityTrace a = sweep_sensitivities(*asked.model, asked.sweep);
  const SensitivityTrace b = sweep_sensitivities(*then.model, then.sweep);
  ASSERT_EQ(a.s.size(), 91u);
  EXPECT_EQ(a.s, b.s);
  const Index xb = asked.model->coordinate_index("xB");
  for (std::size_t k = 0; k < a.s.size(); ++k)
    EXPECT_NEAR(a.s[k][static_cast<std::size_t>(xb)], slider_derivatives(2.0 * a.rows.t[k], 0.25, 1.0, 3)[0], 1e-9);
  auto refused = [&](std::vector<SensitivityRequest> requests, bool models) {
    SceneOverrides bad = o;
    bad.sensitivities = std::move(requests);
    bad.sensitivity_models = models;
    try {
      (void)tree.read(bad);
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("(read)");
  };
  EXPECT_EQ(refused({{"L9", 0.0}}, true), "cases.csv: 'L9' is not a parameter of crank_slider.yaml (its parameters: "
                                          "L2, L3)");
  EXPECT_EQ(refused({{"L2", 0.0}, {"L2", 1e-4}}, false), "cases.csv: parameter 'L2' is asked for twice");
  EXPECT_EQ(refused({{"L2", -1.0}}, false),
            "cases.csv: the step of 'L2' must be a positive finite number (0: the default)");
  SceneOverrides listed = o;
  listed.sensitivity_models = false;
  const Scene without = tree.read(listed);
  ASSERT_EQ(without.sweep.sensitivities.size(), 1u);
  EXPECT_EQ(without.sweep.sensitivities[0].value, 1.0);
  EXPECT_EQ(without.sweep.sensitivities[0].models[0], nullptr);
  EXPECT_EQ(without.sweep.sensitivities[0].reached, nullptr);
}

// The models along `parameter` at `value` of `scene` (read with `read_with`), built through the C++ API as the
// scene's `output.sensitivities` builds them.
OutputSensitivity along(const Scene& scene, const std::string& parameter, double value,
                        SceneOverrides read_with = {}) {
  read_with.sensitivity_models = false;
  const OutputSensitivity s = sensitivity_along(scene, parameter, value, 0.0, {}, read_with);
  EXPECT_EQ(s.step, default_sensitivity_step(value));
  EXPECT_EQ(check_sensitivity_models(*scene.model, s), "");
  return s;
}

// sensitivity_along() is what the scene's own `output.sensitivities` builds: the same models (the sweeps agree to
// the bit), and one line naming the value where the moved scene cannot be read.
TEST(Sensitivity, AlongAParameterAsTheScenesOwnOutput) {
  const Scene own = parse_scene(kCrankSlider, "c.yaml");
  ASSERT_EQ(own.sweep.sensitivities.size(), 2u);
  Scene api = parse_scene(kCrankSlider, "c.yaml");
  api.sweep.sensitivities = {sensitivity_along(api, "L2", 0.3), sensitivity_along(api, "L3", 1.0, 1e-3)};
  EXPECT_EQ(api.sweep.sensitivities[1].step, 1e-3);
  const SensitivityTrace a = sweep_sensitivities(*own.model, own.sweep), b = sweep_sensitivities(*api.model, api.sweep);
  ASSERT_EQ(a.s.size(), 91u);
  ASSERT_EQ(b.s.size(), a.s.size());
  for (std::size_t k = 0; k < a.s.size(); ++k) ASSERT_TRUE(a.s[k] == b.s[k]) << "row " << k;
  try {
    (void)sensitivity_along(api, "L3", 1.0, 0.6);
    FAIL() << "L3 = -0.2 was read";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), "with L3 = -0.19999999999999996 (the difference step 0.6 from 1) the scene "
                                     "cannot be read: c.yaml:8:57: constraints[1].length: must be positive, got L3 "
                                     "= -0.19999999999999996");
  }
}

// The scene at parameter = value swept as `phiq run` sweeps it (prepare_scene: redundant rows left out).
SensitivityTrace sweep_at(const std::string& text, const std::string& parameter, double value,
                          const std::string& with_sensitivity = "", double tolerance = 1e-13) {
  SceneOverrides o;
  o.parameters = {{parameter, value}};
  Scene s = parse_scene(text, "scene.yaml", {}, o);
  s.sweep.newton.tolerance = tolerance;
  if (!with_sensitivity.empty()) s.sweep.sensitivities = {along(s, with_sensitivity, value, o)};
  SquareScene sq;
  EXPECT_EQ(prepare_scene(*s.model, s.sweep.t_begin, s.sweep.assembly, &sq), SolveStatus::kSuccess);
  SensitivityTrace r;
  if (!s.sweep.sensitivities.empty()) return sweep_sensitivities(sq.model(*s.model), s.sweep, &sq.start);
  Workspace ws(sq.model(*s.model));
  ws.q = sq.start;
  EXPECT_EQ(sweep(sq.model(*s.model), s.sweep, &r.rows, &r.summary, &ws), SolveStatus::kSuccess);
  return r;
}

// Whole-sweep sensitivities against central differences of two sweeps re-solved at p ± δ: relative 1e-6 of the
// largest sensitivity of each order (of ∂q/∂p's where an order's are all zero: a translation has no ∂q̇/∂p).
void expect_matches_resolved_sweeps(const std::string& rel, const std::string& parameter, double value) {
  const std::string text = test::slurp(model_path(rel));
  const SensitivityTrace r = sweep_at(text, parameter, value, parameter);
  const double delta = 1e-4 * std::max(1.0, std::fabs(value));
  const SensitivityTrace up = sweep_at(text, parameter, value + delta);
  const SensitivityTrace down = sweep_at(text, parameter, value - delta);
  ASSERT_EQ(up.rows.q.size(), r.s.size());
  ASSERT_EQ(down.rows.q.size(), r.s.size());
  const Index n = static_cast<Index>(r.rows.q[0].size());
  const SensitivityLayout layout{n};
  double position_scale = 0.0;
  for (int order = 0; order < 3; ++order) {
    const auto& u = order == 0 ? up.rows.q : order == 1 ? up.rows.qd : up.rows.qdd;
    const auto& d = order == 0 ? down.rows.q : order == 1 ? down.rows.qd : down.rows.qdd;
    double scale = 0.0, worst = 0.0;
    for (std::size_t k = 0; k < r.s.size(); ++k)
      for (Index j = 0; j < n; ++j) {
        const double exact = r.s[k][layout.offset(0, order) + j];
        ASSERT_TRUE(std::isfinite(exact)) << rel << " t = " << r.rows.t[k];
        scale = std::max(scale, std::fabs(exact));
        worst = std::max(worst, std::fabs(exact - (u[k](j) - d[k](j)) / (2 * delta)));
      }
    if (order == 0) {
      position_scale = scale;
      EXPECT_GT(scale, 1e-3) << rel << ": the parameter moves the motion";
    }
    EXPECT_LE(worst, 1e-6 * std::max(scale, position_scale)) << rel << ", ∂/∂" << parameter << " of order " << order;
  }
}

TEST(Sensitivity, PlanarFourBarMatchesResolvedSweeps) {
  expect_matches_resolved_sweeps("seed/fourbar_natural.yaml", "L3", 1.2);
  expect_matches_resolved_sweeps("seed/fourbar_reference_point.yaml", "L2", 0.4);
}

TEST(Sensitivity, SpatialScenesMatchResolvedSweeps) {
  expect_matches_resolved_sweeps("spatial/rssr.yaml", "L", 0.92);
  expect_matches_resolved_sweeps("spatial/crank_slider_natural.yaml", "h", 0.1);
}

TEST(Sensitivity, RedundantParallelogramMatchesItsClosedForm) {
  // Every crank at ψ = π/3 + t, the coupler's left end at r (cos ψ, sin ψ): ∂xc/∂r = cos ψ, ∂yc/∂r = sin ψ and
  // their time derivatives; the redundant fifth bar's row is left out of the solves, not of Φp.
  const std::string text = test::slurp(model_path("redundant/parallelogram_fifth_bar.yaml"));
  const SensitivityTrace r = sweep_at(text, "r", 1.0, "r", 1e-10);
  const Scene s = parse_scene(text, "p.yaml");
  const Index xc = s.model->coordinate_index("xc"), yc = s.model->coordinate_index("yc");
  const SensitivityLayout layout{s.model->num_coordinates()};
  ASSERT_EQ(r.s.size(), 101u);
  for (std::size_t k = 0; k < r.s.size(); ++k) {
    const double psi = M_PI / 3 + r.rows.t[k], c = std::cos(psi), sn = std::sin(psi);
    const double want_x[3] = {c, -sn, -c}, want_y[3] = {sn, c, -sn};
    for (int o = 0; o < 3; ++o) {
      EXPECT_NEAR(r.s[k][layout.offset(0, o) + xc], want_x[o], 1e-9) << "t = " << r.rows.t[k] << " order " << o;
      EXPECT_NEAR(r.s[k][layout.offset(0, o) + yc], want_y[o], 1e-9) << "t = " << r.rows.t[k] << " order " << o;
    }
  }
  expect_matches_resolved_sweeps("redundant/parallelogram_fifth_bar.yaml", "d", 1.0);
}

TEST(Sensitivity, RowsOnASingularPositionAreNaNTheOthersFinite) {
  // The parallelogram's change points (crank at π and 2π): Φq has no inverse there, the rows say NaN; every other
  // row has finite sensitivities.
  const std::string text = test::slurp(model_path("hard/change_point_exact.yaml"));
  const SensitivityTrace r = sweep_at(text, "r", 1.0, "r", 1e-10);
  ASSERT_GT(r.summary.singular_positions, 0);
  Index nan_rows = 0;
  for (const auto& row : r.s) {
    const bool nan = std::isnan(row[0]);
    nan_rows += nan;
    for (double v : row) EXPECT_EQ(std::isnan(v), nan);
  }
  EXPECT_EQ(nan_rows, r.summary.singular_positions);
}

TEST(Sensitivity, SameBitsOnEveryThreadCount) {
  const std::string text = test::slurp(model_path("seed/fourbar_natural.yaml"));
  Scene s = parse_scene(text, "f.yaml");
  s.sweep.sensitivities = {along(s, "L2", 0.4), along(s, "L4", 1.0)};
  std::vector<std::vector<double>> first;
  for (int threads : {1, 2, 3}) {
    SweepOptions o = s.sweep;
    o.threads = threads;
    o.chunk_steps = 40;
    const SensitivityTrace r = sweep_sensitivities(*s.model, o);
    if (threads == 1) first = r.s;
    ASSERT_EQ(r.s.size(), first.size());
    for (std::size_t k = 0; k < first.size(); ++k)
      for (std::size_t i = 0; i < first[k].size(); ++i)
        ASSERT_EQ(std::memcmp(&r.s[k][i], &first[k][i], sizeof(double)), 0)
            << threads << " threads, row " << k << " value " << i;
  }
}

TEST(Sensitivity, PositionsOnlyFactoriseApartAndLeaveTheSweepsBits) {
  // Without velocities the workspace's factors are not at the rows: the sensitivities factorise Φq there on
  // their own, and the positions stay the bits of the same sweep without sensitivities.
  Scene s = parse_scene(kCrankSlider, "crank_slider.yaml");
  const SensitivityTrace full = sweep_sensitivities(*s.model, s.sweep);
  s.sweep.velocities = s.sweep.accelerations = false;
  const SensitivityTrace r = sweep_sensitivities(*s.model, s.sweep);
  SweepOptions plain = s.sweep;
  plain.sensitivities.clear();
  Trace p;
  ASSERT_EQ(sweep(*s.model, plain, &p), SolveStatus::kSuccess);
  ASSERT_EQ(r.rows.q.size(), p.q.size());
  const SensitivityLayout layout{s.model->num_coordinates()};
  for (std::size_t k = 0; k < p.q.size(); ++k) {
    EXPECT_EQ(r.rows.q[k], p.q[k]) << "row " << k;
    for (Index j = 0; j < s.model->num_coordinates(); ++j)
      for (std::size_t i = 0; i < 2; ++i) {
        EXPECT_NEAR(r.s[k][layout.offset(i, 0) + j], full.s[k][layout.offset(i, 0) + j], 1e-10);
        EXPECT_TRUE(std::isnan(r.s[k][layout.offset(i, 1) + j]));  // q̇'s: not asked for
      }
  }
  EXPECT_EQ(r.summary.counters.sensitivity_solves, 91 * 2);
}

TEST(Sensitivity, SolveSensitivitiesOnAWorkspaceEqualsTheSweeps) {
  const Scene s = parse_scene(kCrankSlider, "crank_slider.yaml");
  const SensitivityTrace r = sweep_sensitivities(*s.model, s.sweep);
  Workspace ws(*s.model);
  const std::size_t k = 37;
  ws.q = r.rows.q[k], ws.qd = r.rows.qd[k], ws.qdd = r.rows.qdd[k];
  std::vector<double> out(r.s[k].size());
  LinearSummary ls;
  ASSERT_EQ(solve_sensitivities(*s.model, s.sweep.sensitivities, r.rows.t[k], 2, ws, out.data(), &ls),
            SolveStatus::kSuccess)
      << ls.message;
  for (std::size_t i = 0; i < out.size(); ++i) EXPECT_NEAR(out[i], r.s[k][i], 1e-12) << i;
  EXPECT_THROW((void)solve_sensitivities(*s.model, s.sweep.sensitivities, 0.0, 3, ws, out.data()), Error);
}

TEST(Sensitivity, AParameterTheMotionDoesNotDependOnGivesZeros) {
  // `unused` reaches no constraint: its column is zero (reported by its values, not an error).
  const std::string text = test::replace_first(
      test::replace_first(kCrankSlider, "{L2: 0.3, L3: 1.0}", "{L2: 0.3, L3: 1.0, unused: 5}"),
      "sensitivities: [L2, {parameter: L3, step: 1e-3}]", "sensitivities: [unused]");
  const Scene s = parse_scene(text, "c.yaml");
  const SensitivityTrace r = sweep_sensitivities(*s.model, s.sweep);
  for (const auto& row : r.s)
    for (double v : row) EXPECT_EQ(v, 0.0);
  ASSERT_EQ(r.summary.warnings.size(), 1u);
  EXPECT_EQ(r.summary.warnings[0].kind, "no_dependence");
  EXPECT_EQ(r.summary.warnings[0].message, "no constraint or driver reads the parameter 'unused': its sensitivities are zero");
  // a parameter that is read is not reported
  const Scene both = parse_scene(kCrankSlider, "c.yaml");
  const SensitivityTrace read = sweep_sensitivities(*both.model, both.sweep);
  for (const SweepWarning& w : read.summary.warnings) EXPECT_NE(w.kind, "no_dependence");
}

TEST(Sensitivity, SceneRefusals) {
  auto with = [](const std::string& list) {
    return test::replace_first(kCrankSlider, "sensitivities: [L2, {parameter: L3, step: 1e-3}]",
                               "sensitivities: " + list);
  };
  EXPECT_EQ(test::scene_error(with("[L9]")),
            "bad.yaml:12:65: output.sensitivities[0]: 'L9' is not a parameter of the scene (its parameters: L2, L3)");
  EXPECT_EQ(test::scene_error(with("[L2, L2]")), "bad.yaml:12:69: output.sensitivities[1]: parameter 'L2' listed twice");
  EXPECT_EQ(test::scene_error(with("[{parameter: L2, step: 0}]")),
            "bad.yaml:12:87: output.sensitivities[0].step: the difference step must be positive");
  EXPECT_EQ(test::scene_error(with("[{parameter: L2, by: 1}]")).substr(0, 43),
            "bad.yaml:12:81: output.sensitivities[0].by:");
  // A parameter that sets a family's range changes the model's structure: no derivative.
  const char* family = R"(phiq: 1
parameters: {N: 3}
coordinates:
  for i in 1..N:
    x{i}: 0
drivers:
  - for i in 1..N:
      - {name: "d{i}", coordinate: "x{i}", law: {type: linear, initial: 0, rate: 1}}
time: {start: 0, end: 1, steps: 2}
output: {sensitivities: [N]}
)";
  const std::string e = test::scene_error(family);
  EXPECT_NE(e.find("output.sensitivities"), std::string::npos) << e;
  EXPECT_NE(e.find("'N'"), std::string::npos) << e;
}

// The adjoint form (SensitivityForm::kAdjoint) against the direct one on the same sweep, every coordinate an
// output: relative 1e-10 of each order's largest value, on planar, spatial and redundant scenes (the transposed
// second-derivative terms are differences along the motion: exact for lengths, h⁴ inside sines). `direct_rows`:
// the rows the adjoint sweep solves in the direct form, where Φq is not smooth along the motion (a spline's knot).
void expect_adjoint_equals_direct(const std::string& rel, const std::vector<std::pair<std::string, double>>& params,
                                  Index direct_rows = 0) {
  const std::string text = test::slurp(model_path(rel));
  Scene s = parse_scene(text, "scene.yaml");
  s.sweep.sensitivities.clear();
  for (const auto& [name, value] : params) s.sweep.sensitivities.push_back(along(s, name, value));
  SquareScene sq;
  ASSERT_EQ(prepare_scene(*s.model, s.sweep.t_begin, s.sweep.assembly, &sq), SolveStatus::kSuccess);
  const Model& model = sq.model(*s.model);
  SweepOptions direct = s.sweep, adjoint = s.sweep;
  direct.sensitivity_form = SensitivityForm::kDirect;
  adjoint.sensitivity_form = SensitivityForm::kAdjoint;
  const SensitivityTrace d = sweep_sensitivities(model, direct, &sq.start);
  const SensitivityTrace a = sweep_sensitivities(model, adjoint, &sq.start);
  EXPECT_EQ(d.summary.sensitivity_form, SensitivityForm::kDirect);
  EXPECT_EQ(a.summary.sensitivity_form, SensitivityForm::kAdjoint);
  EXPECT_EQ(a.summary.counters.sensitivity_direct_rows, direct_rows) << rel;
  EXPECT_EQ(d.summary.counters.sensitivity_direct_rows, 0) << rel;
  ASSERT_EQ(a.s.size(), d.s.size());
  const Index n = model.num_coordinates();
  const SensitivityLayout layout{n};
  const int orders = s.sweep.accelerations ? 3 : s.sweep.velocities ? 2 : 1;
  for (int o = 0; o < orders; ++o) {
    double scale = 0.0, worst = 0.0;
    for (std::size_t k = 0; k < d.s.size(); ++k) {
      EXPECT_EQ(a.rows.q[k], d.rows.q[k]) << rel << " row " << k;  // the sweep itself is the same bits
      for (std::size_t j = 0; j < params.size(); ++j)
        for (Index i = 0; i < n; ++i) {
          const double want = d.s[k][layout.offset(j, o) + i], got = a.s[k][layout.offset(j, o) + i];
          if (std::isnan(want)) {
            EXPECT_TRUE(std::isnan(got)) << rel << " row " << k;  // a singular row's
            continue;
          }
          scale = std::max(scale, std::fabs(want));
          worst = std::max(worst, std::fabs(got - want));
        }
    }
    EXPECT_GT(scale, 0.0) << rel << " order " << o;
    EXPECT_LE(worst, 1e-10 * scale) << rel << ", order " << o << ": " << worst << " of " << scale;
  }
}

TEST(Sensitivity, TheAdjointFormEqualsTheDirectOne) {
  expect_adjoint_equals_direct("seed/fourbar_natural.yaml", {{"L2", 0.4}, {"L3", 1.2}});
  expect_adjoint_equals_direct("seed/fourbar_reference_point.yaml", {{"L2", 0.4}});
  expect_adjoint_equals_direct("spatial/rssr.yaml", {{"L", 0.92}});
  expect_adjoint_equals_direct("spatial/crank_slider_natural.yaml", {{"h", 0.1}});
  expect_adjoint_equals_direct("redundant/parallelogram_fifth_bar.yaml", {{"r", 1.0}, {"d", 1.0}});
  // A pin in a slot along a spline: the rows whose adjoint differences along the motion straddle one of its knots
  // (their sixth-order second difference was off by 0.4 to 2 % of ∂q̈/∂p) are solved in the direct form.
  // (`bend` changes the spline's length: the contact's parameter co-moves with it)
  expect_adjoint_equals_direct("slots/curved_slot_crank.yaml", {{"L2", 0.2}, {"L3", 0.6}, {"bend", 1.0}}, 5);
  // A flat follower on a circle whose radius is a parameter: the contact co-moves (ParameterReach::comotion)
  expect_adjoint_equals_direct("cams/eccentric_flat.yaml", {{"R", 0.05}, {"e", 0.015}});
}

// An eccentric circular cam (radius R, eccentricity e, turning at ω) under a flat-faced follower: the face's height
// is y = R + e sin ωt, so ∂y/∂R = 1, ∂y/∂e = sin ωt, ∂y/∂ω = e t cos ωt and their time derivatives, exactly. Over
// ten turns the contact's curve parameter reaches s = 20πR: differenced at fixed s, a radius step h turns the circle
// under the contact by s h / R², and ∂y/∂R was off by 7·10⁻⁶; the contact moves with the radius
// (ParameterReach::comotion) instead. ∂θ/∂ω = t grows likewise, and the direct form's step along the motion is
// scaled to it (a step h|s| put ∂ẏ/∂ω off by 4·10⁻⁷). Both forms, to 10⁻⁹.
TEST(Sensitivity, ACamsRadiusOverTenTurnsAgainstTheClosedForm) {
  std::string text = test::slurp(model_path("cams/eccentric_flat.yaml"));
  text = test::replace_first(text, "time: {start: 0, end: 2*pi/omega, steps: 72}",
                             "time: {start: 0, end: 20*pi/omega, steps: 720}");
  text = test::replace_first(text, "output: {velocities: true, accelerations: true}",
                             "output: {velocities: true, accelerations: true, sensitivities: [R, e, omega]}");
  const Scene s = parse_scene(text, "cam.yaml");
  ASSERT_EQ(s.sweep.sensitivities.size(), 3u);
  const Model& model = *s.model;
  // R moves the circle's length 2πR: the contact's parameter co-moves at (∂ℓ/∂R) / ℓ = 1/R; e and ω move no
  // curve's length.
  const Index cam_s = model.coordinate_index("cam.s");
  const ParameterReach by_r = parameter_reach(model, s.sweep.sensitivities[0]);
  ASSERT_EQ(by_r.comotion.size(), 1u);
  EXPECT_EQ(by_r.comotion[0].coordinate, cam_s);
  EXPECT_NEAR(by_r.comotion[0].rate, 1.0 / 0.05, 1e-9);
  EXPECT_TRUE(parameter_reach(model, s.sweep.sensitivities[1]).comotion.empty());
  EXPECT_TRUE(parameter_reach(model, s.sweep.sensitivities[2]).comotion.empty());
  const double e = 0.015, w = 2.0;
  const Index y = model.coordinate_index("yf");
  const SensitivityLayout layout{model.num_coordinates()};
  for (SensitivityForm form : {SensitivityForm::kDirect, SensitivityForm::kAdjoint}) {
    SweepOptions o = s.sweep;
    o.sensitivity_form = form;
    const SensitivityTrace r = sweep_sensitivities(model, o);
    ASSERT_EQ(r.s.size(), 721u);
    double worst[3][3] = {};
    for (std::size_t k = 0; k < r.s.size(); ++k) {
      const double t = r.rows.t[k], c = std::cos(w * t), sn = std::sin(w * t);
      const double exact[3][3] = {{1.0, 0.0, 0.0},                                             // R
                                  {sn, w * c, -w * w * sn},                                     // e
                                  {e * t * c, e * (c - w * t * sn), -e * w * (2 * sn + w * t * c)}};  // ω
      for (std::size_t j = 0; j < 3; ++j)
        for (int order = 0; order < 3; ++order)
          worst[j][order] = std::max(worst[j][order],
                                     std::fabs(r.s[k][layout.offset(j, order) + y] - exact[j][order]));
    }
    for (std::size_t j = 0; j < 3; ++j)
      for (int order = 0; order < 3; ++order)
        EXPECT_LE(worst[j][order], 1e-9) << to_string(form) << ", parameter " << j << ", order " << order;
  }
}

// A pin in a circular slot of radius r driven along the slot by its arc length s (a driver on the coordinate the
// slot adds, as the C++ API allows): s = 0.3 + w t is fixed, so ∂s/∂r = 0, and P = c + r (cos φ, sin φ) with
// φ = s/r gives ∂x/∂r = cos φ + φ sin φ, ∂y/∂r = sin φ − φ cos φ, ∂ẋ/∂r = (wφ/r) cos φ, ∂ẏ/∂r = (wφ/r) sin φ,
// ∂ẍ/∂r = (w/r)² (cos φ − φ sin φ), ∂ÿ/∂r = (w/r)² (sin φ + φ cos φ). r moves the contact's s with the circle
// (ParameterReach::comotion), so the driver, which reads s and not r, is in r's reach: left out, its row of the
// derivative along (q̂, 1) would be 0 instead of q̂_s, and ∂s/∂r would be −q̂_s. Over 2.3 turns, both forms, 1e-9.
Model slot_by_arc(double r, const Model* share = nullptr) {
  ModelBuilder b;
  const double s0 = 0.3;
  const Index x = b.add_coordinate("x", 0.2 + r * std::cos(s0 / r)), y = b.add_coordinate("y", 0.1 + r * std::sin(s0 / r));
  PointOnCurveSpec slot;
  slot.a = Frame2{Slot::coordinate(x), Slot::coordinate(y), Slot{}};
  slot.on = CurveOn{Frame2{}, Curve::circle({0.2, 0.1}, r)};
  b.add("slot", slot);
  b.add_driver("push", b.num_coordinates() - 1, MotionLaw::linear(s0, 0.35));  // on slot.s
  if (share) b.share_analysis_with(*share);
  return std::move(b).build();
}

TEST(Sensitivity, AConstraintReadingACoMovingCoordinateIsInTheReach) {
  const double r = 0.5, w = 0.35, h = default_sensitivity_step(r);
  const Model model = slot_by_arc(r);
  OutputSensitivity p;
  p.name = "r", p.value = r, p.step = h;
  const double shifts[4] = {-2, -1, 1, 2};
  for (std::size_t k = 0; k < 4; ++k)
    p.models[k] = std::make_shared<const Model>(slot_by_arc(r + shifts[k] * h, &model));
  ASSERT_EQ(check_sensitivity_models(model, p), "");
  const Index s_index = model.coordinate_index("slot.s"), xi = model.coordinate_index("x"),
              yi = model.coordinate_index("y");
  const ParameterReach reach = parameter_reach(model, p);
  ASSERT_EQ(reach.comotion.size(), 1u);
  EXPECT_EQ(reach.comotion[0].coordinate, s_index);
  EXPECT_NEAR(reach.comotion[0].rate, 1.0 / r, 1e-9);
  EXPECT_EQ(reach.rows, (std::vector<Index>{0, 1, 2}));  // the slot's two rows and the driver's, which reads s
  SweepOptions o;
  o.t_begin = 0.0, o.t_end = 20.0, o.steps = 200;
  o.velocities = o.accelerations = true;
  o.sensitivities = {p};
  const SensitivityLayout layout{model.num_coordinates()};
  for (SensitivityForm form : {SensitivityForm::kDirect, SensitivityForm::kAdjoint}) {
    o.sensitivity_form = form;
    const SensitivityTrace tr = sweep_sensitivities(model, o);
    ASSERT_EQ(tr.s.size(), 201u);
    double worst = 0.0;
    for (std::size_t k = 0; k < tr.s.size(); ++k) {
      const double phi = (0.3 + w * tr.rows.t[k]) / r, c = std::cos(phi), sn = std::sin(phi), g = w / r;
      const double want[3][2] = {{c + phi * sn, sn - phi * c},
                                 {g * phi * c, g * phi * sn},
                                 {g * g * (c - phi * sn), g * g * (sn + phi * c)}};
      for (int order = 0; order < 3; ++order) {
        worst = std::max(worst, std::fabs(tr.s[k][layout.offset(0, order) + xi] - want[order][0]));
        worst = std::max(worst, std::fabs(tr.s[k][layout.offset(0, order) + yi] - want[order][1]));
        worst = std::max(worst, std::fabs(tr.s[k][layout.offset(0, order) + s_index]));  // s is driven
      }
    }
    EXPECT_LE(worst, 1e-9) << to_string(form);
  }
}

// A scene read twice: as it is (its reached kinds' own derivatives) and with its models along each parameter kept
// whole (every constraint differenced from them: SceneOverrides::keep_sensitivity_models).
std::pair<Scene, Scene> own_and_kept(const std::string& text, const std::string& path) {
  SceneOverrides keep;
  keep.keep_sensitivity_models = true;
  return {parse_scene(text, path), parse_scene(text, path, {}, keep)};
}

// The sweeps of the two readings of own_and_kept() in `form`.
std::pair<SensitivityTrace, SensitivityTrace> own_and_kept_sweeps(const std::pair<Scene, Scene>& scenes,
                                                                    SensitivityForm form) {
  SweepOptions a = scenes.first.sweep, b = scenes.second.sweep;
  a.sensitivity_form = b.sensitivity_form = form;
  return {sweep_sensitivities(*scenes.first.model, a), sweep_sensitivities(*scenes.second.model, b)};
}

// sensitivity_along() keeps of the four models along a parameter only the constraints it reaches
// (keep_reached_only()): the sweeps give the same bits as with the models kept, in both forms, a curve's co-moving
// parameter included; where the reached kinds differentiate their own data (the driver's law along ω), their rates
// and no copies, and the sweeps agree with the kept models' to 1e-10.
TEST(Sensitivity, ModelsAlongAParameterAreReleasedButForItsReach) {
  const std::string text = test::slurp(model_path("cams/eccentric_flat.yaml"));
  const Scene s = parse_scene(text, "cam.yaml");
  SceneOverrides keep;
  keep.keep_sensitivity_models = true;
  for (const char* name : {"R", "e", "omega"}) {
    const double value = name[0] == 'R' ? 0.05 : name[0] == 'e' ? 0.015 : 2.0;
    const OutputSensitivity slim = sensitivity_along(s, name, value);
    const OutputSensitivity kept = sensitivity_along(s, name, value, 0.0, {}, keep);
    for (std::size_t k = 0; k < 4; ++k) {
      EXPECT_EQ(slim.models[k], nullptr) << name;
      ASSERT_NE(kept.models[k], nullptr) << name;
      ASSERT_EQ(slim.reached->along[k].size(), slim.reach->spans.size()) << name;
    }
    EXPECT_EQ(slim.reached->reach, slim.reach);
    EXPECT_EQ(kept.reached, nullptr);
    EXPECT_EQ(check_sensitivity_models(*s.model, slim), "");
    // the reach, found before the models went, is what they give
    EXPECT_EQ(parameter_reach(*s.model, slim).rows, parameter_reach(*s.model, kept).rows) << name;
    // a span whose kind differentiates its data holds their rates and no copies (the driver's law, along ω); the
    // cam's contact co-moves with R and e, whose spans are differenced from their copies
    std::size_t constraints = 0, rated = 0;
    for (std::size_t j = 0; j < slim.reach->spans.size(); ++j) {
      const std::size_t n = slim.reach->spans[j].end - slim.reach->spans[j].begin;
      constraints += n;
      if (slim.reached->rates[j]) rated += n;
    }
    EXPECT_EQ(rated > 0, name[0] == 'o') << name;
    std::size_t copied = 0;
    for (const auto& block : slim.reached->along[0]) copied += block->size();
    EXPECT_EQ(copied, constraints - rated) << name;
    EXPECT_LT(constraints, s.model->constraints().size()) << name;
    for (SensitivityForm form : {SensitivityForm::kDirect, SensitivityForm::kAdjoint}) {
      SweepOptions a = s.sweep, b = s.sweep;
      a.sensitivities = {slim}, b.sensitivities = {kept};
      a.sensitivity_form = b.sensitivity_form = form;
      a.velocities = b.velocities = a.accelerations = b.accelerations = true;
      const SensitivityTrace ra = sweep_sensitivities(*s.model, a), rb = sweep_sensitivities(*s.model, b);
      ASSERT_EQ(ra.s.size(), rb.s.size());
      for (std::size_t k = 0; k < ra.s.size(); ++k)
        for (std::size_t i = 0; i < ra.s[k].size(); ++i) {
          if (std::isnan(ra.s[k][i]) && std::isnan(rb.s[k][i])) continue;  // the adjoint's unwritten entries
          if (rated == 0) {  // the same differences of the same data: the same bits
            ASSERT_EQ(ra.s[k][i], rb.s[k][i]) << name << " " << to_string(form) << " row " << k << " entry " << i;
          } else {  // the kind's derivatives against the kept models' differences: both exact for a linear law
            ASSERT_NEAR(ra.s[k][i], rb.s[k][i], 1e-10 * std::max(1.0, std::fabs(rb.s[k][i])))
                << name << " " << to_string(form) << " row " << k << " entry " << i;
          }
        }
    }
  }
  // a reach other than the one the constraints were kept for is refused, not read from released models
  OutputSensitivity other = sensitivity_along(s, "R", 0.05);
  other.reach = std::make_shared<const ParameterReach>(whole_model_reach(*s.model));
  EXPECT_HAS(check_sensitivity_models(*s.model, other), "its reach is not the one their constraints were kept for");
  // kept constraints whose data's rates do not match their reach's spans are refused, not read out of range
  OutputSensitivity odd = sensitivity_along(s, "R", 0.05);
  auto rates = std::make_shared<ReachedConstraints>();
  rates->reach = odd.reach;
  rates->rates.resize(odd.reach->spans.size() + 1);
  odd.reached = rates;
  EXPECT_EQ(check_sensitivity_models(*s.model, odd),
            "sensitivity to 'R': the rates of its kept constraints' data are not one for each span of their reach");
}

// The worst deviations of `exact`'s and `differenced`'s ∂x_B/∂L, ∂ẋ_B/∂L, ∂ẍ_B/∂L (L2 the first parameter, L3
// the second) from the crank-slider's closed form over every row, each of `exact`'s expected within 1e-9 of it and,
// with `agree`, within 1e-10 (relative) of `differenced`'s.
std::pair<double, double> slider_deviations(const Scene& s, const SensitivityTrace& exact,
                                            const SensitivityTrace& differenced, SensitivityForm form, bool agree) {
  EXPECT_EQ(exact.s.size(), 91u);
  EXPECT_EQ(differenced.s.size(), exact.s.size());
  const Index xb = s.model->coordinate_index("xB");
  const SensitivityLayout layout{s.model->num_coordinates()};
  double worst_exact = 0.0, worst_differenced = 0.0;
  for (std::size_t k = 0; k < std::min(exact.s.size(), differenced.s.size()); ++k)
    for (int which : {2, 3}) {
      const std::size_t j = which == 2 ? 0 : 1;
      const auto want = slider_sensitivities(exact.rows.t[k], which);
      for (int o = 0; o < 3; ++o) {
        const double e = exact.s[k][layout.offset(j, o) + xb], d = differenced.s[k][layout.offset(j, o) + xb];
        EXPECT_NEAR(e, want[o], 1e-9) << to_string(form) << " t = " << exact.rows.t[k] << ", L" << which;
        if (agree) {
          EXPECT_NEAR(e, d, 1e-10 * std::max(1.0, std::fabs(d))) << to_string(form);
        }
        worst_exact = std::max(worst_exact, std::fabs(e - want[o]));
        worst_differenced = std::max(worst_differenced, std::fabs(d - want[o]));
      }
    }
  return {worst_exact, worst_differenced};
}

// The crank-slider's crank (polar) and rod (distance) differentiate their own data (DataDifferentiable): the
// constraints kept along L2 and L3 hold their data's rates, and the sensitivities are the kinds' derivatives, exact
// whatever the step. With a step of 5 % the rod's differences are off by 2(h/L)⁴ ≈ 10⁻⁵ (the models kept, which
// difference), while the kinds' stay at the closed form to 1e-9; at the default step the two agree to 1e-10.
TEST(Sensitivity, KindsThatDifferentiateTheirDataAreExactAtAnyStep) {
  const std::string coarse = test::replace_first(kCrankSlider, "sensitivities: [L2, {parameter: L3, step: 1e-3}]",
                                                 "sensitivities: [{parameter: L2, step: 0.015}, {parameter: L3, step: 0.05}]");
  for (const std::string& text : {std::string(kCrankSlider), coarse}) {
    const bool large = text == coarse;
    const auto scenes = own_and_kept(text, "crank_slider.yaml");
    const Scene& s = scenes.first;
    for (const OutputSensitivity& p : s.sweep.sensitivities) {
      ASSERT_TRUE(p.reached) << p.name;
      ASSERT_EQ(p.reached->rates.size(), 1u) << p.name;  // one constraint each: the crank, the rod
      EXPECT_NE(p.reached->rates[0], nullptr) << p.name;
    }
    for (SensitivityForm form : {SensitivityForm::kDirect, SensitivityForm::kAdjoint}) {
      const auto [exact, differenced] = own_and_kept_sweeps(scenes, form);
      const auto [worst_exact, worst_differenced] = slider_deviations(s, exact, differenced, form, !large);
      if (large) {
        EXPECT_GT(worst_differenced, 1e-6) << to_string(form) << ": the differences at a 5 % step";
      }
      EXPECT_LT(worst_exact, 1e-9) << to_string(form);
    }
  }
}

// A parameter that reaches a driver's law: the crank swings, θ = A sin(W t), and W is the parameter. The law's
// rate (MotionLaw::rate_along) is the harmonic's derivative along its frequency, exact: at a 10 % step the
// sensitivities of x_B stay at the closed form, where the kept models' differences along W are off by about
// (hW)⁴ t⁵ / 30. With θ_W = A t cos(W t), θ̇ = A W cos(W t), θ̈ = −A W² sin(W t) and their rates along W:
//   ∂x/∂W = x′ θ_W,   ∂ẋ/∂W = x″ θ_W θ̇ + x′ θ̇_W,   ∂ẍ/∂W = x‴ θ_W θ̇² + 2 x″ θ̇ θ̇_W + x″ θ_W θ̈ + x′ θ̈_W.
TEST(Sensitivity, ADriversLawIsDifferentiatedAlongItsData) {
  std::string text = test::replace_first(kCrankSlider, "law: {type: linear, initial: 0, rate: 2}",
                                         "law: {type: harmonic, amplitude: 1.2, frequency: W}");
  text = test::replace_first(text, "parameters: {L2: 0.3, L3: 1.0}", "parameters: {L2: 0.3, L3: 1.0, W: 2.0}");
  text = test::replace_first(text, "sensitivities: [L2, {parameter: L3, step: 1e-3}]",
                             "sensitivities: [{parameter: W, step: 0.2}]");
  const auto scenes = own_and_kept(text, "swing.yaml");
  const Scene& s = scenes.first;
  const OutputSensitivity& w = s.sweep.sensitivities.at(0);
  ASSERT_TRUE(w.reached);
  ASSERT_EQ(w.reached->rates.size(), 1u);  // the driver alone
  EXPECT_NE(w.reached->rates[0], nullptr);
  const double A = 1.2, W = 2.0;
  for (SensitivityForm form : {SensitivityForm::kDirect, SensitivityForm::kAdjoint}) {
    const auto [exact, differenced] = own_and_kept_sweeps(scenes, form);
    ASSERT_EQ(exact.s.size(), 91u);
    ASSERT_EQ(differenced.s.size(), 91u);
    const Index n = s.model->num_coordinates(), xb = s.model->coordinate_index("xB");
    const SensitivityLayout layout{n};
    double worst_exact = 0.0, worst_differenced = 0.0;
    for (std::size_t k = 0; k < exact.s.size(); ++k) {
      const double t = exact.rows.t[k], c = std::cos(W * t), sn = std::sin(W * t);
      const double th = A * sn, thd = A * W * c, thdd = -A * W * W * sn;
      const double th_w = A * t * c, thd_w = A * c - A * W * t * sn, thdd_w = -2 * A * W * sn - A * W * W * t * c;
      const auto x = slider_theta_derivatives(th, 0.3, 1.0);
      const double want[3] = {x[0] * th_w, x[1] * th_w * thd + x[0] * thd_w,
                              x[2] * th_w * thd * thd + 2 * x[1] * thd * thd_w + x[1] * th_w * thdd + x[0] * thdd_w};
      for (int o = 0; o < 3; ++o) {
        const double e = exact.s[k][layout.offset(0, o) + xb], d = differenced.s[k][layout.offset(0, o) + xb];
        EXPECT_NEAR(e, want[o], 1e-9 * std::max(1.0, std::fabs(want[o])))
            << to_string(form) << " t = " << t << ", order " << o;
        worst_exact = std::max(worst_exact, std::fabs(e - want[o]));
        worst_differenced = std::max(worst_differenced, std::fabs(d - want[o]));
      }
    }
    EXPECT_GT(worst_differenced, 1e-4) << to_string(form) << ": the differences at a 10 % step";
    EXPECT_LT(worst_exact, 1e-8) << to_string(form);
  }
}

// The crank-slider written as the notes write Φ, in equations whose texts read L2 and L3, the rod's rational in
// L3: the equations differentiate their texts along the parameters (CompiledExpression::along_constants()), so
// that at steps of 10 % the sensitivities of x_B stay at the closed form to 1e-9, in both forms, where the kept
// models' differences along L3 are off by more than 10⁻⁶.
TEST(Sensitivity, EquationsAreDifferentiatedAlongTheParametersTheirTextsRead) {
  std::string text = test::replace_first(
      kCrankSlider, "  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}\n"
                    "  - {name: rod, type: distance, points: [A, B], length: L3}\n",
      "  - {name: crank_x, type: equation, expr: \"xA - L2*cos(theta2)\", unit: length}\n"
      "  - {name: crank_y, type: equation, expr: \"yA - L2*sin(theta2)\", unit: length}\n"
      "  - {name: rod, type: equation, expr: \"((xB - xA)^2 + yA^2)/L3 - L3\", unit: length}\n");
  text = test::replace_first(text, "sensitivities: [L2, {parameter: L3, step: 1e-3}]",
                             "sensitivities: [{parameter: L2, step: 0.03}, {parameter: L3, step: 0.1}]");
  const auto scenes = own_and_kept(text, "crank_slider_equations.yaml");
  const Scene& s = scenes.first;
  for (const OutputSensitivity& p : s.sweep.sensitivities) {
    ASSERT_TRUE(p.reached) << p.name;
    ASSERT_EQ(p.reached->rates.size(), 1u) << p.name;  // crank_x and crank_y along L2, the rod along L3
    EXPECT_NE(p.reached->rates[0], nullptr) << p.name;
  }
  for (SensitivityForm form : {SensitivityForm::kDirect, SensitivityForm::kAdjoint}) {
    const auto [exact, differenced] = own_and_kept_sweeps(scenes, form);
    const auto [worst_exact, worst_differenced] = slider_deviations(s, exact, differenced, form, false);
    EXPECT_GT(worst_differenced, 1e-6) << to_string(form) << ": the differences at a 10 % step";
    EXPECT_LT(worst_exact, 1e-9) << to_string(form);
  }
}

// The README's crank-slider (test::readme_crank_slider) with its crank, or its rod, at `v`: what
// sensitivity_along() of a model built in code builds the models along L2 and L3 with.
Model readme_slider_along_l2(double v, const Model* share) {
  return test::readme_crank_slider(v, 1.0, MotionLaw::linear(0.0, 2.0), share);
}
Model readme_slider_along_l3(double v, const Model* share) {
  return test::readme_crank_slider(0.3, v, MotionLaw::linear(0.0, 2.0), share);
}

// sensitivity_along() of a model built in code: the four models along L2 and L3 built by the caller's function,
// one at a time, and only the crank's and the rod's constraints kept of them, with their data's rates; the sweep's
// ∂x_B/∂L and its time derivatives meet the closed form to 1e-9 at a 5 % step, and equal those of the four models
// kept whole to 1e-10 at the default step; with no column written, the sweep solves them in the direct form, every
// coordinate's. A function that builds another structure, or none, is refused in a line.
TEST(Sensitivity, ModelsBuiltInCodeHaveTheirParametersDifferentiated) {
  const Model model = test::readme_crank_slider();
  const ModelAtParameter along_l2 = readme_slider_along_l2, along_l3 = readme_slider_along_l3;
  SweepOptions o;
  o.t_begin = 0.0, o.t_end = M_PI, o.steps = 90;
  o.velocities = o.accelerations = true;
  const Index xb = model.coordinate_index("xB");
  const SensitivityLayout layout{model.num_coordinates()};
  for (const bool coarse : {true, false}) {
    std::vector<OutputSensitivity> slim = {sensitivity_along(model, "L2", 0.3, along_l2, coarse ? 0.015 : 0.0),
                                           sensitivity_along(model, "L3", 1.0, along_l3, coarse ? 0.05 : 0.0)};
    for (const OutputSensitivity& p : slim) {
      EXPECT_TRUE(std::all_of(p.models.begin(), p.models.end(), [](const auto& m) { return m == nullptr; }));
      ASSERT_TRUE(p.reached) << p.name;
      ASSERT_EQ(p.reached->rates.size(), 1u) << p.name;
      EXPECT_NE(p.reached->rates[0], nullptr) << p.name;
      EXPECT_EQ(check_sensitivity_models(model, p), "");
    }
    EXPECT_EQ(slim[0].reach->rows, (std::vector<Index>{0, 1}));  // the crank's two rows
    EXPECT_EQ(slim[1].reach->rows, (std::vector<Index>{2}));     // the rod's
    o.sensitivities = slim;
    const SensitivityTrace exact = sweep_sensitivities(model, o);
    ASSERT_EQ(exact.s.size(), 91u);
    // no column written (the plan's coordinate_columns empty): auto solves every coordinate's, the direct form
    EXPECT_EQ(exact.summary.sensitivity_form, SensitivityForm::kDirect);
    for (std::size_t k = 0; k < exact.s.size(); ++k)
      for (std::size_t j = 0; j < 2; ++j) {
        const auto want = slider_sensitivities(exact.rows.t[k], j == 0 ? 2 : 3);
        for (int order = 0; order < 3; ++order)
          EXPECT_NEAR(exact.s[k][layout.offset(j, order) + xb], want[order], 1e-9)
              << "t = " << exact.rows.t[k] << ", L" << (j + 2) << ", order " << order;
      }
    if (coarse) continue;
    o.sensitivities = {sensitivity_along(model, "L2", 0.3, along_l2, 0.0, true),
                       sensitivity_along(model, "L3", 1.0, along_l3, 0.0, true)};
    for (const OutputSensitivity& p : o.sensitivities) {
      EXPECT_TRUE(std::all_of(p.models.begin(), p.models.end(), [](const auto& m) { return m != nullptr; }));
      EXPECT_EQ(p.reached, nullptr);
    }
    const SensitivityTrace kept = sweep_sensitivities(model, o);
    ASSERT_EQ(kept.s.size(), exact.s.size());
    for (std::size_t k = 0; k < kept.s.size(); ++k)
      for (std::size_t i = 0; i < kept.s[k].size(); ++i)
        EXPECT_NEAR(exact.s[k][i], kept.s[k][i], 1e-10 * std::max(1.0, std::fabs(kept.s[k][i]))) << k << " " << i;
  }
  // a function that adds a coordinate away from the nominal value builds another structure
  const ModelAtParameter grows = [](double v, const Model* share) {
    if (v == 0.3) return readme_slider_along_l2(v, share);
    ModelBuilder b;
    b.add_coordinate("x", 0.0);
    b.add_driver("push", 0, MotionLaw::linear(0.0, 1.0));
    return std::move(b).build();
  };
  try {
    (void)sensitivity_along(model, "L2", 0.3, grows);
    ADD_FAILURE() << "a model of another structure was accepted";
  } catch (const Error& e) {
    EXPECT_HAS(std::string(e.what()), "sensitivity to 'L2'");
  }
  EXPECT_THROW((void)sensitivity_along(model, "L2", 0.3, ModelAtParameter{}), Error);
}

// A Stepper (a simulator's own clock) delivers the sensitivities of each step as a sweep's rows: the crank-slider
// built in code, L2 and L3 along it, stepped at uneven times forward and back against the closed form (1e-9), and
// over a grid the very bits of run_sweep in order. The adjoint form and models of another mechanism are refused.
TEST(Sensitivity, AStepperDeliversTheSensitivitiesOfEachStep) {
  const Model model = test::readme_crank_slider();
  StepperOptions so;
  so.sensitivities = {
      sensitivity_along(model, "L2", 0.3, readme_slider_along_l2),
      sensitivity_along(model, "L3", 1.0, readme_slider_along_l3)};
  const Index xb = model.coordinate_index("xB"), n = model.num_coordinates();
  const SensitivityLayout layout{n};
  {
    Stepper stepper(model, so);
    EXPECT_EQ(stepper.sensitivities(), nullptr);  // before the first step
    for (const double t : {0.0, 0.13, 0.4, 0.37, 0.9, 1.55, 1.2, 2.6}) {
      ASSERT_EQ(stepper.step(t), SolveStatus::kSuccess) << t;
      const double* sens = stepper.sensitivities();
      ASSERT_NE(sens, nullptr);
      for (std::size_t j = 0; j < 2; ++j) {
        const auto want = slider_sensitivities(t, j == 0 ? 2 : 3);
        for (int order = 0; order < 3; ++order)
          EXPECT_NEAR(sens[layout.offset(j, order) + xb], want[order], 1e-9) << "t = " << t << ", L" << (j + 2);
      }
    }
  }
  // over a grid: run_sweep's rows in order, to the bit
  SweepOptions o;
  o.t_begin = 0.0, o.t_end = M_PI, o.steps = 30, o.chunk_steps = 30;
  o.velocities = o.accelerations = true;
  o.sensitivities = so.sensitivities;
  const SensitivityTrace swept = sweep_sensitivities(model, o);
  ASSERT_EQ(swept.s.size(), 31u);
  Stepper stepper(model, so);
  for (Index k = 0; k <= o.steps; ++k) {
    ASSERT_EQ(stepper.step(o.time_of(k)), SolveStatus::kSuccess) << k;
    const std::vector<double>& want = swept.s[static_cast<std::size_t>(k)];
    ASSERT_EQ(want.size(), static_cast<std::size_t>(layout.size(2)));
    EXPECT_EQ(std::memcmp(stepper.sensitivities(), want.data(), sizeof(double) * want.size()), 0) << "row " << k;
  }
  StepperOptions adjoint = so;
  adjoint.sensitivity_form = SensitivityForm::kAdjoint;
  EXPECT_THROW(Stepper(model, adjoint), Error);
  StepperOptions other = so;
  other.sensitivities = {sensitivity_along(slot_by_arc(0.5), "r", 0.5, [](double v, const Model* m) {
    return slot_by_arc(v, m);
  })};
  try {
    Stepper refused(model, other);
    ADD_FAILURE() << "models of another mechanism were accepted";
  } catch (const Error& e) {
    EXPECT_HAS(std::string(e.what()), "StepperOptions: sensitivity to 'r'");
  }
}

// The eccentric circular cam under a translating roller follower (models/cams/eccentric_roller.yaml): the roller's
// radius ρ moves the cam constraint's offset and not its curve (no co-moving contact), so the constraint
// differentiates its own data and the follower's height y = e sin θ + D, D = √((R + ρ)² − e² cos² θ), has
//   ∂y/∂ρ = A/D,   ∂ẏ/∂ρ = −ω N A/D³,   ∂ÿ/∂ρ = ω² (3 N² A/D⁵ − e² cos 2θ A/D³),   A = R + ρ, N = e² sin θ cos θ,
// θ = ω t: to 1e-9 of their scale in both forms, at a step of 40 % of ρ (the kind's derivative does not depend on
// it). The kept models' differences agree to 1e-10: at fixed q the constraint is linear in ρ, so its differences
// are exact too; what the kind's own derivative saves is the four copies of the constraint and their evaluations.
TEST(Sensitivity, ARollersRadiusIsDifferentiatedByTheCamConstraint) {
  const std::string text = test::replace_first(test::slurp(model_path("cams/eccentric_roller.yaml")),
                                               "output: {velocities: true, accelerations: true}",
                                               "output: {velocities: true, accelerations: true, sensitivities: "
                                               "[{parameter: rho, step: 0.004}]}");
  const auto scenes = own_and_kept(text, "eccentric_roller.yaml");
  const Scene& s = scenes.first;
  ASSERT_EQ(s.sweep.sensitivities.size(), 1u);
  const OutputSensitivity& p = s.sweep.sensitivities[0];
  ASSERT_TRUE(p.reached);
  EXPECT_TRUE(p.reach->comotion.empty());
  ASSERT_EQ(p.reached->rates.size(), 1u);  // the cam constraint alone
  EXPECT_NE(p.reached->rates[0], nullptr);
  const double R = 0.05, e = 0.015, rho = 0.01, w = 2.0, A = R + rho;
  const Index yf = s.model->coordinate_index("yf");
  const SensitivityLayout layout{s.model->num_coordinates()};
  for (SensitivityForm form : {SensitivityForm::kDirect, SensitivityForm::kAdjoint}) {
    const auto [exact, differenced] = own_and_kept_sweeps(scenes, form);
    ASSERT_EQ(exact.s.size(), 73u);
    ASSERT_EQ(differenced.s.size(), exact.s.size());
    double worst_exact = 0.0, worst_differenced = 0.0;
    for (std::size_t k = 0; k < exact.s.size(); ++k) {
      const double th = w * exact.rows.t[k], c = std::cos(th), sn = std::sin(th);
      const double D = std::sqrt(A * A - e * e * c * c), N = e * e * sn * c;
      const double d3 = std::pow(D, 3), d5 = std::pow(D, 5);
      const double want[3] = {A / D, -w * N * A / d3, w * w * (3.0 * N * N * A / d5 - e * e * std::cos(2.0 * th) * A / d3)};
      const double scale[3] = {1.0, w, w * w};
      for (int o = 0; o < 3; ++o) {
        worst_exact = std::max(worst_exact, std::fabs(exact.s[k][layout.offset(0, o) + yf] - want[o]) / scale[o]);
        worst_differenced =
            std::max(worst_differenced, std::fabs(differenced.s[k][layout.offset(0, o) + yf] - want[o]) / scale[o]);
      }
    }
    EXPECT_LT(worst_exact, 1e-9) << to_string(form);
    EXPECT_LT(worst_differenced, 1e-9) << to_string(form);
    for (std::size_t k = 0; k < exact.s.size(); ++k)
      for (int o = 0; o < 3; ++o) {
        const double d = differenced.s[k][layout.offset(0, o) + yf];
        EXPECT_NEAR(exact.s[k][layout.offset(0, o) + yf], d, 1e-10 * std::max(1.0, std::fabs(d))) << to_string(form);
      }
  }
}

// The RSSR four-bar in space: its crank's and rocker's arms (a, b: the coupler's ends on the bodies), the rocker's
// ground hinge (d, e: a revolute's folded ground attachment) and the coupler's length reach constraints whose kinds
// differentiate their own data (a spatial distance, a revolute), read through the scene: every reached span holds
// its rates, and the sensitivities are those of the four models' differences (exact here too: the data are linear
// in the parameters and the rows quadratic) to 1e-9 of their scale, in both forms.
TEST(Sensitivity, SpatialJointsDifferentiateTheirDataThroughTheScene) {
  const std::string text = test::replace_first(
      test::slurp(model_path("spatial/rssr.yaml")), "output: {velocities: true, accelerations: true}",
      "output: {velocities: true, accelerations: true, sensitivities: [a, b, d, e, L]}");
  const auto scenes = own_and_kept(text, "rssr.yaml");
  const Scene& s = scenes.first;
  ASSERT_EQ(s.sweep.sensitivities.size(), 5u);
  for (const OutputSensitivity& p : s.sweep.sensitivities) {
    ASSERT_TRUE(p.reached) << p.name;
    ASSERT_FALSE(p.reached->rates.empty()) << p.name;
    for (const auto& r : p.reached->rates) EXPECT_NE(r, nullptr) << p.name;
  }
  for (SensitivityForm form : {SensitivityForm::kDirect, SensitivityForm::kAdjoint}) {
    const auto [exact, differenced] = own_and_kept_sweeps(scenes, form);
    ASSERT_EQ(exact.s.size(), 73u);
    ASSERT_EQ(differenced.s.size(), exact.s.size());
    double scale = 0.0, worst = 0.0;
    for (std::size_t k = 0; k < exact.s.size(); ++k)
      for (std::size_t i = 0; i < exact.s[k].size(); ++i) {
        if (std::isnan(exact.s[k][i]) && std::isnan(differenced.s[k][i])) continue;  // coordinates not written
        scale = std::max(scale, std::fabs(differenced.s[k][i]));
        worst = std::max(worst, std::fabs(exact.s[k][i] - differenced.s[k][i]));
      }
    EXPECT_GT(scale, 0.1) << to_string(form);
    EXPECT_LT(worst, 1e-9 * scale) << to_string(form);
  }
}

// The notes' four-bar in bars (natural coordinates: distances) and in pins (reference-point coordinates: L3 in the
// coupler's and rocker's local points, L1 in the rocker's ground pivot) is one mechanism: the sensitivities of its
// point B to L1 and L3, and their time derivatives, are the same in both, each kind giving its own derivatives. At a
// 6 % step, where the bars' differences would be off by 2(h/L)⁴ ≈ 3·10⁻⁵.
TEST(Sensitivity, TheFourBarInBarsAndInPinsHasOneSensitivity) {
  const std::string output = "output: {velocities: true, accelerations: true, sensitivities: "
                             "[{parameter: L1, step: 0.06}, {parameter: L3, step: 0.072}]}";
  auto read = [&](const char* rel) {
    const std::string text = test::slurp(model_path(rel));
    return parse_scene(test::replace_first(text, "output: {velocities: true, accelerations: true}", output), rel);
  };
  const Scene bars = read("seed/fourbar_natural.yaml"), pins = read("seed/fourbar_reference_point.yaml");
  for (const Scene* s : {&bars, &pins})
    for (const OutputSensitivity& p : s->sweep.sensitivities)
      for (const auto& r : p.reached->rates) EXPECT_NE(r, nullptr) << p.name;  // every reached span its own
  const SensitivityTrace a = sweep_sensitivities(*bars.model, bars.sweep), b = sweep_sensitivities(*pins.model, pins.sweep);
  ASSERT_EQ(a.s.size(), 361u);
  ASSERT_EQ(b.s.size(), 361u);
  const Model& mb = *bars.model;
  const Model& mp = *pins.model;
  const Index xb = mb.coordinate_index("xB"), yb = mb.coordinate_index("yB");
  const Index x4 = mp.coordinate_index("x4"), y4 = mp.coordinate_index("y4"), p4 = mp.coordinate_index("psi4");
  const SensitivityLayout la{mb.num_coordinates()}, lp{mp.num_coordinates()};
  const double half = 0.5;  // B = r4 + R(ψ4) (L4/2, 0), L4 = 1
  double worst = 0.0;
  for (std::size_t k = 0; k < a.s.size(); ++k) {
    const double psi = b.rows.q[k][p4], w = b.rows.qd[k][p4], al = b.rows.qdd[k][p4];
    const double ux = half * std::cos(psi), uy = half * std::sin(psi);  // R s, and its perp (−uy, ux)
    for (std::size_t j = 0; j < 2; ++j) {
      auto at = [&](int o, Index i) { return b.s[k][lp.offset(j, o) + i]; };
      const double s0 = at(0, p4), s1 = at(1, p4), s2 = at(2, p4);
      // ∂B/∂p, ∂Ḃ/∂p, ∂B̈/∂p from the rocker's ∂r4/∂p, ∂ψ4/∂p and their time derivatives
      const double want[3][2] = {
          {at(0, x4) - uy * s0, at(0, y4) + ux * s0},
          {at(1, x4) - uy * s1 - ux * w * s0, at(1, y4) + ux * s1 - uy * w * s0},
          {at(2, x4) - uy * s2 - ux * (al * s0 + 2 * w * s1) + uy * w * w * s0,
           at(2, y4) + ux * s2 - uy * (al * s0 + 2 * w * s1) - ux * w * w * s0}};
      for (int o = 0; o < 3; ++o) {
        const double got[2] = {a.s[k][la.offset(j, o) + xb], a.s[k][la.offset(j, o) + yb]};
        for (int c = 0; c < 2; ++c) {
          EXPECT_NEAR(got[c], want[o][c], 1e-8 * std::max(1.0, std::fabs(want[o][c])))
              << "t = " << a.rows.t[k] << (j ? ", L3" : ", L1") << ", order " << o << (c ? ", y" : ", x");
          worst = std::max(worst, std::fabs(got[c] - want[o][c]));
        }
      }
    }
  }
  EXPECT_LT(worst, 1e-8);
}

// Bars between natural points and a linear driver: Φq is linear in q, so its second difference along the motion is
// rounding alone, which the smoothness check does not take for a knot: no row leaves the adjoint form, and its
// values are the direct form's.
TEST(Sensitivity, ALinearJacobianKeepsEveryRowAdjoint) {
  const char* bars = R"(phiq: 1
parameters: {L2: 0.3, L3: 1.0}
coordinates: {xA: 0.0, yA: 0.3, xB: 0.96}
points: {O: [0, 0], A: [xA, yA], B: [xB, 0]}
constraints:
  - {name: crank, type: distance, points: [O, A], length: L2}
  - {name: rod, type: distance, points: [A, B], length: L3}
drivers:
  - {name: push, coordinate: xA, law: {type: linear, initial: 0, rate: 0.2}}
time: {start: 0, end: 1, steps: 50}
output: {coordinates: [xB], velocities: true, accelerations: true, sensitivities: [L2, L3]}
)";
  const Scene s = parse_scene(bars, "bars.yaml");
  SweepOptions direct = s.sweep, adjoint = s.sweep;
  direct.sensitivity_form = SensitivityForm::kDirect;
  adjoint.sensitivity_form = SensitivityForm::kAdjoint;
  const SensitivityTrace d = sweep_sensitivities(*s.model, direct), a = sweep_sensitivities(*s.model, adjoint);
  EXPECT_EQ(a.summary.counters.sensitivity_direct_rows, 0);
  const Index xb = s.model->coordinate_index("xB");
  const SensitivityLayout layout{s.model->num_coordinates()};
  ASSERT_EQ(a.s.size(), 51u);
  for (std::size_t k = 0; k < a.s.size(); ++k)
    for (std::size_t j = 0; j < 2; ++j)
      for (int o = 0; o < 3; ++o) {
        const Index at = layout.offset(j, o) + xb;
        EXPECT_NEAR(a.s[k][at], d.s[k][at], 1e-10 * std::max(1.0, std::fabs(d.s[k][at]))) << k << " " << j << " " << o;
      }
}

// The form is chosen by cost (effective_sensitivity_form): positions only, the crank-slider's slider xB alone to
// L2 and L3 is solved in the adjoint form by itself (one solve a row where the direct form takes two) and is the
// closed form's to 1e-9; with q̇ and q̈ one parameter does not pay for the adjoint's 15 evaluations of Φq a row
// (the direct form's 3 solves and 8 evaluations), two do: the adjoint gives the direct form's values in 4 solves a
// row (λ, μ, τ, ν) where the direct form takes 6. The coordinates not written are NaN in the adjoint form.
TEST(Sensitivity, TheFormIsChosenByItsCost) {
  const std::string one = test::replace_first(kCrankSlider, "output: {", "output: {coordinates: [xB], ");
  const std::string positions =
      test::replace_first(one, "velocities: true, accelerations: true", "velocities: false, accelerations: false");
  const Scene sp = parse_scene(positions, "crank_slider.yaml");
  const SensitivityTrace rp = sweep_sensitivities(*sp.model, sp.sweep);
  EXPECT_EQ(rp.summary.sensitivity_form, SensitivityForm::kAdjoint);
  EXPECT_EQ(rp.summary.counters.sensitivity_solves, 91);
  EXPECT_HAS(rp.summary.BriefReport(), "91 sensitivity solves (adjoint)");
  const Index n = sp.model->num_coordinates(), xb = sp.model->coordinate_index("xB");
  const SensitivityLayout layout{n};
  ASSERT_EQ(rp.s.size(), 91u);
  for (std::size_t k = 0; k < rp.s.size(); ++k)
    for (int which : {2, 3}) {
      const std::size_t j = which == 2 ? 0 : 1;
      EXPECT_NEAR(rp.s[k][layout.offset(j, 0) + xb], slider_derivatives(2.0 * rp.rows.t[k], 0.3, 1.0, which)[0], 1e-9);
      for (Index i = 0; i < n; ++i) {
        if (i != xb) {
          EXPECT_TRUE(std::isnan(rp.s[k][layout.offset(j, 0) + i]));
        }
      }
    }

  // With q̇ and q̈ and one output: the direct form for one parameter, the adjoint from two.
  const Scene single = parse_scene(
      test::replace_first(one, "sensitivities: [L2, {parameter: L3, step: 1e-3}]", "sensitivities: [L2]"),
      "crank_slider.yaml");
  const SensitivityTrace rs = sweep_sensitivities(*single.model, single.sweep);
  EXPECT_EQ(rs.summary.sensitivity_form, SensitivityForm::kDirect);
  EXPECT_EQ(rs.summary.counters.sensitivity_solves, 91 * 3);
  const Scene forced = parse_scene(
      test::replace_first(one, "output: {", "output: {sensitivity_form: direct, "), "crank_slider.yaml");
  EXPECT_EQ(forced.sweep.sensitivity_form, SensitivityForm::kDirect);
  const SensitivityTrace direct = sweep_sensitivities(*forced.model, forced.sweep);
  EXPECT_EQ(direct.summary.sensitivity_form, SensitivityForm::kDirect);
  EXPECT_EQ(direct.summary.counters.sensitivity_solves, 91 * 2 * 3);
  const Scene s = parse_scene(one, "crank_slider.yaml");
  EXPECT_EQ(s.sweep.sensitivity_form, SensitivityForm::kAuto);
  const SensitivityTrace r = sweep_sensitivities(*s.model, s.sweep);
  EXPECT_EQ(r.summary.sensitivity_form, SensitivityForm::kAdjoint);
  EXPECT_EQ(r.summary.counters.sensitivity_solves, 91 * 4);
  EXPECT_HAS(r.summary.BriefReport(), "364 sensitivity solves (adjoint)");
  ASSERT_EQ(r.s.size(), 91u);
  for (std::size_t k = 0; k < r.s.size(); ++k)
    for (int which : {2, 3}) {
      const std::size_t j = which == 2 ? 0 : 1;
      const auto want = slider_sensitivities(r.rows.t[k], which);
      for (int o = 0; o < 3; ++o) {
        const double got = r.s[k][layout.offset(j, o) + xb], d = direct.s[k][layout.offset(j, o) + xb];
        EXPECT_NEAR(got, want[o], 1e-9) << "t = " << r.rows.t[k] << ", L" << which << ", order " << o;
        EXPECT_NEAR(got, d, 1e-10 * std::max(1.0, std::fabs(d))) << "t = " << r.rows.t[k];
        for (Index i = 0; i < n; ++i) {
          if (i != xb) {
            EXPECT_TRUE(std::isnan(r.s[k][layout.offset(j, o) + i]));
          }
        }
      }
    }
  EXPECT_EQ(test::scene_error(test::replace_first(one, "output: {", "output: {sensitivity_form: sideways, ")),
            "bad.yaml:12:28: output.sensitivity_form: sensitivity_form is auto, direct or adjoint");
  // the rule: P ((order + 1) solves and (0, 2, 8) evaluations) against O·(1, 2, 4) solves and (0, 4, 15)
  // evaluations, an evaluation at half a solve
  EXPECT_EQ(effective_sensitivity_form(SensitivityForm::kAuto, 2, 2, 0), SensitivityForm::kDirect);
  EXPECT_EQ(effective_sensitivity_form(SensitivityForm::kAuto, 3, 2, 0), SensitivityForm::kAdjoint);
  EXPECT_EQ(effective_sensitivity_form(SensitivityForm::kAuto, 1, 1, 1), SensitivityForm::kDirect);  // 3, 4
  EXPECT_EQ(effective_sensitivity_form(SensitivityForm::kAuto, 2, 1, 1), SensitivityForm::kAdjoint);
  EXPECT_EQ(effective_sensitivity_form(SensitivityForm::kAuto, 1, 1, 2), SensitivityForm::kDirect);  // 7, 11.5
  EXPECT_EQ(effective_sensitivity_form(SensitivityForm::kAuto, 2, 1, 2), SensitivityForm::kAdjoint);  // 14, 11.5
  EXPECT_EQ(effective_sensitivity_form(SensitivityForm::kAuto, 2, 2, 2), SensitivityForm::kDirect);  // 14, 15.5
  EXPECT_EQ(effective_sensitivity_form(SensitivityForm::kAuto, 3, 2, 2), SensitivityForm::kAdjoint);
  EXPECT_EQ(effective_sensitivity_form(SensitivityForm::kAdjoint, 1, 9, 2), SensitivityForm::kAdjoint);
  EXPECT_EQ(effective_sensitivity_form(SensitivityForm::kDirect, 9, 1, 0), SensitivityForm::kDirect);
}

TEST(Sensitivity, SolveSensitivitiesAdjointOnAWorkspace) {
  const Scene s = parse_scene(kCrankSlider, "crank_slider.yaml");
  const SensitivityTrace r = sweep_sensitivities(*s.model, s.sweep);
  Workspace ws(*s.model);
  const std::size_t k = 37;
  ws.q = r.rows.q[k], ws.qd = r.rows.qd[k], ws.qdd = r.rows.qdd[k];
  const Index xa = s.model->coordinate_index("xA"), xb = s.model->coordinate_index("xB");
  std::vector<double> out(r.s[k].size());
  LinearSummary ls;
  ASSERT_EQ(solve_sensitivities_adjoint(*s.model, s.sweep.sensitivities, {xb, xa}, r.rows.t[k], 2, ws, out.data(), &ls),
            SolveStatus::kSuccess)
      << ls.message;
  const SensitivityLayout layout{s.model->num_coordinates()};
  for (std::size_t j = 0; j < 2; ++j)
    for (int o = 0; o < 3; ++o)
      for (Index i = 0; i < s.model->num_coordinates(); ++i) {
        const double got = out[static_cast<std::size_t>(layout.offset(j, o) + i)];
        if (i == xa || i == xb) {
          EXPECT_NEAR(got, r.s[k][layout.offset(j, o) + i], 1e-10) << j << " " << o << " " << i;
        } else {
          EXPECT_TRUE(std::isnan(got));
        }
      }
  EXPECT_THROW((void)solve_sensitivities_adjoint(*s.model, s.sweep.sensitivities, {xb, xb}, 0.0, 2, ws, out.data()),
               Error);
  EXPECT_THROW((void)solve_sensitivities_adjoint(*s.model, s.sweep.sensitivities, {4}, 0.0, 2, ws, out.data()), Error);
}

}  // namespace
}  // namespace phiq
