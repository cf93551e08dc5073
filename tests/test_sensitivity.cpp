// Sensitivities to design parameters (phiq/sensitivity.hpp) in a sweep: ∂q/∂p, ∂q̇/∂p, ∂q̈/∂p against
// closed forms (the crank-slider's slider, differentiated exactly by nested dual numbers; the redundant
// parallelogram), against central differences of two re-solved sweeps (planar, spatial, redundant scenes), over
// thread counts, in positions-only sweeps (same bits of q as without them), the caller's requests and the scene's
// refusals. The adjoint form: test_sensitivity_forms.cpp; the models along a parameter:
// test_sensitivity_models_along.cpp; the kinds' own derivatives of their data: test_sensitivity_data_derivatives.cpp.
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
#include "sensitivity_support.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

using test::along;
using test::kCrankSlider;
using test::model_path;
using test::SensitivityTrace;
using test::slider_derivatives;
using test::sweep;
using test::sweep_sensitivities;
using test::Trace;

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
    (void)run_sweep(
        *s.model, plain, ws, [](const StepView&) { return true; }, &t.summary);
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
  EXPECT_EQ(refused({{"L9", 0.0}}, true),
            "cases.csv: 'L9' is not a parameter of crank_slider.yaml (its parameters: "
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
    EXPECT_EQ(std::string(e.what()),
              "with L3 = -0.19999999999999996 (the difference step 0.6 from 1) the scene "
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
  const std::string text =
      test::replace_first(test::replace_first(kCrankSlider, "{L2: 0.3, L3: 1.0}", "{L2: 0.3, L3: 1.0, unused: 5}"),
                          "sensitivities: [L2, {parameter: L3, step: 1e-3}]", "sensitivities: [unused]");
  const Scene s = parse_scene(text, "c.yaml");
  const SensitivityTrace r = sweep_sensitivities(*s.model, s.sweep);
  for (const auto& row : r.s)
    for (double v : row) EXPECT_EQ(v, 0.0);
  ASSERT_EQ(r.summary.warnings.size(), 1u);
  EXPECT_EQ(r.summary.warnings[0].kind, "no_dependence");
  EXPECT_EQ(r.summary.warnings[0].message,
            "no constraint or driver reads the parameter 'unused': its sensitivities are zero");
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
  EXPECT_EQ(test::scene_error(with("[L2, L2]")),
            "bad.yaml:12:69: output.sensitivities[1]: parameter 'L2' listed twice");
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

}  // namespace
}  // namespace phiq
