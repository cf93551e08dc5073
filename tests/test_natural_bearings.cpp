// A bearing at a natural point (BearingFriction on a point two bodies' frames share, solve/friction_losses.hpp): the
// natural four-bar, its links' angles coordinates of segment_angle constraints, with a journal at each of O, A, B, C
// needs the motor torque and carries the pin loads of the reference-point four-bar with the same journals on its
// revolutes, at every row, in a sweep and through the API's DriverEfforts; what cannot be split is refused in one
// line.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "phiq/phiq.hpp"
#include "reaction_rows.hpp"
#include "sensitivity_support.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

constexpr const char* kNaturalBearingsParts =
    "  crank: {%sframe: {origin: O, x: A}, mass: 1.0, center_of_mass: [0.2, 0], inertia: 0.013333333333333334}\n"
    "  coupler: {frame: {origin: A, x: B}, mass: 2.0, center_of_mass: [0.6, 0], inertia: 0.24}\n"
    "  rocker: {frame: {origin: C, x: B}, mass: 1.5, center_of_mass: [0.5, 0], inertia: 0.125}\n";

// Each link's bearing (μ 0.2, r 0.05) on the relative turn `turn[k]` of pin k (O, A, B, C).
std::string natural_bearings_loads(const char* const (&turn)[4]) {
  std::string s = "loads:\n  gravity: [0, -9.81]\n  torsional_springs:\n";
  const char* pins[4] = {"O", "A", "B", "C"};
  for (int k = 0; k < 4; ++k)
    s += std::string("    - {name: f") + pins[k] + ", angle: \"" + turn[k] + "\", bearing: {joint: " + pins[k] +
         ", coefficient: 0.2, radius: 0.05}}\n";
  return s + "time: {start: 0, end: 2*pi, steps: 48}\n" +
         "output: {velocities: true, accelerations: true, efforts: [motor], reactions: [O, A, B, C], losses: all}\n";
}

// seed/fourbar_natural.yaml with the coupler's and rocker's angles θ3, θ4 (segment_angle constraints), massive links
// and a bearing at each point; `angle_of_a` replaces the turn at A (θ3 − θ2).
std::string natural_four_bar_with_bearings(const std::string& angle_of_a = "theta3 - theta2") {
  std::string text = test::model_file_text("seed/fourbar_natural.yaml", "time:");
  text = test::replace_first(text, "  theta2: 0.0\n", "  theta2: 0.0\n  theta3: 1.0\n  theta4: 1.5\n");
  text = test::replace_first(text, "drivers:",
                             "  - {name: coupler_angle, type: segment_angle, segment: [A, B], angle: theta3}\n"
                             "  - {name: rocker_angle, type: segment_angle, segment: [C, B], angle: theta4}\n"
                             "drivers:");
  const char* const turn[4] = {"theta2", angle_of_a.c_str(), "theta4 - theta3", "theta4"};
  std::string parts = kNaturalBearingsParts;
  parts.replace(parts.find("%s"), 2, "");
  return text + "parts:\n" + parts + natural_bearings_loads(turn);
}

TEST(NaturalBearings, TheNaturalFourBarsJournalsAreTheReferencePointForms) {
  const Scene natural = parse_scene(natural_four_bar_with_bearings(), "natural.yaml");
  std::string text = test::model_file_text("seed/fourbar_reference_point.yaml", "time:");
  const char* const turn[4] = {"psi2", "psi3 - psi2", "psi4 - psi3", "psi4"};
  text +=
      "parts:\n"
      "  crank: {mass: 1.0, center_of_mass: [0, 0], inertia: 0.013333333333333334}\n"
      "  coupler: {mass: 2.0, center_of_mass: [0, 0], inertia: 0.24}\n"
      "  rocker: {mass: 1.5, center_of_mass: [0, 0], inertia: 0.125}\n" +
      natural_bearings_loads(turn);
  const Scene reference = parse_scene(text, "reference.yaml");
  SweepSummary sum;
  const test::ReactionRows a = test::sweep_reactions(natural, &sum), b = test::sweep_reactions(reference);
  ASSERT_EQ(a.values.size(), 49u);
  ASSERT_EQ(b.values.size(), 49u);
  EXPECT_GT(sum.counters.effort_solves, 3u * 49u);  // the moments are solved for, in passes
  double largest_friction = 0.0;
  for (std::size_t k = 0; k < a.values.size(); ++k) {
    const std::vector<double>&u = a.values[k], &v = b.values[k];
    ASSERT_EQ(u.size(), v.size());
    EXPECT_NEAR(u[0], v[0], 1e-8 * (1 + std::fabs(v[0]))) << "motor torque, row " << k;
    for (std::size_t j = 0; j < 4; ++j)
      for (std::size_t c = 0; c < 2; ++c)
        EXPECT_NEAR(u[2 + 3 * j + c], v[2 + 3 * j + c], 1e-8 * (1 + std::fabs(v[2 + 3 * j + c])))
            << "pin " << j << ", row " << k;
    for (std::size_t j = 0; j < 8; ++j)  // each bearing's friction and power
      EXPECT_NEAR(u[14 + j], v[14 + j], 1e-8 * (1 + std::fabs(v[14 + j]))) << "loss value " << j << ", row " << k;
    largest_friction = std::max(largest_friction, u[14]);
  }
  EXPECT_GT(largest_friction, 0.2);  // N m at O: the journals are felt
}

TEST(NaturalBearings, DriverEffortsGiveTheSweepsTorqueRowByRow) {
  // the API's loop over rows (its losses set up once, the scene's natural joints given): the sweep's motor torque,
  // and the one-row function's given them; without the natural joints the bearing names no joint it knows
  const Scene s = parse_scene(natural_four_bar_with_bearings(), "natural.yaml");
  const test::ReactionRows rows = test::sweep_reactions(s);
  ASSERT_EQ(rows.q.size(), 49u);
  DriverEfforts efforts(*s.model, s.parts, s.loads, s.sweep.efforts.natural);
  Workspace ws(*s.model);
  std::vector<double> e;
  for (std::size_t k = 0; k < rows.q.size(); ++k) {
    ws.q = rows.q[k], ws.qd = rows.qd[k], ws.qdd = rows.qdd[k];
    std::string why;
    ASSERT_EQ(efforts(s.sweep.time_of(static_cast<Index>(k)), ws, e, &why), SolveStatus::kSuccess) << why;
    ASSERT_EQ(e.size(), 1u);
    EXPECT_NEAR(e[0], rows.values[k][0], 1e-9 * (1 + std::fabs(rows.values[k][0]))) << "row " << k;
  }
  // the one-row function, given them, gives the last row's (set up again at its call)
  std::vector<double> once;
  ASSERT_EQ(driver_efforts(*s.model, s.parts, s.loads, s.sweep.t_end, ws, once, nullptr, s.sweep.efforts.natural),
            SolveStatus::kSuccess);
  ASSERT_EQ(once.size(), 1u);
  EXPECT_EQ(once[0], e[0]);
  EXPECT_THROW(
      {
        try {
          (void)driver_efforts(*s.model, s.parts, s.loads, 0.0, ws, e);
        } catch (const Error& error) {
          EXPECT_HAS(std::string(error.what()), "bearing joint 'O' is not a constraint of the model, nor a point");
          throw;
        }
      },
      Error);
}

// The efforts' ∂τ/∂p with the journals at the points: their loads are their bodies' balances, affine in λ (the losses'
// adjoint reads their own constraints' rows), and along p those balances read the bodies' motion, parts, loads, own
// constraints and fixed pivots as the scene along p holds them: the crank's length, the ground pivots' distance
// (C's constant) and μ, against re-solved sweeps, also with a massless part listed first.
TEST(NaturalBearings, TheEffortsSensitivitiesMatchResolvedSweeps) {
  std::string text = natural_four_bar_with_bearings();
  for (int pin = 0; pin < 4; ++pin) text = test::replace_first(text, "coefficient: 0.2", "coefficient: mu");
  text = test::replace_first(text, "parameters: {", "parameters: {mu: 0.2, ");
  text = test::replace_first(text, "time: {start: 0, end: 2*pi, steps: 48}", "time: {start: 0.1, end: 2.9, steps: 28}");
  text = test::replace_first(
      text, "output: {velocities: true, accelerations: true, efforts: [motor], reactions: [O, A, B, C], losses: all}",
      "output: {efforts: [motor], sensitivities: [L2, L1, mu]}");
  test::expect_effort_sensitivities_match_resolved_sweeps(text);
  // a massless part before the links (the efforts' parts keep those with mass: the links' indices shift)
  test::expect_effort_sensitivities_match_resolved_sweeps(
      test::replace_first(text, "parts:\n", "parts:\n  stand: {frame: {at: [0, 0], angle: 0}}\n"));
  // with a reference-point arm on a revolute at (0, 0.3), turned at twice the crank's rate and tied to the coupler by
  // a spring, its journal (radius ra) a bearing of a constraint beside the points' (its geometry kept per multiplier
  // apart from theirs)
  std::string arm = test::replace_first(text, "  theta4: 1.5\n", "  theta4: 1.5\n  xa: 0\n  ya: 0.3\n  pa: 0\n");
  arm = test::replace_first(arm, "points:", "bodies: {arm: [xa, ya, pa]}\npoints:");
  arm = test::replace_first(
      arm, "drivers:",
      "  - {name: arm_pivot, type: revolute, between: [{body: ground, at: [0, 0.3]}, {body: arm}]}\n"
      "  - {name: arm_follows, type: equation, expr: \"pa - 2*theta2\", unit: angle}\n"
      "drivers:");
  arm = test::replace_first(arm, "parts:\n", "parts:\n  arm: {mass: 0.5, center_of_mass: [0.1, 0], inertia: 0.01}\n");
  arm = test::replace_first(
      arm, "  torsional_springs:\n",
      "  springs: [{name: tie, between: [{part: arm, at: [0.2, 0]}, {part: coupler, at: [0.5, 0]}], "
      "stiffness: 40, free_length: 0.3}]\n"
      "  torsional_springs:\n    - {name: fa, angle: pa, bearing: {joint: arm_pivot, coefficient: "
      "mu, radius: ra}}\n");
  arm = test::replace_first(arm, "parameters: {", "parameters: {ra: 0.03, ");
  test::expect_effort_sensitivities_match_resolved_sweeps(
      test::replace_first(arm, "sensitivities: [L2, L1, mu]", "sensitivities: [L2, mu, ra]"));
}

TEST(NaturalBearings, WhatCannotBeSplitIsRefusedInOneLine) {
  // a turn that reads the points: its moment does not say which bodies it turns, so the points' reactions, which the
  // bearings read, cannot hold it: the scene's reader refuses it at the first bearing at a point
  const std::string reads_points = "atan2(yB - yA, xB - xA) - theta2";
  EXPECT_HAS(test::scene_error(
                 test::replace_first(natural_four_bar_with_bearings(reads_points), "reactions: [O, A, B, C], ", "")),
             "loads.torsional_springs[0].bearing.joint: the bearing at natural point 'O' would hold torsional spring "
             "'fA''s moment: its angle reads the points");
  {  // and the losses' set-up, for loads built in code: that spring put in place of fA, with fA's bearing
    const Scene good = parse_scene(natural_four_bar_with_bearings(), "natural.yaml");
    std::string bare =
        test::replace_first(natural_four_bar_with_bearings(reads_points), "reactions: [O, A, B, C], losses: all", "");
    for (const char* pin : {"O", "A", "B", "C"})
      bare = test::replace_first(bare, std::string(", bearing: {joint: ") + pin + ", coefficient: 0.2, radius: 0.05}",
                                 ", stiffness: 0");
    const Scene spring = parse_scene(bare, "natural.yaml");  // (no bearing: nothing to refuse)
    Loads loads = good.loads;
    auto applied = std::make_shared<AppliedLoads>(*loads.applied);
    TorsionalSpring& fA = applied->torsional_springs.at(1);
    ASSERT_EQ(fA.name, "fA");
    const BearingFriction bearing = *fA.bearing;
    fA = spring.loads.applied->torsional_springs.at(1);
    fA.bearing = bearing;
    loads.applied = applied;
    EXPECT_THROW(
        {
          try {
            DriverEfforts efforts(*good.model, good.parts, loads, good.sweep.efforts.natural);
          } catch (const Error& e) {
            EXPECT_HAS(std::string(e.what()),
                       "torsional spring 'fA': bearing at natural point 'A': its angle reads "
                       "the points");
            throw;
          }
        },
        Error);
  }
  // a bearing at a point no two parts hold (the rocker gone, B is the coupler's alone): refused where it is named
  EXPECT_HAS(test::scene_error(test::replace_first(
                 test::replace_first(natural_four_bar_with_bearings(), "reactions: [O, A, B, C], ", ""),
                 "  rocker: {frame: {origin: C, x: B}, mass: 1.5, center_of_mass: [0.5, 0], inertia: 0.125}\n", "")),
             "loads.torsional_springs[2].bearing.joint: point 'B' is no joint: no two parts with frames of points hold "
             "it");
}

}  // namespace
}  // namespace phiq
