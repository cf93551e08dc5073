// Driver efforts as sweep outputs (OutputPlan::efforts, the scene's `output: efforts`): each written row's torque
// and power are the inverse dynamics of that row (phiq/inverse_dynamics.hpp), asking for them leaves the motion's
// bits as they are, every thread count gives the same bits, and a singular row has none.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "phiq/effort_sensitivity.hpp"
#include "phiq/inverse_dynamics.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// The notes' four-bar in natural coordinates with three massive links under gravity.
std::string massive_fourbar(const std::string& output) {
  return test::model_file_text("seed/fourbar_natural.yaml", "output:") +
         "parts:\n"
         "  crank: {frame: {origin: O, x: A}, center_of_mass: [L2/2, 0], mass: 1.0, inertia: L2*L2/12}\n"
         "  coupler: {frame: {origin: A, x: B}, center_of_mass: [L3/2, 0], mass: 2.0, inertia: 2.0*L3*L3/12}\n"
         "  rocker: {frame: {origin: C, x: B}, center_of_mass: [L4/2, 0], mass: 1.5, inertia: 1.5*L4*L4/12}\n"
         "loads: {gravity: [0, -9.81]}\n"
         "output: " +
         output + "\n";
}

struct EffortRows {
  std::vector<double> t;
  std::vector<Eigen::VectorXd> q, qd, qdd;
  std::vector<std::vector<double>> efforts;
};

EffortRows sweep_efforts(const Scene& s, SweepOptions opt, SweepSummary* sum = nullptr) {
  EffortRows r;
  Workspace ws(*s.model);
  const std::size_t n = static_cast<std::size_t>(opt.efforts.size());
  const SolveStatus st = run_sweep(
      *s.model, opt, ws,
      [&](const StepView& v) {
        r.t.push_back(v.t), r.q.push_back(v.q);
        if (v.qd) r.qd.push_back(*v.qd);
        if (v.qdd) r.qdd.push_back(*v.qdd);
        r.efforts.emplace_back(v.efforts, v.efforts + n);
        return true;
      },
      sum);
  EXPECT_EQ(st, SolveStatus::kSuccess);
  return r;
}

// A transmission's effort (output.efforts naming it) is what it applies to its first member: a pinion of inertia J1
// driven at θ1 = 2t + 3t² meshes with a wheel of three times its radius (J2, braked by T = 5 + t against its turn):
// θ2 = −θ1/3, and the mesh's torque on the pinion is −(T + J2·2)/3 (Newton on the wheel alone), the motor's
// J1·6 − that; a rack of mass m driven by the same pinion (x = r θ) under a force F: the mesh pushes the rack with
// m r·6 − F, and the motor turns with J1·6 + r (m r·6 − F). Their powers: the motor's τ θ̇, the mesh's 0.
TEST(SweepEfforts, ATransmissionsEffortIsTheLoadItAppliesToItsFirstMember) {
  const double j1 = 0.002, j2 = 0.04, m = 3.0, r = 0.05;
  // the motor on the pinion's θ1: a scene with `parameters`, output fields `output` and `rest` (coordinates, mesh,
  // parts)
  const std::string pinion =
      "  pinion: {frame: {at: [0, 0], angle: th1}, mass: 1, center_of_mass: [0, 0], inertia: 0.002}\n";
  auto train = [&](const std::string& parameters, const std::string& output, const std::string& rest) {
    return "phiq: 1\nname: train\n" + parameters + "drivers:\n" +
           "  - {name: motor, coordinate: th1, law: {type: polynomial, coefficients: [0, 2, 3]}}\n"
           "time: {start: 0, end: 1, steps: 10}\n"
           "output: {velocities: true, accelerations: true, efforts: [motor, mesh], power: true" +
           output + "}\n" + rest;
  };
  // the gear pair, its wheel's radius and inertia as written
  auto gear_pair = [&](const std::string& radius, const std::string& inertia) {
    return "coordinates: {th1: 0, th2: 0}\n"
           "constraints: [{name: mesh, type: gear, between: [th1, th2], radii: [0.05, " +
           radius + "]}]\nparts:\n" + pinion +
           "  wheel: {frame: {at: [0.2, 0], angle: th2}, mass: 3, center_of_mass: [0, 0], inertia: " + inertia +
           "}\n"
           "loads: {torques: [{name: brake, part: wheel, torque: 5 + t}]}\n";
  };
  const Scene gears = parse_scene(train("", "", gear_pair("0.15", "0.04")), "gears.yaml");
  const EffortRows g = sweep_efforts(gears, gears.sweep);
  ASSERT_EQ(g.t.size(), 11u);
  for (std::size_t k = 0; k < g.t.size(); ++k) {
    const double t = g.t[k], mesh = -(5.0 + t + j2 * 2.0) / 3.0;
    EXPECT_NEAR(g.efforts[k][1], mesh, 1e-12) << t;
    EXPECT_NEAR(g.efforts[k][0], j1 * 6.0 - mesh, 1e-12) << t;
    EXPECT_NEAR(g.efforts[k][2], g.efforts[k][0] * (2.0 + 6.0 * t), 1e-11) << t;  // τ θ̇1
    EXPECT_EQ(g.efforts[k][3], 0.0) << t;                                         // λ Φt, Φt = 0
  }
  const Scene rack = parse_scene(
      train("", "",
            "coordinates: {th1: 0, x: 0}\n"
            "constraints: [{name: mesh, type: rack_pinion, rack: x, pinion: th1, radius: 0.05}]\nparts:\n" +
                pinion +
                "  rack: {frame: {at: [x, -0.05], angle: 0}, mass: 3, center_of_mass: [0, 0], inertia: 0.1}\n"
                "loads: {forces: [{name: cut, part: rack, force: [-10 - 4*t, 0]}]}\n"),
      "rack.yaml");
  const EffortRows p = sweep_efforts(rack, rack.sweep);
  ASSERT_EQ(p.t.size(), 11u);
  for (std::size_t k = 0; k < p.t.size(); ++k) {
    const double t = p.t[k], push = m * r * 6.0 - (-10.0 - 4.0 * t);
    EXPECT_NEAR(p.efforts[k][1], push, 1e-12) << t;
    EXPECT_NEAR(p.efforts[k][0], j1 * 6.0 + r * push, 1e-12) << t;
  }
  // ∂/∂p of the mesh's torque −6 J2/k² − T/k (k = R/r1 the ratio) through the sensitivities, exact: along J2,
  // −6/k²; along R, (12 J2/k³ + T/k²)/r1; the motor's the opposite, its power's θ̇1 times that
  const Scene sens = parse_scene(
      train("parameters: {R: 0.15, J: 0.04}\n", ", sensitivities: [J, R]", gear_pair("R", "J")), "gears_sens.yaml");
  const std::size_t base = static_cast<std::size_t>(sens.sweep.efforts.size());
  const EffortSensitivityLayout layout{2};
  Workspace ws(*sens.model);
  std::size_t rows = 0;
  SweepSummary ssum;
  ASSERT_EQ(run_sweep(
                *sens.model, sens.sweep, ws,
                [&](const StepView& v) {
                  const double t = v.t, k = 3.0, torque = 5.0 + t;
                  const double d_j = -6.0 / (k * k), d_r = (12.0 * j2 / (k * k * k) + torque / (k * k)) / r;
                  EXPECT_NEAR(v.efforts[base + layout.offset(0, 1)], d_j, 1e-9) << t;
                  EXPECT_NEAR(v.efforts[base + layout.offset(1, 1)], d_r, 1e-8) << t;
                  EXPECT_NEAR(v.efforts[base + layout.offset(1, 0)], -d_r, 1e-8) << t;
                  EXPECT_NEAR(v.efforts[base + layout.power_offset(2, 1, 0)], -d_r * (2.0 + 6.0 * t), 1e-7) << t;
                  ++rows;
                  return true;
                },
                &ssum),
            SolveStatus::kSuccess)
      << ssum.message;
  EXPECT_EQ(rows, 11u);
  // a constraint that is neither a driver nor a transmission still has none
  EXPECT_NE(error_of(train("", "",
                           "coordinates: {th1: 0, th2: 0}\n"
                           "constraints: [{name: mesh, type: equation, expr: th1 + 3*th2}]\nparts:\n" +
                               pinion))
                .find("'mesh' does not depend on time: no motor drives it, it has no effort (a driver has, and a "
                      "transmission"),
            std::string::npos);
}

TEST(SweepEfforts, EachRowsEffortAndPowerAreItsInverseDynamics) {
  const Scene s = parse_scene(massive_fourbar("{velocities: true, accelerations: true, efforts: all, power: true}"),
                              "fourbar.yaml");
  ASSERT_EQ(s.sweep.efforts.constraints.size(), 1u);
  SweepSummary sum;
  const EffortRows r = sweep_efforts(s, s.sweep, &sum);
  ASSERT_EQ(r.t.size(), 361u);
  EXPECT_EQ(sum.counters.effort_solves, 361);
  Workspace ws(*s.model);
  double worst = 0.0, worst_power = 0.0, scale = 0.0;
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    ws.q = r.q[k], ws.qd = r.qd[k], ws.qdd = r.qdd[k];
    std::vector<double> tau;
    std::string why;
    ASSERT_EQ(driver_efforts(*s.model, s.parts, s.loads, r.t[k], ws, tau, &why), SolveStatus::kSuccess) << why;
    worst = std::max(worst, std::fabs(r.efforts[k][0] - tau[0]));
    worst_power = std::max(worst_power, std::fabs(r.efforts[k][1] - r.efforts[k][0] * 1.0));  // θ̇ = 1 rad/s
    scale = std::max(scale, std::fabs(tau[0]));
  }
  EXPECT_GT(scale, 1.0);
  EXPECT_LT(worst, 1e-9 * scale);         // the row's factors are Φq at q, or at Newton's last iterate within tol
  EXPECT_LT(worst_power, 1e-12 * scale);  // P = λ Φt = τ θ̇ for a coordinate driven at a constant rate
}

TEST(SweepEfforts, AskingForEffortsLeavesTheMotionsBitsAndEveryThreadCountGivesTheSame) {
  const Scene with =
      parse_scene(massive_fourbar("{velocities: true, accelerations: true, efforts: [motor]}"), "fourbar.yaml");
  const Scene bare = parse_scene(massive_fourbar("{velocities: true, accelerations: true}"), "fourbar.yaml");
  const Scene only = parse_scene(massive_fourbar("{efforts: [motor], coordinates: [xB]}"), "fourbar.yaml");
  SweepOptions one = with.sweep;
  one.threads = 1;
  const EffortRows a = sweep_efforts(with, one);
  test::Trace b;
  ASSERT_EQ(test::sweep(*bare.model, bare.sweep, &b), SolveStatus::kSuccess);
  const EffortRows c = sweep_efforts(only, only.sweep);  // q̈ solved for the efforts, not delivered
  EXPECT_TRUE(c.qd.empty());
  EXPECT_TRUE(c.qdd.empty());
  SweepOptions two = with.sweep;
  two.threads = 2;
  SweepSummary sum2;
  const EffortRows d = sweep_efforts(with, two, &sum2);
  EXPECT_GT(sum2.parallel_chunks, 1);
  ASSERT_EQ(a.t.size(), b.t.size());
  ASSERT_EQ(a.t.size(), c.t.size());
  ASSERT_EQ(a.t.size(), d.t.size());
  for (std::size_t k = 0; k < a.t.size(); ++k) {
    EXPECT_EQ(a.q[k], b.q[k]) << k;
    EXPECT_EQ(a.q[k], c.q[k]) << k;
    EXPECT_EQ(a.q[k], d.q[k]) << k;
    EXPECT_EQ(a.efforts[k][0], c.efforts[k][0]) << k;
    EXPECT_EQ(a.efforts[k][0], d.efforts[k][0]) << k;
  }
}

TEST(SweepEfforts, ASingularRowHasNoEffort) {
  // The change-point four-bar lands on its two singular positions at steps 120 and 300.
  const Scene s = parse_scene(test::model_file_text("hard/change_point_exact.yaml", "output:") +
                                  "parts:\n  coupler: {mass: 1.0, inertia: 0.1, center_of_mass: [1, 0]}\n"
                                  "loads: {gravity: [0, -9.81]}\n"
                                  "output: {efforts: all}\n",
                              "change_point.yaml");
  const EffortRows r = sweep_efforts(s, s.sweep);
  ASSERT_EQ(r.t.size(), 361u);
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    if (k == 120 || k == 300)
      EXPECT_TRUE(std::isnan(r.efforts[k][0])) << k;
    else
      EXPECT_TRUE(std::isfinite(r.efforts[k][0])) << k;
  }
}

TEST(SweepEfforts, AnAppliedForceAloneGivesTheStaticTorque) {
  // Massless links, 10 N straight down at the crank's tip A: the motor holds the crank with τ = 10 N · x_A (the
  // coupler and the rocker, unloaded and massless, carry nothing).
  const Scene s = parse_scene(test::model_file_text("seed/fourbar_natural.yaml", "output:") +
                                  "parts:\n  crank: {frame: {origin: O, x: A}}\n"
                                  "loads: {forces: [{name: weight, part: crank, at: [L2, 0], force: [0, -10]}]}\n"
                                  "output: {efforts: all, coordinates: [xA]}\n",
                              "held_crank.yaml");
  const EffortRows r = sweep_efforts(s, s.sweep);
  ASSERT_EQ(r.t.size(), 361u);
  double worst = 0.0;
  for (std::size_t k = 0; k < r.t.size(); ++k) worst = std::max(worst, std::fabs(r.efforts[k][0] - 10.0 * r.q[k](0)));
  EXPECT_LT(worst, 1e-9);
}

TEST(SweepEfforts, ARedundantParallelogramNeedsTheTorqueOfItsFourBar) {
  // The fifth bar (crank3, massless) repeats what the parallelogram already imposes: the model is swept on its
  // independent rows, and the motor's torque is that of the four-bar without it, row by row.
  const std::string massive =
      "parts:\n  crank1: {mass: 1.0, inertia: 0.1, center_of_mass: [0.5, 0]}\n"
      "  crank2: {mass: 1.0, inertia: 0.1, center_of_mass: [0.5, 0]}\n"
      "  coupler: {mass: 2.0, inertia: 0.2, center_of_mass: [0.5, 0]}\n"
      "loads: {gravity: [0, -9.81]}\noutput: {efforts: all}\n";
  const std::string five = test::model_file_text("redundant/parallelogram_fifth_bar.yaml", "output:");
  std::string four;
  std::istringstream lines(five);
  for (std::string line; std::getline(lines, line);)
    if (line.find("crank3") == std::string::npos && line.find("x3:") == std::string::npos &&
        line.find("y3:") == std::string::npos && line.find("psi3:") == std::string::npos)
      four += line + "\n";
  std::vector<std::vector<double>> torque;
  for (const std::string& text : {five, four}) {
    const Scene s = parse_scene(text + massive, "parallelogram.yaml");
    SquareScene square;
    ASSERT_EQ(prepare_scene(*s.model, s.sweep.t_begin, s.sweep.assembly, &square), SolveStatus::kSuccess)
        << square.assembly.message;
    const Model& m = square.model(*s.model);
    Workspace ws(m);
    ws.q = square.start;
    std::vector<double> tau;
    const auto keep = [&](const StepView& v) {
      tau.push_back(v.efforts[0]);
      return true;
    };
    ASSERT_EQ(run_sweep(m, s.sweep, ws, keep, nullptr), SolveStatus::kSuccess);
    torque.push_back(tau);
  }
  EXPECT_FALSE(torque[0].empty());
  ASSERT_EQ(torque[0].size(), torque[1].size());
  double worst = 0.0, scale = 0.0;
  for (std::size_t k = 0; k < torque[0].size(); ++k)
    worst = std::max(worst, std::fabs(torque[0][k] - torque[1][k])), scale = std::max(scale, std::fabs(torque[1][k]));
  EXPECT_GT(scale, 1.0);
  EXPECT_LT(worst, 1e-9 * scale);
}

TEST(SweepEfforts, TheSceneRefusesEffortsItCannotGiveInOneLine) {
  const std::string fourbar = test::model_file_text("seed/fourbar_natural.yaml", "output:");
  EXPECT_NE(error_of(fourbar + "output: {efforts: all}\n").find("no part has mass and no load is applied"),
            std::string::npos)
      << error_of(fourbar + "output: {efforts: all}\n");
  const std::string massive = massive_fourbar("{efforts: ");
  EXPECT_NE(error_of(massive + "[pump]}").find("unknown driver 'pump'"), std::string::npos);
  EXPECT_NE(error_of(massive + "[crank]}").find("'crank' does not depend on time"), std::string::npos);
  EXPECT_NE(error_of(massive + "[motor, motor]}").find("driver listed twice"), std::string::npos);
  EXPECT_NE(error_of(massive + "some}").find("expected `all` or a list of drivers"), std::string::npos);
  EXPECT_NE(error_of(massive_fourbar("{power: true}")).find("list `efforts` too"), std::string::npos);
}

}  // namespace
}  // namespace phiq
