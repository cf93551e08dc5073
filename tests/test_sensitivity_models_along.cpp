// The models along a design parameter (sensitivity.hpp): a curve's parameter co-moving with the parameter (a cam's
// radius over ten turns, a pin driven along a circular slot), the four models released but for the parameter's
// reach, models built in code by the caller's function (sensitivity_along()), and a Stepper delivering each step's
// sensitivities.
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

using test::model_path;
using test::SensitivityTrace;
using test::slider_sensitivities;
using test::sweep_sensitivities;

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
      const double exact[3][3] = {{1.0, 0.0, 0.0},                                                    // R
                                  {sn, w * c, -w * w * sn},                                           // e
                                  {e * t * c, e * (c - w * t * sn), -e * w * (2 * sn + w * t * c)}};  // ω
      for (std::size_t j = 0; j < 3; ++j)
        for (int order = 0; order < 3; ++order)
          worst[j][order] = std::max(worst[j][order], std::fabs(r.s[k][layout.offset(j, order) + y] - exact[j][order]));
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
  const Index x = b.add_coordinate("x", 0.2 + r * std::cos(s0 / r)),
              y = b.add_coordinate("y", 0.1 + r * std::sin(s0 / r));
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
      const double want[3][2] = {
          {c + phi * sn, sn - phi * c}, {g * phi * c, g * phi * sn}, {g * g * (c - phi * sn), g * g * (sn + phi * c)}};
      for (int order = 0; order < 3; ++order) {
        worst = std::max(worst, std::fabs(tr.s[k][layout.offset(0, order) + xi] - want[order][0]));
        worst = std::max(worst, std::fabs(tr.s[k][layout.offset(0, order) + yi] - want[order][1]));
        worst = std::max(worst, std::fabs(tr.s[k][layout.offset(0, order) + s_index]));  // s is driven
      }
    }
    EXPECT_LE(worst, 1e-9) << to_string(form);
  }
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
  so.sensitivities = {sensitivity_along(model, "L2", 0.3, readme_slider_along_l2),
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
  other.sensitivities = {
      sensitivity_along(slot_by_arc(0.5), "r", 0.5, [](double v, const Model* m) { return slot_by_arc(v, m); })};
  try {
    Stepper refused(model, other);
    ADD_FAILURE() << "models of another mechanism were accepted";
  } catch (const Error& e) {
    EXPECT_HAS(std::string(e.what()), "StepperOptions: sensitivity to 'r'");
  }
}

}  // namespace
}  // namespace phiq
