// Sensitivities of the drivers' efforts to the scene's parameters (phiq/effort_sensitivity.hpp, columns
// `NAME.effort.d_P`): a pendulum driven with a constant angular acceleration against its closed form
// τ = m g l cos θ + (I + m l²) α, and a massive crank-slider (polar crank, a load at the slider's pin) and the
// massive four-bar of models/dynamics (natural coordinates) and a spatial RSSR, also with torsional springs on its
// hinges' angles, parts and loads on frames of expressions, and forces of the rates (der()) and laws of them,
// against central differences of whole sweeps re-solved at p ± δ, p ± δ/2 (Richardson), every row; the columns as the
// CSV names them. A crank-slider whose parameters reach a length, a mass, a frame, gravity, a force, a spring and a
// torsional spring carries parts and loads along p only for those that move them, and writes the same bits as with its
// own forces along every parameter.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <sstream>

#include "phiq/effort_sensitivity.hpp"
#include "phiq/phiq.hpp"
#include "fourbar_parts.hpp"
#include "reaction_rows.hpp"
#include "sensitivity_support.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

using test::effort_rows_sweep;
using test::expect_effort_sensitivities_match_resolved_sweeps;
using EffortSensitivityRows = test::EffortRows;

const char* const kEffortPendulum = R"(phiq: 1
name: pendulum
parameters: {L: 0.8, mb: 1.5}
coordinates: {x: 0.8, y: 0.0, th: 0.0}
points: {O: [0, 0], P: [x, y]}
constraints:
  - {name: rod, type: distance, points: [O, P], length: L}
  - {name: rod_angle, type: segment_angle, segment: [O, P], angle: th}
drivers:
  - {name: motor, coordinate: th, law: {type: polynomial, coefficients: [0.3, 2, 1.5]}}
parts:
  bob: {frame: {origin: O, x: P}, center_of_mass: [L, 0], mass: mb, inertia: 0.02}
loads: {gravity: [0, -9.81]}
time: {start: 0, end: 2, steps: 40}
output: {efforts: all, sensitivities: [L, mb]}
)";

TEST(EffortSensitivity, APendulumsTorqueFollowsItsClosedFormInLengthAndMass) {
  // θ = 0.3 + 2t + 1.5t², α = 3: τ = m g L cos θ + (I + m L²) α, so ∂τ/∂L = m g cos θ + 2 m L α and
  // ∂τ/∂m = g L cos θ + L² α, exactly (the mass reaches no constraint: its part alone).
  const Scene s = parse_scene(kEffortPendulum, "pendulum.yaml");
  const EffortSensitivityRows r = effort_rows_sweep(s);
  ASSERT_EQ(r.t.size(), 41u);
  const double g = 9.81, L = 0.8, m = 1.5, I = 0.02, alpha = 3.0;
  const std::size_t at = static_cast<std::size_t>(s.sweep.efforts.size());
  double worst_tau = 0.0, worst_l = 0.0, worst_m = 0.0;
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    const double t = r.t[k], th = 0.3 + 2 * t + 1.5 * t * t;
    worst_tau = std::max(worst_tau, std::fabs(r.values[k][0] - (m * g * L * std::cos(th) + (I + m * L * L) * alpha)));
    worst_l = std::max(worst_l, std::fabs(r.values[k][at] - (m * g * std::cos(th) + 2 * m * L * alpha)));
    worst_m = std::max(worst_m, std::fabs(r.values[k][at + 1] - (g * L * std::cos(th) + L * L * alpha)));
  }
  ::testing::Test::RecordProperty(
      "worst_tau_L_m", scientific(worst_tau, 2) + " " + scientific(worst_l, 2) + " " + scientific(worst_m, 2));
  // scales: |∂τ/∂L| up to 22, |∂τ/∂m| up to 10
  EXPECT_LT(worst_tau, 1e-9);
  EXPECT_LT(worst_l, 1e-8);
  EXPECT_LT(worst_m, 1e-8);
  // in the API too, at the sweep's last row
  std::vector<double> d;
  std::string why;
  Workspace at_end(*s.model);
  SweepOptions o = s.sweep;
  o.sensitivities.clear(), o.efforts = OutputEfforts{};
  o.velocities = o.accelerations = true;
  ASSERT_EQ(run_sweep(
                *s.model, o, at_end, [](const StepView&) { return true; }, nullptr),
            SolveStatus::kSuccess);
  ASSERT_EQ(solve_effort_sensitivities(*s.model, s.sweep.efforts, s.sweep.sensitivities, 2.0, at_end, d, &why),
            SolveStatus::kSuccess)
      << why;
  ASSERT_EQ(d.size(), 4u);  // ∂τ/∂L, ∂τ/∂m, then the power's
  EXPECT_NEAR(d[0], r.values.back()[at], 1e-9);
  EXPECT_NEAR(d[1], r.values.back()[at + 1], 1e-9);
}

TEST(EffortSensitivity, AStepperDeliversThePendulumsClosedForm) {
  // The Stepper finds each parameter's reach once, at construction (its steps need it: ∂τ/∂p requires it), and
  // delivers ∂τ/∂L and ∂τ/∂m as the sweep does: the closed form of the test above at every step.
  const Scene s = parse_scene(kEffortPendulum, "pendulum.yaml");
  StepperOptions o;
  o.sensitivities = s.sweep.sensitivities;
  o.efforts = s.sweep.efforts;
  Stepper stepper(*s.model, o);
  const double g = 9.81, L = 0.8, m = 1.5, alpha = 3.0;
  const std::size_t at = static_cast<std::size_t>(s.sweep.efforts.size());
  for (const double t : {0.0, 0.35, 0.7, 1.4}) {
    ASSERT_EQ(stepper.step(t), SolveStatus::kSuccess) << t;
    ASSERT_NE(stepper.efforts(), nullptr);
    const double th = 0.3 + 2 * t + 1.5 * t * t;
    EXPECT_NEAR(stepper.efforts()[at], m * g * std::cos(th) + 2 * m * L * alpha, 1e-8) << t;
    EXPECT_NEAR(stepper.efforts()[at + 1], g * L * std::cos(th) + L * L * alpha, 1e-8) << t;
  }
}

TEST(EffortSensitivity, AMassiveCrankSlidersTorqueMatchesResolvedSweeps) {
  // The notes' crank-slider (a polar crank: its data differentiated by the kinds) with massive crank and rod and
  // 5 N pushing back on the slider's pin, which the rod's part carries at its end (L3 moves where it acts).
  expect_effort_sensitivities_match_resolved_sweeps(R"(phiq: 1
name: crank_slider
parameters: {L2: 0.3, L3: 1.0}
coordinates: {theta2: 0.0, xA: 0.28, yA: 0.03, xB: 1.25}
points: {O: [0, 0], A: [xA, yA], B: [xB, 0]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}
  - {name: rod, type: distance, points: [A, B], length: L3}
drivers:
  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 2}}
parts:
  crank: {frame: {origin: O, x: A}, center_of_mass: [L2/2, 0], mass: 0.5, inertia: 0.5*L2*L2/12}
  rod: {frame: {origin: A, x: B}, center_of_mass: [L3/2, 0], mass: 1.2, inertia: 1.2*L3*L3/12}
loads:
  gravity: [0, -9.81]
  forces: [{name: push, part: rod, at: [L3, 0], force: [-5, 0]}]
time: {start: 0, end: pi, steps: 60}
output: {efforts: all, sensitivities: [L2, L3]}
)");
}

// The crank-slider's massive crank and rod under gravity, with `loads` (forces), over half a turn.
std::string massive_crank_slider_with(const std::string& loads, const std::string& output) {
  return test::crank_slider_scene(
      ", c: 4",
      "parts:\n"
      "  crank: {frame: {origin: O, x: A}, center_of_mass: [L2/2, 0], mass: 0.5, inertia: 0.5*L2*L2/12}\n"
      "  rod: {frame: {origin: A, x: B}, center_of_mass: [L3/2, 0], mass: 1.2, inertia: 1.2*L3*L3/12}\n"
      "loads:\n  gravity: [0, -9.81]\n  forces:\n" +
          loads + "time: {start: 0, end: pi, steps: 60}\noutput: " + output + "\n");
}

TEST(EffortSensitivity, ACrankSliderWithAForceOfItsRatesMatchesResolvedSweeps) {
  // a drag on the slider's pin reading the rates (der()): L2 and L3 move ẋB, c scales the force
  expect_effort_sensitivities_match_resolved_sweeps(massive_crank_slider_with(
      "    - {name: drag, part: rod, at: [L3, 0], force: [\"-c*der(xB)*abs(der(xB)) - 2*der(xB)\", \"-c*der(yA)\"]}\n",
      "{efforts: all, sensitivities: [L2, L3, c]}"));
}

TEST(EffortSensitivity, ACrankSliderWithALawOfTheSlidersSpeedMatchesResolvedSweeps) {
  // a drag measured against the slider's speed (a table law of der(xB)) whose values read c, and a law of the
  // stroke: L2 and L3 move the arguments, c the table
  expect_effort_sensitivities_match_resolved_sweeps(massive_crank_slider_with(
      "    - name: drag\n"
      "      part: rod\n"
      "      at: [L3, 0]\n"
      "      force:\n"
      "        - {law: {type: table, t: [-1, -0.5, 0, 0.5, 1], values: [6*c, 2*c, 0, -2*c, -6*c]}, of: der(xB)}\n"
      "        - {law: {type: polynomial, coefficients: [1, 0, 3]}, of: xB - L3}\n",
      "{efforts: all, sensitivities: [L2, L3, c]}"));
}

TEST(EffortSensitivity, TheMassiveFourBarsTorqueMatchesResolvedSweeps) {
  // models/dynamics/fourbar_motor_torque.yaml (natural coordinates; centres and inertias read L2, L3, L4)
  const std::string text = test::model_file_text("dynamics/fourbar_motor_torque.yaml", "output:");
  expect_effort_sensitivities_match_resolved_sweeps(text + "output: {efforts: all, sensitivities: [L1, L2, L3]}\n");
}

TEST(EffortSensitivity, ASpatialRssrsTorqueMatchesResolvedSweeps) {
  // models/spatial/rssr.yaml (reference points and Euler parameters, a joint driver) with a massive crank and
  // rocker under gravity along −y: the dimensions a, b and L move the pins, the centres and the inertias
  const std::string text = test::model_file_text("spatial/rssr.yaml", "time:");
  expect_effort_sensitivities_match_resolved_sweeps(
      text +
      "parts:\n"
      "  crank: {mass: 0.8, center_of_mass: [a/2, 0, 0], inertia: [0.001, 0.8*a*a/12, 0.8*a*a/12]}\n"
      "  rocker: {mass: 1.1, center_of_mass: [0, b/2, 0], inertia: [1.1*b*b/12, 0.001, 1.1*b*b/12]}\n"
      "loads: {gravity: [0, -9.81, 0]}\n"
      "time: {start: 0, end: 2*pi, steps: 36}\n"
      "output: {efforts: all, sensitivities: [a, b, L]}\n");
}

TEST(EffortSensitivity, ARssrWithSpringsOnItsJointsAnglesMatchesResolvedSweeps) {
  // torsional spring-dampers on both hinges' angles (parts/force_rate.cpp carries their derivatives exactly): the
  // dimensions move the rocker's angle, kt, th0 and ct the rocker spring's constants
  expect_effort_sensitivities_match_resolved_sweeps(
      test::rssr_with_joint_springs("2", "{efforts: all, sensitivities: [a, b, L, kt, th0, ct]}"));
}

TEST(EffortSensitivity, RotorsAndDryFrictionsOnJointsAnglesMatchResolvedSweeps) {
  // a rotor and a dry friction on the rocker hinge's angle (its θ̈'s rate along p differenced in Q) and on an
  // expression's (exact): J and f reach the torque alone, the dimensions through the motion
  expect_effort_sensitivities_match_resolved_sweeps(test::replace_first(
      test::rssr_with_joint_springs("2", "{efforts: all, sensitivities: [a, b, kt, J, f]}"), "damping: ct}",
      "damping: ct, inertia: J, friction: f}\n    - {angle: \"2*atan2(rocker_e1, rocker_e0)\", inertia: J}"));
}

TEST(EffortSensitivity, PartsAndLoadsOnFramesOfExpressionsMatchResolvedSweeps) {
  // an arm on a frame of expressions (sines and products of the coordinates and t, d and L3 in them) with a mass, a
  // force and a torque, planar; a spatial one on the RSSR whose axis reads b: exact, no Q differenced
  // (tests/test_force_rate.cpp counts it)
  expect_effort_sensitivities_match_resolved_sweeps(
      test::crank_slider_with_expression_frame("{efforts: all, sensitivities: [L2, L3, d]}"));
  expect_effort_sensitivities_match_resolved_sweeps(
      test::rssr_with_expression_frame("[0.3, 0.4*b, 0.866]", "{efforts: all, sensitivities: [a, b]}"));
}

// With the losses that read the multipliers (solve/friction_losses.hpp): the adjoint of their fixed point, their
// data along p and their joints' geometry along the motion. A bearing at every pin of the massive four-bar (μ a
// parameter; the lengths move the pins and the inertias); the hoist's lossy stages (an efficiency, the drum's
// radius); a tilted spatial hinge's journal, collar and bending arm (the speed moves the motion, e the centre).
TEST(EffortSensitivity, BearingsAndGearLossesMatchResolvedSweeps) {
  std::string fourbar = test::model_file_text("dynamics/fourbar_pin_friction.yaml", "output:");
  for (const char* pin : {"O", "A", "B", "C"})
    fourbar = test::replace_first(fourbar, std::string("joint: ") + pin + ", coefficient: 0.15",
                                  std::string("joint: ") + pin + ", coefficient: mu");
  // (not at t = 0 and 1, where pin B's turn is zero and its friction's sign, not differentiable, is rounding's)
  fourbar = test::replace_first(fourbar, "time: {start: 0, end: 1, steps: 72}",
                                "time: {start: 0.01, end: 0.99, "
                                "steps: 49}");
  expect_effort_sensitivities_match_resolved_sweeps(
      test::replace_first(fourbar, "parameters: {", "parameters: {mu: 0.15, ") +
      "output: {efforts: all, sensitivities: [L2, L3, mu]}\n");
  const std::string hoist =
      test::replace_first(test::replace_first(test::model_file_text("dynamics/hoist_gear_losses.yaml", "output:"),
                                              "efficiency: 0.97,", "efficiency: eta1,"),
                          "parameters: {", "parameters: {eta1: 0.97, ") +
      "output: {efforts: all, sensitivities: [eta1, r]}\n";
  expect_effort_sensitivities_match_resolved_sweeps(hoist);
  {  // the API at the sweep's last row, the losses solved there alike
    const Scene s = parse_scene(hoist, "hoist.yaml");
    const EffortSensitivityRows r = effort_rows_sweep(s);
    Workspace at_end(*s.model);
    SweepOptions o = s.sweep;
    o.sensitivities.clear(), o.efforts = OutputEfforts{};
    o.velocities = o.accelerations = true, o.newton.tolerance = 1e-12;
    ASSERT_EQ(run_sweep(
                  *s.model, o, at_end, [](const StepView&) { return true; }, nullptr),
              SolveStatus::kSuccess);
    std::vector<double> d;
    std::string why;
    ASSERT_EQ(
        solve_effort_sensitivities(*s.model, s.sweep.efforts, s.sweep.sensitivities, s.sweep.t_end, at_end, d, &why),
        SolveStatus::kSuccess)
        << why;
    const std::size_t at = static_cast<std::size_t>(s.sweep.efforts.size());
    for (std::size_t j = 0; j < 2; ++j) EXPECT_NEAR(d[j], r.values.back()[at + j], 1e-8 * (1 + std::fabs(d[j]))) << j;
    EXPECT_GT(std::fabs(d[0]), 0.1);  // ∂τ/∂η1 (N m): the first stage's loss felt
  }
  expect_effort_sensitivities_match_resolved_sweeps(
      "phiq: 1\nname: rotor\ndimension: 3\nparameters: {w: 4, e: 0.1, mu: 0.15}\n"
      "coordinates: {x: 0, y: 0, z: 0, e0: 1, e1: 0, e2: 0, e3: 0}\nbodies: {disc: [x, y, z, e0, e1, e2, e3]}\n"
      "constraints:\n  - {name: hinge, type: revolute, between: [{body: ground, axis: [0, 0.3, 1]}, {body: disc, "
      "axis: [0, 0, 1]}]}\n"
      "drivers:\n  - {name: motor, joint: hinge, law: {type: polynomial, coefficients: [0, w, 0.7]}}\n"
      "parts:\n  disc: {mass: 3.0, center_of_mass: [e, 0.05, 0.25], inertia: [0.02, 0.03, 0.04]}\n"
      "loads:\n  gravity: [0, 0, -9.81]\n"
      "  torsional_springs: [{name: bearing, joint: hinge, bearing: {coefficient: mu, radius: 0.02, "
      "thrust_radius: 0.035, moment_arm: 0.04}}]\n"
      "time: {start: 0, end: 1.5, steps: 30}\noutput: {efforts: all, sensitivities: [w, e, mu]}\n");
  // a spatial slide's whole moment over its arm (the centre's offsets and μ)
  expect_effort_sensitivities_match_resolved_sweeps(
      test::spatial_slide_text(0.3, 0.1, "output: {efforts: all, sensitivities: [d, e, mu]}\n"));
}

// An offset crank-slider whose slide's friction reads its reaction (across it, and its tilt over an arm): the line's
// offset e and tilt move the slide's own data (at fixed multipliers a planar slide's load, |λ across| + |λ turn| / a,
// does not move with them: what moves τ is the motion and the load's direction); the crank's length and μ beside.
TEST(EffortSensitivity, ASlidesOffsetAndTiltUnderItsFrictionMatchResolvedSweeps) {
  expect_effort_sensitivities_match_resolved_sweeps(R"yaml(phiq: 1
name: offset_slider
parameters: {L2: 0.1, L3: 0.35, e: 0.03, tilt: 0.2, mu: 0.15}
coordinates: {x2: 0.045, y2: 0.02, psi2: 0.4, x3: 0.25, y3: 0.06, psi3: 0.0, x4: 0.42, y4: 0.11, psi4: 0.2}
bodies: {crank: [x2, y2, psi2], rod: [x3, y3, psi3], slider: [x4, y4, psi4]}
constraints:
  - {name: O, type: revolute, between: [{body: ground, at: [0, 0]}, {body: crank, at: [-L2/2, 0]}]}
  - {name: A, type: revolute, between: [{body: crank, at: [L2/2, 0]}, {body: rod, at: [-L3/2, 0]}]}
  - {name: B, type: revolute, between: [{body: rod, at: [L3/2, 0]}, {body: slider, at: [0, 0]}]}
  - {name: slide, type: prismatic, between: [{body: ground, at: [0, e]}, {body: slider}],
     axis: ["cos(tilt)", "sin(tilt)"], angle: tilt}
drivers:
  - {name: motor, coordinate: psi2, law: {type: linear, initial: 0.4, rate: 2}}
parts:
  crank: {mass: 0.5, center_of_mass: [0, 0], inertia: 0.0005}
  rod: {mass: 0.8, center_of_mass: [0, 0], inertia: 0.008}
  slider: {mass: 1.2, center_of_mass: [0.02, 0.01], inertia: 0.002}
loads:
  gravity: [0, -9.81]
  forces: [{name: gas, part: slider, force: ["-40*cos(tilt)", "-40*sin(tilt)"]}]
  torsional_springs: [{name: guide, angle: "x4*cos(tilt) + y4*sin(tilt)",
                       bearing: {joint: slide, coefficient: mu, moment_arm: 0.05}}]
time: {start: 0, end: 1, steps: 20}
output: {efforts: all, sensitivities: [e, tilt, L2, mu]}
)yaml");
}

// Parameters of a loss's own constraint: a spatial hinge's axes, ground's (tilt) and the disc's (ta), the side its
// reaction is written on, whose axis splits the journal's load into radial, axial and bending parts (the hinge's
// sides moved along their data's rates: without them ∂τ/∂ta is off by 7%), and a gear's pitch radius, its mesh's
// ratio (the hoist's first stage, raising and lowering: without it, off by 3% of its largest).
TEST(EffortSensitivity, ParametersOfALossesOwnJointOrRatioMatchResolvedSweeps) {
  expect_effort_sensitivities_match_resolved_sweeps(
      "phiq: 1\nname: rotor\ndimension: 3\nparameters: {tilt: 0.3, ta: 0.2}\n"
      "coordinates: {x: 0, y: 0, z: 0, e0: 1, e1: 0, e2: 0, e3: 0}\nbodies: {disc: [x, y, z, e0, e1, e2, e3]}\n"
      "constraints:\n  - {name: hinge, type: revolute, between: [{body: disc, at: [0.01, 0, 0.02], axis: [0, ta, 1]}, "
      "{body: ground, axis: [0, tilt, 1]}]}\n"
      "drivers:\n  - {name: motor, joint: hinge, law: {type: polynomial, coefficients: [0, 4, 0.7]}}\n"
      "parts:\n  disc: {mass: 3.0, center_of_mass: [0.1, 0.05, 0.25], inertia: [0.02, 0.03, 0.04]}\n"
      "loads:\n  gravity: [0, 0, -9.81]\n"
      "  torsional_springs: [{name: bearing, joint: hinge, bearing: {coefficient: 0.15, radius: 0.02, "
      "thrust_radius: 0.035, moment_arm: 0.04}}]\n"
      "time: {start: 0, end: 1.5, steps: 30}\noutput: {efforts: all, sensitivities: [tilt, ta]}\n");
  std::string hoist = test::model_file_text("dynamics/hoist_gear_losses.yaml", "output:");
  hoist = test::replace_first(hoist, "teeth: [12, 36]", "radii: [r1, 0.09]");
  hoist = test::replace_first(hoist, "parameters: {", "parameters: {r1: 0.03, ");
  expect_effort_sensitivities_match_resolved_sweeps(hoist + "output: {efforts: all, sensitivities: [r1]}\n");
}

TEST(EffortSensitivity, TheFourFormulationsOfTheFourBarGiveOneSensitivity) {
  // relative angles (the parts' frames read L2, L3 in their expressions), natural, reference-point (the pins'
  // local points read them) and mixed coordinates: ∂τ/∂L of one physical torque, alike at every row
  const char* forms[] = {"relative", "natural", "reference_point", "mixed"};
  std::vector<EffortSensitivityRows> rows;
  for (const char* form : forms) {
    const std::string text = test::model_file_text(std::string("seed/fourbar_") + form + ".yaml", "time:");
    const Scene s = parse_scene(text + "parts:\n" + test::fourbar_parts(form) +
                                    "loads: {gravity: [0, -9.81]}\n"
                                    "time: {start: 0, end: 2*pi, steps: 60}\n"
                                    "output: {efforts: all, sensitivities: [L2, L3, L4]}\n",
                                form);
    rows.push_back(effort_rows_sweep(s));
    ASSERT_EQ(rows.back().values.size(), 61u) << form;
  }
  double worst = 0.0, scale = 0.0;
  for (std::size_t f = 1; f < 4; ++f)
    for (std::size_t k = 0; k < 61; ++k)
      for (std::size_t j = 2; j < 5; ++j) {  // after the effort and its power
        scale = std::max(scale, std::fabs(rows[0].values[k][j]));
        worst = std::max(worst, std::fabs(rows[f].values[k][j] - rows[0].values[k][j]));
      }
  ::testing::Test::RecordProperty("worst_relative", scientific(worst / scale, 2));
  EXPECT_GT(scale, 1.0);
  EXPECT_LT(worst, 1e-7 * scale);
}

TEST(EffortSensitivity, ARedundantParallelogramHasItsFourBarsSensitivity) {
  // models/redundant/parallelogram_fifth_bar.yaml, swept on its independent rows (a row dropped: w and λ over the
  // kept ones), against the four-bar without its fifth bar: ∂τ/∂r and ∂τ/∂d alike, row by row
  const std::string five = test::model_file_text("redundant/parallelogram_fifth_bar.yaml", "output:");
  std::string four;
  std::istringstream lines(five);
  for (std::string line; std::getline(lines, line);)
    if (line.find("crank3") == std::string::npos && line.find("x3:") == std::string::npos &&
        line.find("y3:") == std::string::npos && line.find("psi3:") == std::string::npos)
      four += line + "\n";
  const std::string massive =
      "parts:\n  crank1: {mass: 1.0, inertia: 0.1, center_of_mass: [r/2, 0]}\n"
      "  crank2: {mass: 1.0, inertia: 0.1, center_of_mass: [r/2, 0]}\n"
      "  coupler: {mass: 2.0, inertia: 0.2, center_of_mass: [d/2, 0]}\n"
      "loads: {gravity: [0, -9.81]}\noutput: {efforts: all, sensitivities: [r, d]}\n";
  std::vector<std::vector<std::vector<double>>> values;
  for (const std::string& text : {five, four}) {
    const Scene s = parse_scene(text + massive, "parallelogram.yaml");
    SquareScene square;
    ASSERT_EQ(prepare_scene(*s.model, s.sweep.t_begin, s.sweep.assembly, &square), SolveStatus::kSuccess)
        << square.assembly.message;
    const Model& m = square.model(*s.model);
    Workspace ws(m);
    ws.q = square.start;
    std::vector<std::vector<double>> rows;
    const std::size_t size = static_cast<std::size_t>(effort_values(s.sweep.efforts, 2));
    SweepSummary sum;
    ASSERT_EQ(run_sweep(
                  m, s.sweep, ws,
                  [&](const StepView& v) {
                    rows.emplace_back(v.efforts, v.efforts + size);
                    return true;
                  },
                  &sum),
              SolveStatus::kSuccess)
        << sum.message;
    values.push_back(rows);
  }
  ASSERT_EQ(values[0].size(), values[1].size());
  double worst = 0.0, scale = 0.0;
  for (std::size_t k = 0; k < values[0].size(); ++k)
    for (std::size_t j = 2; j < 4; ++j) {
      ASSERT_TRUE(std::isfinite(values[0][k][j])) << k;
      worst = std::max(worst, std::fabs(values[0][k][j] - values[1][k][j]));
      scale = std::max(scale, std::fabs(values[1][k][j]));
    }
  ::testing::Test::RecordProperty("worst_relative", scientific(worst / scale, 2));
  EXPECT_GT(scale, 1.0);
  EXPECT_LT(worst, 1e-7 * scale);
}

// A massive crank-slider whose parameters reach different things: the lengths L2, L3 the constraints only; mr a
// mass; xo the pivot, a part's frame and the constraints; g, F, k, kt the gravity, a force, a spring and a torsional
// spring.
const char* const kEffortReachCrankSlider = R"(phiq: 1
name: crank_slider_loads
parameters: {L2: 0.3, L3: 1.0, mr: 1.2, xo: 0.1, g: 9.81, F: 5, k: 40, kt: 2}
coordinates: {theta2: 0.0, xA: 0.38, yA: 0.03, xB: 1.35}
points: {O: [xo, 0], A: [xA, yA], B: [xB, 0]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}
  - {name: rod, type: distance, points: [A, B], length: L3}
drivers:
  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 2}}
parts:
  crank: {frame: {origin: O, x: A}, center_of_mass: [0.15, 0], mass: 0.5, inertia: 0.004}
  rod: {frame: {origin: A, x: B}, center_of_mass: [0.5, 0], mass: mr, inertia: 0.1}
loads:
  gravity: [0, -g]
  forces: [{name: push, part: rod, at: [1.0, 0], force: [-F, 0]}]
  springs: [{name: pull, between: [{part: rod, at: [1.0, 0]}, {point: [2, 0]}], stiffness: k, free_length: 0.5}]
  torsional_springs: [{name: twist, coordinate: theta2, stiffness: kt}]
time: {start: 0, end: pi, steps: 30}
output: {efforts: all, sensitivities: [L2, L3, mr, xo, g, F, k, kt]}
)";

TEST(EffortSensitivity, OnlyTheParametersThatMoveAPartOrALoadCarryThemAlong) {
  // A parameter that reaches the constraints only leaves parts_along and loads_along null (Q is then not
  // differenced along it: 4 evaluations of Q per row, not 8); one that moves a mass, a frame or a load sets them
  // at all four points of the difference.
  const Scene s = parse_scene(kEffortReachCrankSlider, "crank_slider_loads.yaml");
  ASSERT_EQ(s.sweep.sensitivities.size(), 8u);
  for (const OutputSensitivity& p : s.sweep.sensitivities) {
    const bool parts = p.name == "mr" || p.name == "xo";
    const bool loads = p.name == "g" || p.name == "F" || p.name == "k" || p.name == "kt";
    for (std::size_t k = 0; k < 4; ++k) {
      EXPECT_EQ(p.parts_along[k] != nullptr, parts) << p.name << " at " << k;
      EXPECT_EQ(p.loads_along[k] != nullptr, loads) << p.name << " at " << k;
    }
  }
}

TEST(EffortSensitivity, ParametersThatReachNoForceGiveTheSameColumnsBitForBitAsWithTheirOwnForcesAlong) {
  // The along-p difference of Q skipped where nothing moves is exactly the zero it replaces: the sweep with the
  // scene's own parts and loads standing at every point along each parameter writes the same bits.
  const Scene s = parse_scene(kEffortReachCrankSlider, "crank_slider_loads.yaml");
  Scene along = parse_scene(kEffortReachCrankSlider, "crank_slider_loads.yaml");
  for (OutputSensitivity& p : along.sweep.sensitivities)
    for (std::size_t k = 0; k < 4; ++k) {
      if (!p.parts_along[k]) p.parts_along[k] = along.sweep.efforts.parts;
      if (!p.loads_along[k]) p.loads_along[k] = along.sweep.efforts.loads;
    }
  const EffortSensitivityRows a = effort_rows_sweep(s), b = effort_rows_sweep(along);
  ASSERT_EQ(a.values.size(), 31u);
  ASSERT_EQ(b.values.size(), a.values.size());
  for (std::size_t k = 0; k < a.values.size(); ++k)
    for (std::size_t j = 0; j < a.values[k].size(); ++j)
      EXPECT_EQ(std::bit_cast<std::uint64_t>(a.values[k][j]), std::bit_cast<std::uint64_t>(b.values[k][j]))
          << "row " << k << " value " << j;
}

TEST(EffortSensitivity, ACrankSliderWithLoadsOfEveryKindMatchesResolvedSweeps) {
  // every parameter of the scene above, whatever it reaches, against re-solved sweeps
  expect_effort_sensitivities_match_resolved_sweeps(kEffortReachCrankSlider);
}

TEST(EffortSensitivity, TheCsvColumnsAreNamedAfterTheEffortAndTheParameterAndHoldTheRowsValues) {
  const Scene s = parse_scene(kEffortPendulum, "pendulum.yaml");
  const CsvFormat f(*s.model, s.sweep);
  const std::vector<std::string> names = f.column_names();
  ASSERT_GE(names.size(), 3u);
  EXPECT_EQ(names[names.size() - 3], "motor.effort");
  EXPECT_EQ(names[names.size() - 2], "motor.effort.d_L");
  EXPECT_EQ(names[names.size() - 1], "motor.effort.d_mb");
  Workspace ws(*s.model);
  int rows = 0;
  ASSERT_EQ(run_sweep(
                *s.model, s.sweep, ws,
                [&](const StepView& v) {
                  std::vector<double> row(f.num_values());
                  f.append_values(v, row.data());
                  EXPECT_EQ(row[row.size() - 2], v.efforts[2]);
                  EXPECT_EQ(row[row.size() - 1], v.efforts[3]);
                  ++rows;
                  return true;
                },
                nullptr),
            SolveStatus::kSuccess);
  EXPECT_EQ(rows, 41);
}

}  // namespace
}  // namespace phiq
