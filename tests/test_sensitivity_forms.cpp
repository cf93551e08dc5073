// The two forms of a row's sensitivities (SensitivityForm, sensitivity.hpp): the adjoint form against the direct
// one on planar, spatial, redundant scenes and across a spline's knots, on a linear Jacobian, the form chosen by
// its cost (effective_sensitivity_form), and solve_sensitivities_adjoint() on a workspace.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "cli_test_support.hpp"  // test::slurp
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
using test::slider_sensitivities;
using test::sweep_sensitivities;

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
  const Scene single =
      parse_scene(test::replace_first(one, "sensitivities: [L2, {parameter: L3, step: 1e-3}]", "sensitivities: [L2]"),
                  "crank_slider.yaml");
  const SensitivityTrace rs = sweep_sensitivities(*single.model, single.sweep);
  EXPECT_EQ(rs.summary.sensitivity_form, SensitivityForm::kDirect);
  EXPECT_EQ(rs.summary.counters.sensitivity_solves, 91 * 3);
  const Scene forced =
      parse_scene(test::replace_first(one, "output: {", "output: {sensitivity_form: direct, "), "crank_slider.yaml");
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
  EXPECT_EQ(effective_sensitivity_form(SensitivityForm::kAuto, 1, 1, 2), SensitivityForm::kDirect);   // 7, 11.5
  EXPECT_EQ(effective_sensitivity_form(SensitivityForm::kAuto, 2, 1, 2), SensitivityForm::kAdjoint);  // 14, 11.5
  EXPECT_EQ(effective_sensitivity_form(SensitivityForm::kAuto, 2, 2, 2), SensitivityForm::kDirect);   // 14, 15.5
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
