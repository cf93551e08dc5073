// Sensitivities where the reached kinds differentiate their own data (DataDifferentiable, sensitivity.hpp): the
// crank-slider's polar and distance, a driver's law, equations along the parameters their texts read, a cam
// constraint along its roller's radius, the spatial joints through the scene, the four-bar in bars and in pins;
// each against its closed form and the kept models' differences.
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

using test::kCrankSlider;
using test::model_path;
using test::SensitivityTrace;
using test::slider_sensitivities;
using test::slider_theta_derivatives;
using test::sweep_sensitivities;

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
  const std::string coarse =
      test::replace_first(kCrankSlider, "sensitivities: [L2, {parameter: L3, step: 1e-3}]",
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
  std::string text =
      test::replace_first(kCrankSlider,
                          "  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}\n"
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
      const double want[3] = {A / D, -w * N * A / d3,
                              w * w * (3.0 * N * N * A / d5 - e * e * std::cos(2.0 * th) * A / d3)};
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
  const std::string output =
      "output: {velocities: true, accelerations: true, sensitivities: "
      "[{parameter: L1, step: 0.06}, {parameter: L3, step: 0.072}]}";
  auto read = [&](const char* rel) {
    const std::string text = test::slurp(model_path(rel));
    return parse_scene(test::replace_first(text, "output: {velocities: true, accelerations: true}", output), rel);
  };
  const Scene bars = read("seed/fourbar_natural.yaml"), pins = read("seed/fourbar_reference_point.yaml");
  for (const Scene* s : {&bars, &pins})
    for (const OutputSensitivity& p : s->sweep.sensitivities)
      for (const auto& r : p.reached->rates) EXPECT_NE(r, nullptr) << p.name;  // every reached span its own
  const SensitivityTrace a = sweep_sensitivities(*bars.model, bars.sweep),
                         b = sweep_sensitivities(*pins.model, pins.sweep);
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
      const double want[3][2] = {{at(0, x4) - uy * s0, at(0, y4) + ux * s0},
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

}  // namespace
}  // namespace phiq
