// A bearing's friction from its joint's reaction (BearingFriction, solve/friction_losses.hpp): a massive four-bar
// with a bearing at every pin satisfies every link's Newton–Euler equations written here, each pin's friction couple
// μ r |F| against its relative turn from the written reaction F; a driven pendulum's pivot (μ r |F| added to
// m g l cos ψ) and a spatial rotor's journal and thrust collar (μ (r m ω² e + r_a m g)) against their closed forms,
// through driver_efforts() and the sweep; a cam follower's guide rubs by μ times the cam's side push (Newton, the
// power), settles where μ tan φ < 1 to the closed form and is told where it exceeds 1 (self-locking); parallel
// chunks give the sequential bits; a jamming four-bar is told at its rows; a gear train's, a bevel pair's and a
// planetary's meshing losses (GearLoss) against the motor torque their efficiencies give, whichever way the power
// flows (the planetary's the textbook (1 + η0 i0) / (1 + i0)); and bad input is refused in one line.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>

#include "phiq/applied_loads.hpp"
#include "phiq/inverse_dynamics.hpp"
#include "phiq/phiq.hpp"
#include "phiq/stepper.hpp"
#include "reaction_rows.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// models/dynamics/fourbar_pin_loads.yaml with a bearing of μ, r at each of its pins O, A, B, C, and `output`.
std::string fourbar_with_bearings(double mu, double r, const std::string& output) {
  std::string text = test::model_file_text("dynamics/fourbar_pin_loads.yaml", "loads:");
  const std::string b = "coefficient: " + std::to_string(mu) + ", radius: " + std::to_string(r) + "}}\n";
  text +=
      "loads:\n  gravity: [0, -9.81]\n  torsional_springs:\n"
      "    - {name: fO, angle: psi2, bearing: {joint: O, " +
      b + "    - {name: fA, angle: psi3 - psi2, bearing: {joint: A, " + b +
      "    - {name: fB, angle: psi4 - psi3, bearing: {joint: B, " + b +
      "    - {name: fC, angle: psi4, bearing: {joint: C, " + b + "time: {start: 0, end: 1, steps: 72}\n" + output;
  return text;
}

TEST(BearingFriction, FourBarPinsWithBearingsSatisfyEveryLinksNewtonEuler) {
  const double mu = 0.3, radius = 0.05;
  const std::string out = "output: {velocities: true, accelerations: true, efforts: [motor], reactions: all}\n";
  const Scene s = parse_scene(fourbar_with_bearings(mu, radius, out), "bearings.yaml");
  SweepSummary sum;
  const test::ReactionRows rows = test::sweep_reactions(s, &sum);
  ASSERT_EQ(rows.q.size(), 73u);
  EXPECT_GT(sum.counters.effort_solves, 3 * 73) << "the moments are solved for, in passes";
  auto c = [&](const char* n) { return s.model->coordinate_index(n); };
  double largest_couple = 0.0;
  for (std::size_t k = 0; k < rows.q.size(); ++k) {
    const Eigen::VectorXd& qd = rows.qd[k];
    const std::vector<double>& v = rows.values[k];
    // each pin's friction couple μ r |F| against its relative turn θ̇ (θ = ψ_b − ψ_a; O's and C's ψ against ground)
    const double turn[4] = {qd(c("psi2")), qd(c("psi3")) - qd(c("psi2")), qd(c("psi4")) - qd(c("psi3")), qd(c("psi4"))};
    double f[4];
    for (int j = 0; j < 4; ++j) {
      f[j] = mu * radius * std::hypot(v[2 + 3 * j], v[3 + 3 * j]) * friction_direction(turn[j]);
      largest_couple = std::max(largest_couple, std::fabs(f[j]));
    }
    // on each link: −f on the turn's later body, +f on its earlier one; the motor's torque on the crank
    test::expect_fourbar_links_balance(*s.model, rows.q[k], rows.qdd[k], v,
                                       {v[0] - f[0] + f[1], -f[1] + f[2], -f[2] - f[3]}, 1e-9, k);
  }
  EXPECT_GT(largest_couple, 0.3);  // the couples are felt: a frictionless solution fails the moments above
}

// A bar of mass mass pinned at its end to ground, its centre at l, driven at ψ = ω t with a pivot bearing of μ, r.
std::string pendulum_text(double mu, double r, const std::string& output) {
  return "phiq: 1\nname: pivot\nparameters: {l: 0.5, w: 3}\n"
         "coordinates: {x: 0.5, y: 0, psi: 0}\nbodies: {bar: [x, y, psi]}\n"
         "constraints:\n  - {name: pivot, type: revolute, between: [{body: bar, at: [-l, 0]}, {body: ground, at: "
         "[0, 0]}]}\n"
         "drivers:\n  - {name: motor, coordinate: psi, law: {type: linear, initial: 0.3, rate: w}}\n"
         "parts:\n  bar: {mass: 2.0, center_of_mass: [0, 0], inertia: 0.1}\n"
         "loads:\n  gravity: [0, -9.81]\n  torsional_springs:\n    - {name: journal, angle: psi, bearing: {joint: "
         "pivot, "
         "coefficient: " +
         std::to_string(mu) + ", radius: " + std::to_string(r) +
         "}}\n"
         "time: {start: 0, end: 2, steps: 40}\n" +
         output;
}

TEST(BearingFriction, ADrivenPendulumsPivotAddsMuRTimesItsLoad) {
  const double mu = 0.25, r = 0.03, mass = 2.0, l = 0.5, w = 3.0, g = 9.81;
  const Scene s = parse_scene(
      pendulum_text(mu, r, "output: {velocities: true, accelerations: true, efforts: [motor], reactions: all}\n"),
      "pivot.yaml");
  const test::ReactionRows rows = test::sweep_reactions(s);
  ASSERT_EQ(rows.q.size(), 41u);
  Workspace ws(*s.model);
  std::vector<double> efforts;
  for (std::size_t k = 0; k < rows.q.size(); ++k) {
    const double psi = rows.q[k](s.model->coordinate_index("psi"));
    // the pivot's push on the bar: m a_G − m g, a_G = −ω² l (cos ψ, sin ψ) (no angular acceleration)
    const Eigen::Vector2d F(-mass * w * w * l * std::cos(psi), -mass * w * w * l * std::sin(psi) + mass * g);
    const double expected = mass * g * l * std::cos(psi) + mu * r * F.norm();
    EXPECT_NEAR(rows.values[k][0], expected, 1e-10 * (1.0 + std::fabs(expected))) << "sweep, row " << k;
    EXPECT_NEAR(rows.values[k][2], F.x(), 1e-9 * F.norm()) << "row " << k;  // a couple moves no pin force
    ws.q = rows.q[k], ws.qd = rows.qd[k], ws.qdd = rows.qdd[k];
    std::string why;
    ASSERT_EQ(driver_efforts(*s.model, s.parts, s.loads, 2.0 * static_cast<double>(k) / 40.0, ws, efforts, &why),
              SolveStatus::kSuccess)
        << why;
    EXPECT_NEAR(efforts.at(0), expected, 1e-10 * (1.0 + std::fabs(expected))) << "driver_efforts, row " << k;
  }
}

// A disc of 3 kg on a vertical hinge at the origin, its centre 0.1 off the axis at height `height`, turned at 4 rad/s,
// with a journal of μ 0.15, r 0.02 and a thrust collar of r_a 0.035, `more` its other bearing fields.
std::string rotor_text(double height, const std::string& more) {
  return "phiq: 1\nname: rotor\ndimension: 3\n"
         "coordinates: {x: 0, y: 0, z: 0, e0: 1, e1: 0, e2: 0, e3: 0}\nbodies: {disc: [x, y, z, e0, e1, e2, e3]}\n"
         "constraints:\n  - {name: hinge, type: revolute, between: [{body: ground, axis: [0, 0, 1]}, {body: disc, "
         "axis: [0, 0, 1]}]}\n"
         "drivers:\n  - {name: motor, joint: hinge, law: {type: linear, initial: 0, rate: 4}}\n"
         "parts:\n  disc: {mass: 3.0, center_of_mass: [0.1, 0, " +
         std::to_string(height) +
         "], inertia: [0.02, 0.03, 0.04]}\n"
         "loads:\n  gravity: [0, 0, -9.81]\n"
         "  torsional_springs: [{name: bearing, joint: hinge, bearing: {coefficient: 0.15, radius: 0.02, "
         "thrust_radius: 0.035" +
         more +
         "}}]\n"
         "time: {start: 0, end: 1.5, steps: 30}\n"
         "output: {velocities: true, accelerations: true, efforts: [motor]}\n";
}

TEST(BearingFriction, ASpatialRotorsJournalAndThrustCollarTakeMuTimesTheirLoads) {
  // radial load m ω² e, axial m g; with a bending arm a, the moment across the axis m e (h ω² + g) (the weight's
  // lever e, and the centrifugal force's h: d(H_O)/dt = ω × I_O ω with I_O's product −m e h) presses the journal as
  // its moment over a
  const double mu = 0.15, r = 0.02, ra = 0.035, mass = 3.0, e = 0.1, w = 4.0, g = 9.81, h = 0.25, a = 0.04;
  for (const bool bending : {false, true}) {
    const Scene s = parse_scene(rotor_text(bending ? h : 0.0, bending ? ", moment_arm: 0.04" : ""), "rotor.yaml");
    const test::ReactionRows rows = test::sweep_reactions(s);
    ASSERT_EQ(rows.q.size(), 31u);
    const double moment = bending ? mass * e * (h * w * w + g) / a : 0.0;
    const double expected = mu * (r * (mass * w * w * e + moment) + ra * mass * g);
    for (std::size_t k = 0; k < rows.q.size(); ++k)
      EXPECT_NEAR(rows.values[k][0], expected, 1e-10 * expected) << "row " << k << (bending ? ", bending" : "");
  }
}

TEST(BearingFriction, ASlidesTiltPressesItAsItsMomentOverTheArm) {
  // a 2 kg block pushed along a level slide at a constant speed, its centre d = 0.3 ahead of the slide's point: the
  // slide holds its weight m g and its tilt m g d, and the push is μ m g (1 + d / a) with a moment arm a, μ m g without
  const double mu = 0.2, mass = 2.0, g = 9.81, d = 0.3, a = 0.15;
  for (const bool tilt : {false, true}) {
    const std::string text =
        "phiq: 1\nname: block\ncoordinates: {x: 0, y: 0, psi: 0}\nbodies: {block: [x, y, psi]}\n"
        "constraints:\n  - {name: slide, type: prismatic, between: [{body: ground}, {body: block}]}\n"
        "drivers:\n  - {name: push, coordinate: x, law: {type: linear, initial: 0.1, rate: 0.5}}\n"
        "parts:\n  block: {mass: 2.0, center_of_mass: [0.3, 0], inertia: 0.01}\n"
        "loads:\n  gravity: [0, -9.81]\n"
        "  torsional_springs: [{name: guide, coordinate: x, bearing: {joint: slide, coefficient: 0.2" +
        std::string(tilt ? ", moment_arm: 0.15" : "") +
        "}}]\n"
        "time: {start: 0, end: 1, steps: 10}\noutput: {velocities: true, accelerations: true, efforts: [push], "
        "reactions: all, reaction_axes: joint, losses: all}\n";
    const Scene s = parse_scene(text, "block.yaml");
    const test::ReactionRows rows = test::sweep_reactions(s);
    ASSERT_EQ(rows.q.size(), 11u);
    const double expected = mu * mass * g * (1.0 + (tilt ? d / a : 0.0));
    for (std::size_t k = 0; k < rows.q.size(); ++k) {
      const std::vector<double>& v = rows.values[k];  // push, its power, the slide's Fx, Fy, Mz, the guide's rub
      EXPECT_NEAR(v[0], expected, 1e-10 * expected) << "row " << k;
      EXPECT_NEAR(std::fabs(v[4]), mass * g * d, 1e-10 * mass * g) << "row " << k;  // the tilt, about the point
      EXPECT_NEAR(v[5], expected, 1e-10 * expected) << "row " << k;
    }
  }
}

TEST(BearingFriction, ASpatialSlidesMomentPressesItOverTheArm) {
  // the block's weight m g across the slide and its moment m g √(d² + e²) about the block's point, the reaction's
  // (its centre off the point along and across the travel): the push is μ m g (1 + √(d² + e²) / a)
  const double mu = 0.2, mass = 2.0, g = 9.81, d = 0.3, e = 0.1, a = 0.15;
  const Scene s = parse_scene(test::spatial_slide_text(d, e,
                                                       "output: {velocities: true, accelerations: true, "
                                                       "efforts: [push], reactions: all, losses: all}\n"),
                              "block.yaml");
  const test::ReactionRows rows = test::sweep_reactions(s);
  ASSERT_EQ(rows.q.size(), 11u);
  const double expected = mu * mass * g * (1.0 + std::hypot(d, e) / a);
  for (std::size_t k = 0; k < rows.q.size(); ++k) {
    // (the joint's distance, ground's along the block's axis, falls as the block moves along x: the push is −effort)
    EXPECT_NEAR(-rows.values[k][0], expected, 1e-10 * expected) << "row " << k;
    EXPECT_NEAR(rows.values[k].at(8), expected, 1e-10 * expected) << "row " << k;  // the guide's rub, written
  }
}

TEST(BearingFriction, ACamFollowersGuideRubsByMuTimesTheCamsSidePush) {
  // models/cams/eccentric_roller.yaml: the cam's push on the roller leans off the guide's axis; the guide takes the
  // lean across, and its friction μ |F_across| opposes the rod's travel, so the cam pushes harder
  const double m = 0.7, g = 9.81, mu = 0.3, e = 0.015;
  const std::string text =
      test::model_file_text("cams/eccentric_roller.yaml", "output:") +
      "parts:\n  rod: {mass: 0.7, center_of_mass: [0, 0], inertia: 1e-3}\n"
      "  disc: {mass: 2.0, center_of_mass: [0, 0], inertia: 3e-3}\n"
      "loads:\n  gravity: [0, -9.81]\n"
      "  torsional_springs: [{name: rub, coordinate: yf, bearing: {joint: guide, coefficient: 0.3}}]\n"
      "output: {velocities: true, accelerations: true, efforts: [motor], power: true, "
      "reactions: [cam, guide]}\n";
  const Scene s = parse_scene(text, "rub.yaml");
  const Model* swept = nullptr;
  const test::ReactionRows rows = test::sweep_reactions(s, nullptr, &swept);
  ASSERT_EQ(rows.q.size(), 73u);
  const Index yf = swept->coordinate_index("yf"), th = swept->coordinate_index("th");
  double largest_rub = 0.0;
  for (std::size_t k = 0; k < rows.q.size(); ++k) {
    const std::vector<double>& v = rows.values[k];
    const Eigen::Vector2d cam(v[2], v[3]), guide(v[5], v[6]);  // each on the rod
    const double yd = rows.qd[k](yf), ydd = rows.qdd[k](yf);
    const double rub = -mu * guide.norm() * friction_direction(yd);
    largest_rub = std::max(largest_rub, std::fabs(rub));
    // the rod, which only slides: Newton across the guide and along it, the rub in its y
    EXPECT_NEAR(cam.x() + guide.x(), 0.0, 1e-9) << k;
    EXPECT_NEAR(cam.y() + guide.y() + rub - m * g, m * ydd, 1e-9) << k;
    // the cam pushes along the contact's normal, from its circle's centre to the roller's (on x = 0)
    const double t = rows.q[k](th), nx = -e * std::cos(t), ny = rows.q[k](yf) - e * std::sin(t);
    EXPECT_NEAR(cam.x() * ny - cam.y() * nx, 0.0, 1e-9 * cam.norm()) << k;
    // the motor's power: the rod's kinetic and potential energy's rate and what the guide's rub dissipates (the
    // disc turns steadily about its centre)
    EXPECT_NEAR(v[1], m * yd * (ydd + g) - rub * yd, 1e-9 * (1.0 + std::fabs(v[1]))) << k;
  }
  EXPECT_GT(largest_rub, 0.05);  // the side push is felt
}

TEST(BearingFriction, ACamFollowerJamsWhereMuTanPhiReachesOne) {
  // A steeper cam (pressure angle φ up to 37°): the guide's rub μ |F sin φ| against the push's lift F cos φ, so the
  // pass multiplies a change of the rub by ρ = μ |tan φ|, the follower's classic self-locking number. Below 1 the
  // rub settles to its closed form; above it the rows are told (no solution, or two: never a number).
  const double mu = 2.0, m = 0.7, g = 9.81, e = 0.015;
  std::string text = test::model_file_text("cams/eccentric_roller.yaml", "output:");
  text = test::replace_first(text, "{R: 0.05, e: 0.015, rho: 0.01,", "{R: 0.02, e: 0.015, rho: 0.005,");
  text = test::replace_first(text, "yf: 0.07", "yf: 0.03");
  text +=
      "parts:\n  rod: {mass: 0.7, center_of_mass: [0, 0], inertia: 1e-3}\n"
      "loads:\n  gravity: [0, -9.81]\n"
      "  torsional_springs: [{name: rub, coordinate: yf, bearing: {joint: guide, coefficient: 2}}]\n"
      "output: {velocities: true, accelerations: true, efforts: [motor], reactions: [cam]}\n";
  const Scene s = parse_scene(text, "steep.yaml");
  SquareScene square;
  ASSERT_EQ(prepare_scene(*s.model, s.sweep.t_begin, s.sweep.assembly, &square), SolveStatus::kSuccess);
  const Model& model = square.model(*s.model);
  const Index yf = model.coordinate_index("yf"), th = model.coordinate_index("th");
  Workspace ws(model);
  ws.q = square.start;
  SweepSummary sum;
  std::size_t settled = 0, told = 0;
  ASSERT_EQ(run_sweep(
                model, s.sweep, ws,
                [&](const StepView& v) {
                  const double y = v.q(yf), t = v.q(th), nx = -e * std::cos(t), ny = y - e * std::sin(t);
                  const double rho = mu * std::fabs(nx / ny);
                  if (rho < 0.9) {
                    // the closed form: the lift F ny/|n| less the rub μ F |nx|/|n| against ẏ carries m (ÿ + g)
                    const double yd = (*v.qd)(yf), ydd = (*v.qdd)(yf), s_rub = friction_direction(yd);
                    const double F = m * (ydd + g) * std::hypot(nx, ny) / (ny - s_rub * mu * std::fabs(nx));
                    EXPECT_NEAR(std::hypot(v.efforts[2], v.efforts[3]), std::fabs(F), 1e-9 * std::fabs(F)) << t;
                    EXPECT_TRUE(std::isfinite(v.efforts[0])) << t;
                    ++settled;
                  } else if (rho > 1.1) {
                    EXPECT_TRUE(std::isnan(v.efforts[0])) << "ρ = " << rho << " at θ = " << t;
                    ++told;
                  }
                  return true;
                },
                &sum),
            SolveStatus::kSuccess);
  EXPECT_GT(settled, 20u);
  EXPECT_GT(told, 5u);
  bool warned = false;
  for (const SweepWarning& w : sum.warnings) warned = warned || w.kind == "friction_lock";
  EXPECT_TRUE(warned);
}

// The gear train of models/transmissions/gear_train.yaml, massless, its output held back by a constant torque T
// while the motor turns it three turns each way: the ideal motor torque −T/9, divided by η1 η2 while the motor drives
// the load, multiplied by it while the load drives back (a constant torque, so it aids the motion on the way back).
TEST(GearLosses, AGearTrainsMotorPaysItsTwoStagesLossesWhicheverWayThePowerFlows) {
  const double T = -2.0, eta1 = 0.95, eta2 = 0.9;
  const std::string text = test::model_file_text("transmissions/gear_train.yaml", "output: {") +
                           "loads:\n  torques: [{name: load, part: output, torque: -2}]\n"
                           "  gear_losses: [{gear: first_stage, efficiency: 0.95}, {gear: second_stage, efficiency: "
                           "0.9}]\noutput: {velocities: true, accelerations: true, efforts: [motor], power: true}\n";
  const Scene s = parse_scene(text, "train.yaml");
  SweepSummary sum;
  const test::ReactionRows rows = test::sweep_reactions(s, &sum);
  ASSERT_EQ(rows.q.size(), 121u);
  const Index psi1 = s.model->coordinate_index("psi1");
  std::size_t driving = 0, driven = 0;
  Workspace ws(*s.model);
  std::vector<double> efforts;
  for (std::size_t k = 0; k < rows.q.size(); ++k) {
    const double w = rows.qd[k](psi1), ideal = -T / 9.0;
    const double expected = w > 0 ? ideal / (eta1 * eta2) : w < 0 ? ideal * eta1 * eta2 : ideal;
    EXPECT_NEAR(rows.values[k][0], expected, 1e-12) << "row " << k << ", ω " << w;
    ws.q = rows.q[k], ws.qd = rows.qd[k], ws.qdd = rows.qdd[k];  // the same through driver_efforts()
    ASSERT_EQ(driver_efforts(*s.model, s.parts, s.loads, s.sweep.time_of(static_cast<Index>(k)), ws, efforts),
              SolveStatus::kSuccess);
    EXPECT_NEAR(efforts.at(0), expected, 1e-12) << "driver_efforts(), row " << k;
    // the losses' power: what the motor puts in less what the load takes, (1 − η1 η2) of the power through
    const double lost = rows.values[k][1] + T * w / 9.0;
    EXPECT_NEAR(lost, std::fabs(ideal * w) * (w > 0 ? 1.0 / (eta1 * eta2) - 1.0 : 1.0 - eta1 * eta2), 1e-11) << k;
    (w > 0 ? driving : driven) += w != 0.0;
  }
  EXPECT_GT(driving, 30u);
  EXPECT_GT(driven, 30u);
  EXPECT_GT(sum.counters.effort_solves, 2 * 121) << "the losses are solved for, in passes";
}

// models/transmissions/bevel_gears.yaml (15:30, the output turning the other way at half the speed), massless, a
// torque of ±3 N·m about the output shaft's axis: resisting, the motor pays 1.5 / η; aiding, the load drives the
// motor, which holds back 1.5 η_r (the reverse efficiency, as a worm's back-driving one).
TEST(GearLosses, ABevelPairsLossTakesEtaOfThePowerEachWay) {
  const double eta = 0.8, eta_r = 0.6;
  for (const double torque : {3.0, -3.0}) {
    const std::string text = test::model_file_text("transmissions/bevel_gears.yaml", "output:") +
                             "loads:\n  torques: [{name: load, part: output_shaft, torque: [0, " +
                             std::to_string(torque) +
                             ", 0]}]\n  gear_losses: [{gear: bevel, efficiency: 0.8, reverse_efficiency: 0.6}]\n"
                             "output: {velocities: true, accelerations: true, efforts: [motor]}\n";
    const Scene s = parse_scene(text, "bevel.yaml");
    const test::ReactionRows rows = test::sweep_reactions(s);
    ASSERT_EQ(rows.q.size(), 61u);
    // the output turns at −θ̇1/2 about y: the load's power −torque θ̇1/2, the motor's ideal torque torque/2
    const double ideal = torque / 2.0, expected = torque > 0 ? ideal / eta : ideal * eta_r;
    for (std::size_t k = 0; k < rows.q.size(); ++k)
      EXPECT_NEAR(rows.values[k][0], expected, 1e-10 * std::fabs(expected)) << "torque " << torque << ", row " << k;
  }
}

// models/transmissions/planetary.yaml with its ring held and a torque of 1 N·m holding back the carrier: the sun
// drives the carrier at ω_c = 24/84 of its speed, and the meshes' losses act on the turns relative to the carrier,
// which gives the textbook efficiency of sun to carrier, ring fixed, η = (1 + η0 i0) / (1 + i0), i0 = z_ring / z_sun,
// η0 = η_sun_planet η_planet_ring: the sun's torque is (2/7) / η.
TEST(GearLosses, APlanetarysLossesAreTheTextbooksSunToCarrierEfficiency) {
  std::string text = test::model_file_text("transmissions/planetary.yaml", "output:");
  text = test::replace_first(text, "rate: -0.2}}", "rate: 0}}");
  text +=
      "loads:\n  torques: [{name: load, part: carrier, torque: -1}]\n"
      "  gear_losses: [{gear: sun_planet, efficiency: 0.95}, {gear: planet_ring, efficiency: 0.9}]\n"
      "output: {velocities: true, accelerations: true, efforts: [sun_motor]}\n";
  const test::ReactionRows rows = test::sweep_reactions(parse_scene(text, "planetary.yaml"));
  ASSERT_EQ(rows.q.size(), 141u);
  const double i0 = 60.0 / 24.0, eta0 = 0.95 * 0.9, eta = (1.0 + eta0 * i0) / (1.0 + i0);
  for (std::size_t k = 0; k < rows.q.size(); ++k) EXPECT_NEAR(rows.values[k][0], (2.0 / 7.0) / eta, 1e-12) << k;
}

// The worm of test_bevel_meshes.cpp (one start, pitch radius 0.01 m; a 30-tooth wheel of 0.05 m: lead angle
// λ = atan(1/6)), massless, turned at a rising speed against a torque T about its wheel's shaft, with tooth friction μ:
// the motor pays (T/30) / η, η = (cos φ − μ tan λ)/(cos φ + μ cot λ), when T resists; when T drives, (T/30) η_r,
// η_r = (cos φ − μ cot λ)/(cos φ + μ tan λ), which at μ = 0.2 is negative: the worm locks itself, and the motor
// pushes the load down.
TEST(GearLosses, AWormsFrictionGivesItsEfficienciesAndLocksItWhereTheyTurnNegative) {
  const std::string base = test::worm_scene_text(20);
  const double tan_lead = 1.0 / 6.0, c = std::cos(20 * M_PI / 180);
  for (const double mu : {0.05, 0.2})
    for (const double T : {0.6, -0.6}) {
      const std::string text = base + "loads:\n  torques: [{name: load, part: output_shaft, torque: [0, " +
                               std::to_string(T) +
                               ", 0]}]\n  gear_losses: [{gear: bevel, friction: " + std::to_string(mu) +
                               "}]\noutput: {velocities: true, accelerations: true, efforts: [motor]}\n";
      const test::ReactionRows rows = test::sweep_reactions(parse_scene(text, "worm.yaml"));
      ASSERT_EQ(rows.q.size(), 21u);
      const double eta = (c - mu * tan_lead) / (c + mu / tan_lead), eta_r = (c - mu / tan_lead) / (c + mu * tan_lead);
      const double expected = T > 0 ? (T / 30) / eta : (T / 30) * eta_r;
      if (mu == 0.2 && T < 0) {
        EXPECT_GT(expected, 0.0);  // (self-locking: the motor pushes the load down)
      }
      for (std::size_t k = 0; k < rows.q.size(); ++k)
        EXPECT_NEAR(rows.values[k][0], expected, 1e-10 * std::fabs(expected))
            << "μ " << mu << ", T " << T << ", row " << k;
    }
}

TEST(GearLosses, AFrictionCoefficientIsRefusedWhereThePairIsNoWorm) {
  // the bevel pair with its mean pitch radii: its axes meet, where the worm's lead angle means nothing
  std::string text = test::model_file_text("transmissions/bevel_gears.yaml", "output:");
  text = test::replace_first(text, "teeth: [15, 30]", "radii: [0.03, 0.06]");
  text +=
      "loads:\n  torques: [{name: load, part: output_shaft, torque: [0, 1, 0]}]\n"
      "  gear_losses: [{gear: bevel, friction: 0.1}]\noutput: {velocities: true, accelerations: true, efforts: "
      "[motor]}\n";
  const Scene s = parse_scene(text, "bevel.yaml");
  EXPECT_HAS(test::sweep_error(*s.model, s.sweep), "its axes meet");  // (a bevel pair's is no worm's)
}

TEST(GearLosses, BadLossesAreRefusedInOneLine) {
  const std::string base = test::model_file_text("transmissions/gear_train.yaml", "output: {") +
                           "loads:\n  torques: [{name: load, part: output, torque: -2}]\n";
  const std::string out = "output: {efforts: [motor]}\n";
  for (const auto& [losses, expected] : std::vector<std::pair<std::string, std::string>>{
           {"[{gear: input_pivot, efficiency: 0.9}]", "'input_pivot' is a pin"},
           {"[{gear: nowhere, efficiency: 0.9}]", "unknown transmission 'nowhere'"},
           {"[{gear: first_stage, efficiency: 1.2}]", "an efficiency is in (0, 1]"},
           {"[{gear: first_stage, efficiency: 0}]", "an efficiency is in (0, 1]"},
           {"[{gear: first_stage, efficiency: 0.9, reverse_efficiency: 1.5}]", "a reverse efficiency is at most 1"},
           {"[{gear: first_stage, friction: 0.1}]", "a worm pair's efficiencies (a spatial_gear)"},
           {"[{gear: first_stage, friction: 0.1, efficiency: 0.9}]", "give one or the other"},
           {"[{gear: first_stage}]", "efficiency"}}) {
    try {
      parse_scene(base + "  gear_losses: " + losses + "\n" + out, "bad.yaml");
      ADD_FAILURE() << "accepted: " << losses;
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
}

TEST(BearingFriction, ParallelChunksGiveTheSequentialBits) {
  const Scene s = parse_scene(
      fourbar_with_bearings(0.3, 0.05, "output: {efforts: all, power: true, reactions: all, losses: all}\n"),
      "bearings.yaml");
  auto values = [&](int threads) {
    SweepOptions opt = s.sweep;
    opt.threads = threads;
    std::vector<double> out;
    Workspace ws(*s.model);
    ws.q = s.model->initial_positions();
    EXPECT_EQ(run_sweep(
                  *s.model, opt, ws,
                  [&](const StepView& v) {
                    out.insert(out.end(), v.efforts, v.efforts + s.sweep.efforts.size());
                    return true;
                  },
                  nullptr),
              SolveStatus::kSuccess);
    return out;
  };
  const std::vector<double> one = values(1), two = values(2);
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) ASSERT_EQ(one[i], two[i]) << "value " << i;
}

TEST(BearingFriction, AStepperGivesTheSweepsEffortsWithBearingsAndGearLosses) {
  // the bearings' four-bar and the lossy gear train stepped over their grids: each step's efforts and losses are the
  // sequential sweep's rows, bit for bit (one chunk)
  const std::string train = test::model_file_text("transmissions/gear_train.yaml", "output: {") +
                            "loads:\n  torques: [{name: load, part: output, torque: -2}]\n"
                            "  gear_losses: [{gear: first_stage, efficiency: 0.95}]\n"
                            "output: {velocities: true, accelerations: true, efforts: [motor], power: true, "
                            "losses: all}\n";
  for (const std::string& text :
       {fourbar_with_bearings(0.3, 0.05, "output: {efforts: all, power: true, reactions: all, losses: all}\n"),
        train}) {
    const Scene s = parse_scene(text, "stepped.yaml");
    SweepOptions opt = s.sweep;
    opt.chunk_steps = opt.steps;  // (the rows in order, as a stepper's)
    std::vector<std::vector<double>> rows;
    Workspace ws(*s.model);
    ws.q = s.model->initial_positions();
    const std::size_t n = static_cast<std::size_t>(s.sweep.efforts.size());
    ASSERT_EQ(run_sweep(
                  *s.model, opt, ws,
                  [&](const StepView& v) {
                    rows.emplace_back(v.efforts, v.efforts + n);
                    return true;
                  },
                  nullptr),
              SolveStatus::kSuccess);
    StepperOptions o;
    static_cast<SolverSettings&>(o) = s.sweep;
    o.efforts = s.sweep.efforts;
    Stepper stepper(*s.model, o);
    for (Index k = 0; k <= s.sweep.steps; ++k) {
      ASSERT_EQ(stepper.step(s.sweep.time_of(k)), SolveStatus::kSuccess);
      for (std::size_t i = 0; i < n; ++i)
        ASSERT_EQ(stepper.efforts()[i], rows[static_cast<std::size_t>(k)][i]) << "row " << k << ", value " << i;
    }
  }
}

TEST(BearingFriction, AJammingFourBarIsToldAtItsRowsWithNoEffort) {
  // journals as wide as the links: at some rows the friction adds to its own load more than it takes
  const Scene s = parse_scene(fourbar_with_bearings(1.0, 1.0, "output: {efforts: [motor]}\n"), "jam.yaml");
  Workspace ws(*s.model);
  ws.q = s.model->initial_positions();
  std::size_t undefined = 0, defined = 0;
  SweepSummary sum;
  ASSERT_EQ(run_sweep(
                *s.model, s.sweep, ws,
                [&](const StepView& v) {
                  (std::isnan(v.efforts[0]) ? undefined : defined) += 1;
                  return true;
                },
                &sum),
            SolveStatus::kSuccess);
  EXPECT_GT(undefined, 10u);
  EXPECT_GT(defined, 5u);
  std::size_t told = 0;
  for (const SweepWarning& w : sum.warnings)
    if (w.kind == "friction_lock") {
      ++told;
      EXPECT_NE(w.message.find("jams (self-locking)"), std::string::npos) << w.message;
    }
  EXPECT_GE(told, 1u);
  // realistic bearings settle everywhere
  const Scene fine = parse_scene(fourbar_with_bearings(0.2, 0.02, "output: {efforts: [motor]}\n"), "fine.yaml");
  SweepSummary fine_sum;
  Workspace fine_ws(*fine.model);
  fine_ws.q = fine.model->initial_positions();
  ASSERT_EQ(
      run_sweep(
          *fine.model, fine.sweep, fine_ws, [&](const StepView& v) { return std::isfinite(v.efforts[0]); }, &fine_sum),
      SolveStatus::kSuccess);
  EXPECT_TRUE(fine_sum.warnings.empty());
}

TEST(BearingFriction, BadBearingsAreRefusedInOneLine) {
  const std::string out = "output: {efforts: [motor]}\n";
  auto refused = [&](const std::string& text, const std::string& expected) {
    try {
      parse_scene(text, "bad.yaml");
      ADD_FAILURE() << "accepted: " << expected;
    } catch (const std::exception& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(expected), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  };
  const std::string good = pendulum_text(0.2, 0.01, out);
  refused(test::replace_first(good, "joint: pivot,", "joint: motor,"), "'motor' is a ");
  refused(test::replace_first(test::model_file_text("cams/eccentric_roller.yaml", "output:"), "time:",
                              "parts: {rod: {mass: 1, center_of_mass: [0, 0], inertia: 1}}\nloads: {torsional_springs: "
                              "[{name: rub, coordinate: yf, bearing: {joint: guide, coefficient: 0.3, radius: "
                              "0.1}}]}\ntime:") +
              out,
          "a prismatic pair slides");
  refused(test::replace_first(good, "joint: pivot,", "joint: nowhere,"), "unknown joint 'nowhere'");
  refused(test::replace_first(good, "coefficient: ", "coefficient: -"), "coefficient");
  refused(test::replace_first(good, "radius: 0.01", "thrust_radius: 0.01"), "radius");
  refused(test::replace_first(good, "radius: 0.01", "radius: 0.01, thrust_radius: 0.02"), "none in the plane");
  refused(test::replace_first(good, "radius: 0.01", "radius: 0.01, moment_arm: 0.1"),
          "a pin in the plane carries no moment");
  refused(rotor_text(0.0, ", moment_arm: 0"), "a moment arm is a positive length");
  refused(test::replace_first(good, "bearing: {joint: pivot,", "bearing: {"), "names its `joint`");
}

}  // namespace
}  // namespace phiq
