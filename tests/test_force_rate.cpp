// The exact rate of the generalized forces along a parameter (parts/force_rate.hpp) against the fourth-order
// difference of Q itself along (q + ε s, q̇ + ε ṡ, q̈ + ε s̈) with the scene's parts and loads read at p + ε, on a
// crank-slider whose parameters reach a length, a mass, a ground pivot in a part's frame, gravity, a force, a
// torque in the part's axes, a damped spring and a damped torsional spring, on an RSSR with damped torsional
// springs on its spatial hinges' angles, and on parts and loads on frames of expressions (planar, spatial, the
// relative four-bar), and on forces of the rates (der()) and laws of them; the efforts' sensitivities through it
// against those through the difference of Q (effort_sensitivity.cpp keeps both), and a spring pendulum's against their
// closed form.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>

#include "parts/force_rate.hpp"
#include "phiq/effort_sensitivity.hpp"
#include "phiq/inverse_dynamics.hpp"
#include "phiq/phiq.hpp"
#include "solve/sensitivity_internal.hpp"
#include "fourbar_parts.hpp"
#include "sensitivity_support.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

const char* const kForceRateCrankSlider = R"(phiq: 1
name: crank_slider_rates
parameters: {L2: 0.3, L3: 1.0, mr: 1.2, xo: 0.1, g: 9.81, F: 5, k: 40, c: 3, kt: 2, ct: 0.4, T: 0.7}
coordinates: {theta2: 0.0, xA: 0.38, yA: 0.03, xB: 1.35}
points: {O: [xo, 0], A: [xA, yA], B: [xB, 0]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}
  - {name: rod, type: distance, points: [A, B], length: L3}
drivers:
  - {name: motor, coordinate: theta2, law: {type: polynomial, coefficients: [0.2, 2, 0.8]}}
parts:
  crank: {frame: {origin: O, x: A}, center_of_mass: [L2/2, 0.01], mass: 0.5, inertia: 0.004}
  rod: {frame: {origin: A, x: B}, center_of_mass: [L3/2, 0], mass: mr, inertia: mr*L3*L3/12}
loads:
  gravity: [0, -g]
  forces: [{name: push, part: rod, at: [L3, 0], force: [-F*cos(theta2), F*xB]}]
  torques: [{name: turn, part: rod, torque: T*xA, axes: part}]
  springs: [{name: pull, between: [{part: rod, at: [L3, 0]}, {point: [2, xo]}], stiffness: k, free_length: 0.5,
             damping: c}]
  torsional_springs: [{name: twist, coordinate: theta2, stiffness: kt, damping: ct}]
time: {start: 0, end: 0.9, steps: 9}
output: {efforts: all, sensitivities: [L2, L3, mr, xo, g, F, k, c, kt, ct, T]}
)";

// The scene swept to its last row with velocities and accelerations: the motion stays in `ws`.
void force_rate_swept(const Scene& s, Workspace& ws) {
  SweepOptions o = s.sweep;
  o.sensitivities.clear(), o.efforts = OutputEfforts{};
  o.velocities = o.accelerations = true;
  o.newton.tolerance = 1e-12;
  ASSERT_EQ(run_sweep(
                *s.model, o, ws, [](const StepView&) { return true; }, nullptr),
            SolveStatus::kSuccess);
}

// Q at (q + e v, q̇ + e v̇, q̈ + e v̈) with the parts and loads of copy k along p (k < 0: the scene's own).
Eigen::VectorXd force_rate_q_at(const Scene& s, const OutputSensitivity& p, int k, double e, const Workspace& ws,
                                const Eigen::VectorXd& v, const Eigen::VectorXd& vd, const Eigen::VectorXd& vdd) {
  const Eigen::VectorXd q = ws.q + e * v, qd = ws.qd + e * vd, qdd = ws.qdd + e * vdd;
  Eigen::VectorXd Q = Eigen::VectorXd::Zero(s.model->num_coordinates());
  const auto at = static_cast<std::size_t>(std::max(k, 0));
  add_generalized_forces(k >= 0 && p.parts_along[at] ? *p.parts_along[at] : *s.sweep.efforts.parts,
                         k >= 0 && p.loads_along[at] ? *p.loads_along[at] : *s.sweep.efforts.loads, q.data(), qd.data(),
                         qdd.data(), s.sweep.t_end, Q);
  return Q;
}

// The exact dQ/dp of each of the scene's parameters at its last row, along directions that move every coordinate,
// its rate and its acceleration (not a motion's: the rate is linear), against the difference of Q: along the motion
// with the scene's own parts and loads (a step of 10⁻³: fourth order, error ~10⁻¹²), and along p at the motion's
// point with the copies at p ± h, p ± 2h.
void expect_force_rate_equals_difference_of_q(const Scene& s) {
  Workspace ws(*s.model);
  force_rate_swept(s, ws);
  const Index n = s.model->num_coordinates();
  Eigen::VectorXd v(n), vd(n), vdd(n);
  for (Index i = 0; i < n; ++i) v[i] = 0.3 + 0.1 * i, vd[i] = -0.7 + 0.4 * i, vdd[i] = 1.1 - 0.5 * i;
  for (const OutputSensitivity& p : s.sweep.sensitivities) {
    detail::ForcesAlong along{{}, {}, p.step};
    for (std::size_t k = 0; k < 4; ++k)
      along.parts[k] = p.parts_along[k].get(), along.loads[k] = p.loads_along[k].get();
    Eigen::VectorXd exact(n);
    ASSERT_TRUE(detail::generalized_force_rate(*s.sweep.efforts.parts, *s.sweep.efforts.loads, along, ws.q.data(),
                                               ws.qd.data(), ws.qdd.data(), v.data(), vd.data(), vdd.data(),
                                               s.sweep.t_end, exact))
        << p.name;
    Eigen::VectorXd f[4], g[4];
    const double shift[4] = {-2, -1, 1, 2}, e = 1e-3;
    for (int k = 0; k < 4; ++k) {
      f[k] = force_rate_q_at(s, p, -1, shift[k] * e, ws, v, vd, vdd);
      g[k] = force_rate_q_at(s, p, k, 0.0, ws, v, vd, vdd);
    }
    const Eigen::VectorXd fd =
        ((f[0] - f[3]) + 8.0 * (f[2] - f[1])) / (12.0 * e) + ((g[0] - g[3]) + 8.0 * (g[2] - g[1])) / (12.0 * p.step);
    ::testing::Test::RecordProperty(s.name + "_relative_" + p.name, scientific((exact - fd).norm() / fd.norm(), 2));
    EXPECT_GT(fd.norm(), 1e-2) << p.name;
    EXPECT_LT((exact - fd).norm(), 1e-8 * fd.norm())
        << s.name << " " << p.name << "\nexact " << exact.transpose() << "\nfd    " << fd.transpose();
  }
}

TEST(ForceRate, EqualsTheDifferenceOfQAlongTheMotionAndEachParameter) {
  // Q is a polynomial of degree ≤ 3 in what g, F, k, c, kt, ct, T and mr move, and those linear in p; L2, L3 and
  // xo move the parts by steps of ~10⁻⁴
  const Scene s = parse_scene(kForceRateCrankSlider, "crank_slider_rates.yaml");
  ASSERT_EQ(s.sweep.sensitivities.size(), 11u);
  expect_force_rate_equals_difference_of_q(s);
}

// The scene's efforts' (and powers') sensitivities at its last row through the exact dQ/dp and through Q
// differenced (EffortSensitivityScratch::difference_forces), with how many parameters each differenced.
struct ForceRatePaths {
  std::vector<double> exact, differenced;
  std::size_t exact_differenced = 0, differenced_differenced = 0;
};

void force_rate_paths(const Scene& s, ForceRatePaths& out) {
  Workspace ws(*s.model);
  force_rate_swept(s, ws);
  std::vector<OutputSensitivity> ps = s.sweep.sensitivities;
  for (OutputSensitivity& p : ps)
    if (!p.reach) p.reach = std::make_shared<const ParameterReach>(parameter_reach(*s.model, p));
  const Index n = s.model->num_coordinates();
  std::vector<double> sens(static_cast<std::size_t>(SensitivityLayout{n}.size(ps.size())));
  ASSERT_EQ(solve_sensitivities(*s.model, ps, s.sweep.t_end, 2, ws, sens.data()), SolveStatus::kSuccess);
  Eigen::VectorXd Q = Eigen::VectorXd::Zero(n), kept, lambda;
  add_generalized_forces(*s.sweep.efforts.parts, *s.sweep.efforts.loads, ws.q.data(), ws.qd.data(), ws.qdd.data(),
                         s.sweep.t_end, Q);
  ASSERT_TRUE(multipliers_with_factors(*s.model, *ws.lu, Q, kept, lambda));
  const std::size_t size = EffortSensitivityLayout{s.sweep.efforts.constraints.size()}.size(ps.size());
  out.exact.assign(size, 0.0), out.differenced.assign(size, 0.0);
  detail::EffortSensitivityScratch a, b;
  b.difference_forces = true;
  ASSERT_TRUE(detail::effort_sensitivities_with_factors(*s.model, s.sweep.efforts, ps, s.sweep.t_end, ws.q.data(),
                                                        ws.qd.data(), ws.qdd.data(), lambda, sens.data(), *ws.lu, a,
                                                        out.exact.data()));
  ASSERT_TRUE(detail::effort_sensitivities_with_factors(*s.model, s.sweep.efforts, ps, s.sweep.t_end, ws.q.data(),
                                                        ws.qd.data(), ws.qdd.data(), lambda, sens.data(), *ws.lu, b,
                                                        out.differenced.data()));
  out.exact_differenced = a.differenced, out.differenced_differenced = b.differenced;
}

// Both paths equal to 1e-8, the exact form taken for every parameter.
void expect_force_rate_paths_agree(const Scene& s) {
  ForceRatePaths r;
  force_rate_paths(s, r);
  EXPECT_EQ(r.exact_differenced, 0u) << s.path;  // no parameter fell back to the difference
  EXPECT_EQ(r.differenced_differenced, s.sweep.sensitivities.size());
  ASSERT_EQ(r.exact.size(), r.differenced.size());
  for (std::size_t j = 0; j < r.exact.size(); ++j) {
    ASSERT_TRUE(std::isfinite(r.exact[j])) << j;
    EXPECT_NEAR(r.exact[j], r.differenced[j], 1e-8 * std::max(1.0, std::fabs(r.differenced[j]))) << "value " << j;
  }
}

TEST(ForceRate, TheEffortsSensitivitiesThroughItEqualThoseThroughTheDifferenceOfQ) {
  expect_force_rate_paths_agree(parse_scene(kForceRateCrankSlider, "crank_slider_rates.yaml"));
}

TEST(ForceRate, CarriesForcesOfTheRatesAndLawsOfThemAndOfSpringsDeflectionsExactly) {
  // der() in a force and a torque (∂Q/∂q̇ · ṡ), a table law of the slider's speed whose values read c, a polynomial
  // law of the stroke whose argument reads L3, a harmonic law of t whose amplitude is F, and springs whose elastic
  // force is a law of their deflection (c in a table's values, F in a polynomial's coefficients) with actuators
  // (an expression of t and a rate, a law of the stroke)
  const Scene s = parse_scene(
      test::crank_slider_scene(
          ", c: 4, F: 2",
          "parts:\n  rod: {frame: {origin: A, x: B}, center_of_mass: [L3/2, 0], mass: 1.2, inertia: 1.2*L3*L3/12}\n"
          "loads:\n"
          "  forces:\n"
          "    - {name: drag, part: rod, at: [L3, 0], force: [\"-c*der(xB)*abs(der(xB))\", \"-c*L2*der(yA)\"]}\n"
          "    - name: measured\n"
          "      part: rod\n"
          "      at: [L3/2, 0]\n"
          "      force:\n"
          "        - {law: {type: table, t: [-2, -1, 0, 1, 2], values: [20*c, 6*c, 0, -6*c, -20*c]}, of: der(xB)}\n"
          "        - {law: {type: polynomial, coefficients: [1, 0, 3]}, of: xB - L3}\n"
          "  torques: [{name: shake, part: rod, torque: {law: {type: harmonic, amplitude: F, frequency: 3}}}]\n"
          "  springs: [{name: strut, between: [{part: rod, at: [L3/2, 0]}, {point: [0.5, 0.8]}], free_length: 0.2,\n"
          "             law: {type: table, t: [-1, 0, 1, 2], values: [-c, 0, 3*c, 9*c]}, damping: 2,\n"
          "             tension: \"F*sin(t) + c*der(xB)\"}]\n"
          "  torsional_springs: [{name: coil, angle: \"theta2 - atan2(yA, xA - xB)\", "
          "law: {type: polynomial, coefficients: [0, F, 0, 0.5]}, moment: {law: {type: harmonic, amplitude: c, "
          "frequency: 2}, of: xB}}]\n"
          "time: {start: 0, end: 0.9, steps: 9}\n"
          "output: {efforts: all, power: true, sensitivities: [L2, L3, c, F]}\n"),
      "crank_slider_rate_loads.yaml");
  expect_force_rate_equals_difference_of_q(s);
  expect_force_rate_paths_agree(s);
}

TEST(ForceRate, CarriesARotorsInertiaAndDryFrictionsExactly) {
  // a rotor J θ̈ on the rod's angle to the crank (θ̈ from the expression's jet, its third derivatives included) with a
  // dry friction, and a seal's friction on a line: J, fr and fs reach Q alone, L2 and L3 through the motion
  const Scene s = parse_scene(
      test::crank_slider_scene(
          ", J: 0.3, fr: 1.5, fs: 2",
          "parts:\n  rod: {frame: {origin: A, x: B}, center_of_mass: [L3/2, 0], mass: 1.2, inertia: 1.2*L3*L3/12}\n"
          "loads:\n"
          "  springs: [{name: seal, between: [{part: rod, at: [L3/2, 0]}, {point: [0.5, 0.8]}], friction: fs}]\n"
          "  torsional_springs: [{name: rotor, angle: \"theta2 - atan2(yA, xA - xB)\", inertia: J, friction: fr,\n"
          "                       damping: 0.2}]\n"
          "time: {start: 0, end: 0.9, steps: 9}\n"
          "output: {efforts: all, power: true, sensitivities: [L2, L3, J, fr, fs]}\n"),
      "crank_slider_rotor.yaml");
  expect_force_rate_equals_difference_of_q(s);
  expect_force_rate_paths_agree(s);
  // on a spatial joint's angle the rotor's θ̈ has no exact rate along p here: Q is differenced, said so by false
  const Scene joint =
      parse_scene(test::replace_first(test::rssr_with_joint_springs("1.3", "{efforts: all, sensitivities: [a, kt]}"),
                                      "damping: ct}", "damping: ct, inertia: 0.2}"),
                  "rssr_rotor.yaml");
  ForceRatePaths r;
  force_rate_paths(joint, r);
  EXPECT_EQ(r.exact_differenced, 2u);
}

TEST(ForceRate, ReachesTheNaturalFourBarAndTheSpatialRssrExactly) {
  // models/dynamics/fourbar_motor_torque.yaml (natural coordinates: L1 moves the ground pivot of the rocker's
  // frame) and models/spatial/rssr.yaml with massive bodies (reference points and Euler parameters)
  expect_force_rate_paths_agree(
      parse_scene(test::model_file_text("dynamics/fourbar_motor_torque.yaml", "output:") +
                      "output: {efforts: all, power: true, sensitivities: [L1, L2, L3, L4]}\n",
                  "fourbar.yaml"));
  expect_force_rate_paths_agree(
      parse_scene(test::model_file_text("spatial/rssr.yaml", "time:") +
                      "parts:\n"
                      "  crank: {mass: 0.8, center_of_mass: [a/2, 0, 0], inertia: [0.001, 0.8*a*a/12, 0.8*a*a/12]}\n"
                      "  rocker: {mass: 1.1, center_of_mass: [0, b/2, 0], inertia: [1.1*b*b/12, 0.001, 1.1*b*b/12]}\n"
                      "loads: {gravity: [0, -9.81, 0]}\ntime: {start: 0, end: 1.3, steps: 13}\n"
                      "output: {efforts: all, sensitivities: [a, b, L]}\n",
                  "rssr.yaml"));
}

TEST(ForceRate, CarriesFramesOfExpressionsExactlyInThePlaneAndInSpace) {
  // parts and loads on frames of expressions: their jets by the tape's Taylor pass in dual numbers along the motion
  // (third derivatives of sines and products of several coordinates and t), along p through their copies (d, L3 in
  // the planar arm's expressions; a, b in the spatial one's, b in its axis too)
  const Scene planar = parse_scene(
      test::crank_slider_with_expression_frame("{efforts: all, power: true, sensitivities: [L2, L3, d, m2, F]}"),
      "crank_slider_expression_frame.yaml");
  expect_force_rate_equals_difference_of_q(planar);
  expect_force_rate_paths_agree(planar);
  const Scene spatial = parse_scene(
      test::rssr_with_expression_frame("[0.3, 0.4*b, 0.866]", "{efforts: all, power: true, sensitivities: [a, b, L]}"),
      "rssr_expression_frame.yaml");
  expect_force_rate_equals_difference_of_q(spatial);
  expect_force_rate_paths_agree(spatial);
  // the four-bar in relative angles: every part's frame is one of expressions, L2 and L3 in them
  const std::string text = test::model_file_text("seed/fourbar_relative.yaml", "time:");
  const Scene relative = parse_scene(text + "parts:\n" + test::fourbar_parts("relative") +
                                         "loads: {gravity: [0, -9.81]}\ntime: {start: 0, end: 1, steps: 4}\n"
                                         "output: {efforts: all, sensitivities: [L2, L3, L4]}\n",
                                     "relative.yaml");
  expect_force_rate_equals_difference_of_q(relative);
  expect_force_rate_paths_agree(relative);
}

TEST(ForceRate, RefusesCopiesAlongPWithAnotherFrameOfExpressions) {
  // the copies of the scene read along p with the arm's angle dropped from one of them, or its first component
  // reading another coordinate: not the same frame but for its data
  const Scene s = parse_scene(test::crank_slider_with_expression_frame("{efforts: all, sensitivities: [d]}"),
                              "crank_slider_expression_frame.yaml");
  Workspace ws(*s.model);
  force_rate_swept(s, ws);
  const std::vector<Part>& own = *s.sweep.efforts.parts;
  const auto arm = static_cast<std::size_t>(
      std::find_if(own.begin(), own.end(), [](const Part& p) { return p.name == "arm"; }) - own.begin());
  ASSERT_LT(arm, own.size());
  const Eigen::VectorXd v = Eigen::VectorXd::Ones(s.model->num_coordinates());
  Eigen::VectorXd dq(v.size());
  auto rate_with = [&](const std::vector<Part>& changed) {
    detail::ForcesAlong along{{}, {}, 1e-3};
    along.parts = {&own, &own, &changed, &own};
    return detail::generalized_force_rate(own, *s.sweep.efforts.loads, along, ws.q.data(), ws.qd.data(), ws.qdd.data(),
                                          v.data(), v.data(), v.data(), s.sweep.t_end, dq);
  };
  // copies that are the own parts: the rate along the motion alone, bit for bit
  Eigen::VectorXd alone(v.size());
  ASSERT_TRUE(detail::generalized_force_rate(own, *s.sweep.efforts.loads, {}, ws.q.data(), ws.qd.data(), ws.qdd.data(),
                                             v.data(), v.data(), v.data(), s.sweep.t_end, alone));
  EXPECT_GT(alone.norm(), 1e-2);
  EXPECT_TRUE(rate_with(own));
  EXPECT_EQ(dq, alone);
  std::vector<Part> no_angle = own, other = own;
  no_angle[arm].frame.angle = nullptr;
  EXPECT_FALSE(rate_with(no_angle));
  other[arm].frame.at[0] = own[arm].frame.at[1];
  EXPECT_FALSE(rate_with(other));
}

TEST(ForceRate, CarriesATorsionalSpringOnASpatialJointsAngleExactly) {
  // the joint's angle reads both bodies' Euler parameters: ∂θ/∂q's rate H s and θ̇'s sᵀ H q̇ from the joint's
  // acceleration polarised in q̇ (no step); a, b, L move the rocker's motion, kt, th0, ct the spring's constants
  const Scene s = parse_scene(
      test::rssr_with_joint_springs("1.3", "{efforts: all, power: true, sensitivities: [a, b, L, kt, th0, ct]}"),
      "rssr_springs.yaml");
  expect_force_rate_equals_difference_of_q(s);
  expect_force_rate_paths_agree(s);
}

const char* const kForceRateSpringPendulum = R"(phiq: 1
name: joint_spring_pendulum
dimension: 3
parameters: {k: 3, th0: 0.4, w: 0.8, l: 0.6, m: 1.3, c: 0.25}
coordinates: {x: 0.53, y: -0.29, z: 0, e0: 0.97, e1: 0, e2: 0, e3: -0.25}
bodies:
  bob: [x, y, z, e0, e1, e2, e3]
constraints:
  - {name: hinge, type: revolute,
     between: [{body: ground, axis: [0, 0, 1]}, {body: bob, at: [-l, 0, 0], axis: [0, 0, 1]}]}
drivers:
  - {name: motor, joint: hinge, law: {type: linear, initial: -0.5, rate: w}}
parts:
  bob: {mass: m, center_of_mass: [0, 0, 0], inertia: [0.01, 0.02, 0.03]}
loads:
  gravity: [0, -9.81, 0]
  torsional_springs: [{name: twist, joint: hinge, stiffness: k, free_angle: th0, damping: c}]
time: {start: 0, end: 2, steps: 20}
output: {efforts: all, sensitivities: [k, th0, w, l, m, c]}
)";

// ∂τ/∂(k, θ0, ω, l, m, c) of the pendulum at time t: θ = −0.5 + ω t, τ = k (θ − θ0) + c ω + m g l cos θ.
std::array<double, 6> force_rate_pendulum_closed_form(double t) {
  const double k = 3, th0 = 0.4, w = 0.8, l = 0.6, m = 1.3, c = 0.25, g = 9.81, th = -0.5 + w * t;
  return {th - th0, -k, t * (k - m * g * l * std::sin(th)) + c, m * g * std::cos(th), g * l * std::cos(th), w};
}

TEST(ForceRate, ASpringPendulumsTorqueFollowsItsClosedFormInEveryParameter) {
  // a bob on a hinge turned at the constant rate ω by a joint driver against a damped torsional spring on the
  // hinge's angle and gravity: ω turns the Euler parameters along p, so θ's second derivatives enter through s
  const Scene s = parse_scene(kForceRateSpringPendulum, "joint_spring_pendulum.yaml");
  const test::EffortRows r = test::effort_rows_sweep(s);
  ASSERT_EQ(r.t.size(), 21u);
  const std::size_t at = static_cast<std::size_t>(s.sweep.efforts.size());
  // from row 1 on: row 0 is assembled from the scene's rough guess, to Newton's tolerance (τ itself ~10⁻¹¹ off)
  double worst = 0.0, worst_spring = 0.0;
  for (std::size_t row = 1; row < r.t.size(); ++row) {
    const std::array<double, 6> d = force_rate_pendulum_closed_form(r.t[row]);
    for (std::size_t j = 0; j < 6; ++j) {
      const double error = std::fabs(r.values[row][at + j] - d[j]);
      worst = std::max(worst, error);
      if (j == 0 || j == 1 || j == 5) worst_spring = std::max(worst_spring, error);  // k, θ0, c
    }
  }
  // and at the last row through Q differenced, as this spring was before its angle's derivatives were carried
  ForceRatePaths paths;
  force_rate_paths(s, paths);
  EXPECT_EQ(paths.exact_differenced, 0u);
  const std::array<double, 6> d = force_rate_pendulum_closed_form(2.0);
  double exact = 0.0, differenced = 0.0;
  for (std::size_t j = 0; j < 6; ++j) {
    exact = std::max(exact, std::fabs(paths.exact[j] - d[j]));
    differenced = std::max(differenced, std::fabs(paths.differenced[j] - d[j]));
  }
  ::testing::Test::RecordProperty("worst_rows_spring_last_exact_differenced",
                                  scientific(worst, 2) + " " + scientific(worst_spring, 2) + " " +
                                      scientific(exact, 2) + " " + scientific(differenced, 2));
  // scales: |∂τ/∂ω| up to 2.2, |∂τ/∂l| up to 13; the spring's constants' rates are O(1)
  EXPECT_LT(worst_spring, 1e-12);
  EXPECT_LT(worst, 1e-11);
  EXPECT_LT(exact, 1e-11);
  EXPECT_LT(exact, differenced);  // 6.1e-13 against 3.7e-12 (GCC 12 Release)
}
}  // namespace
}  // namespace phiq
