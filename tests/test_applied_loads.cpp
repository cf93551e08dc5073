// Applied loads (phiq/applied_loads.hpp, the scene's `loads`): a force on a crank-slider's slider against the
// motor torque's closed form; springs' and torsional springs' generalized forces against central differences of
// their potential energy, in natural, reference-point and spatial coordinates; virtual power with masses, gravity,
// a spring, a damper, a force and a torque in all four formulations of the four-bar (every model's own balance:
// test_power_balance.cpp); a force in part axes against
// the same force written in world axes; forces and torques of the rates (der()) against a closed form, a damper
// and the power balance, also as a family; laws of the stroke and of t against a closed form, and a law's table
// left; and the bad input the reader refuses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "phiq/applied_loads.hpp"
#include "phiq/inverse_dynamics.hpp"
#include "phiq/part_motion.hpp"
#include "phiq/phiq.hpp"
#include "fourbar_parts.hpp"
#include "power_balance_support.hpp"

namespace phiq {
namespace {

Eigen::VectorXd applied_q(const Scene& s, const Eigen::VectorXd& q, double t) {
  Eigen::VectorXd Q = Eigen::VectorXd::Zero(s.model->num_coordinates());
  add_applied_forces(*s.loads.applied, q.data(), nullptr, nullptr, t, Q);
  return Q;
}

// ∫₀^δ of a spring's elastic force: ½ k δ², or its law's integral by 5-point Gauss–Legendre (exact for the
// polynomials of degree ≤ 9 the tests' laws are).
double elastic_energy(double stiffness, const MotionLaw& law, double d) {
  if (!law.has_value()) return 0.5 * stiffness * d * d;
  const double x[5] = {0.0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640, 0.9061798459386640};
  const double w[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665, 0.2369268850561891,
                       0.2369268850561891};
  double v = 0.0;
  for (int k = 0; k < 5; ++k) v += w[k] * law.evaluate(0.5 * d * (1.0 + x[k])).f;
  return 0.5 * d * v;
}

// The potential energy of the scene's springs at (q, t): ½ k (L − L0)² + preload · L, ½ k (θ − θ0)² (or their
// laws' integrals).
double spring_energy(const AppliedLoads& loads, const Eigen::VectorXd& q, double t) {
  double v = 0.0;
  for (const LinearSpring& s : loads.springs) {
    const double l =
        kin3::norm(part_pose(s.b.frame, q.data(), t).apply(s.b.at) - part_pose(s.a.frame, q.data(), t).apply(s.a.at));
    v += elastic_energy(s.stiffness, s.law, l - s.free_length) + s.preload * l;
  }
  for (const TorsionalSpring& s : loads.torsional_springs) {
    const double a =
        s.angle ? s.angle->value(q.data(), t) - s.free_angle
                : std::remainder(evaluate_joint(*s.joint, q.data(), nullptr, nullptr).value - s.free_angle, 2 * M_PI);
    v += elastic_energy(s.stiffness, s.law, a);
  }
  return v;
}

// The seed crank-slider (crank 0.3, rod 1, θ = 2t) with a massless slider carrying `loads` (YAML entries of the
// `loads` map), swept: its
// motor's effort against the closed form τ = −F ∂xB/∂θ (the motor's power balances the force's, τ θ̇ + F ẋB = 0),
// F(t, xB, ẋB) the force along x, xB = r cos θ + √(L² − r² sin² θ). The largest difference and the largest |τ|.
struct SliderBalance {
  double worst = 0.0, peak = 0.0;
};
SliderBalance slider_force_balance(const std::string& loads, const std::function<double(double, double, double)>& f) {
  SliderBalance b;
  const Scene s = parse_scene(
      test::model_file_text("seed/crank_slider_mixed.yaml") + "\nparts:\n  slider: {frame: {at: B}}\nloads:\n" + loads,
      "crank_slider.yaml");
  const Model& m = *s.model;
  test::Trace tr;
  EXPECT_EQ(test::sweep(m, s.sweep, &tr), SolveStatus::kSuccess);
  Workspace ws(m);
  const Index theta = m.find_coordinate("theta2");
  const double r = 0.3, L = 1.0;
  std::vector<double> efforts;
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    ws.q = tr.q[k], ws.qd = tr.qd[k], ws.qdd = tr.qdd[k];
    std::string why;
    if (driver_efforts(m, s.parts, s.loads, tr.t[k], ws, efforts, &why) != SolveStatus::kSuccess) {
      ADD_FAILURE() << why;
      return {INFINITY, 0.0};
    }
    const double th = tr.q[k](theta), sn = std::sin(th), cs = std::cos(th);
    const double root = std::sqrt(L * L - r * r * sn * sn);
    const double xb = r * cs + root, dxb = -r * sn - r * r * sn * cs / root;
    const double exact = -f(tr.t[k], xb, 2.0 * dxb) * dxb;
    b.worst = std::max(b.worst, std::fabs(efforts.at(0) - exact));
    b.peak = std::max(b.peak, std::fabs(exact));
  }
  return b;
}

TEST(AppliedLoads, TheCrankSlidersMotorBalancesAForceOnTheSlider) {
  // F = −40 − 10 xB + 5 sin t on the slider along x, no masses
  const SliderBalance b =
      slider_force_balance("  forces:\n    - {name: push, part: slider, force: [-40 - 10*xB + 5*sin(t), 0]}\n",
                           [](double t, double xb, double) { return -40.0 - 10.0 * xb + 5.0 * std::sin(t); });
  EXPECT_GT(b.peak, 10.0);  // newton-metres: the check is not of zeros
  EXPECT_LT(b.worst, 1e-9 * b.peak);
}

// Q of the springs against −∂V/∂q_k by central differences, every coordinate of the model, at its rough placement.
void expect_spring_forces_are_the_energys_gradient(const std::string& rel, const std::string& loads) {
  Scene s = parse_scene(test::model_file_text(rel) + "\nloads:\n" + loads, rel);
  ASSERT_TRUE(s.loads.applied);
  const AppliedLoads& a = *s.loads.applied;
  const Eigen::VectorXd q = s.model->initial_positions();
  const Eigen::VectorXd Q = applied_q(s, q, 0.0);
  const double h = 1e-6;
  double worst = 0.0, scale = 0.0;
  for (Index k = 0; k < q.size(); ++k) {
    Eigen::VectorXd up = q, down = q;
    up(k) += h, down(k) -= h;
    const double fd = -(spring_energy(a, up, 0.0) - spring_energy(a, down, 0.0)) / (2 * h);
    worst = std::max(worst, std::fabs(Q(k) - fd));
    scale = std::max(scale, std::fabs(fd));
  }
  EXPECT_GT(scale, 1.0) << rel;  // newtons: the springs are loaded at this placement
  EXPECT_LT(worst, 1e-7 * scale) << rel;
}

TEST(AppliedLoads, SpringForcesAreTheirEnergysGradientInEveryCoordinateFamily) {
  expect_spring_forces_are_the_energys_gradient(
      "seed/fourbar_reference_point.yaml",
      "  springs:\n"
      "    - {name: s1, between: [{part: crank, at: [0.1, 0.02]}, {part: rocker, at: [-0.2, 0.05]}],\n"
      "       stiffness: 300, free_length: 0.5, preload: 7}\n"
      "    - {name: s2, between: [{point: [0.5, 1.5]}, {part: coupler, at: [0.3, 0]}], stiffness: 80,\n"
      "       free_length: 0.2}\n"
      "  torsional_springs:\n"
      "    - {name: t1, angle: psi3 - psi2, stiffness: 20, free_angle: 0.3}\n"
      "    - {name: t2, coordinate: psi4, stiffness: 5, free_angle: -0.5}\n");
  expect_spring_forces_are_the_energys_gradient(
      "seed/fourbar_natural.yaml",
      "  springs:\n"
      "    - {name: s1, between: [{part: crank, at: [0.2, 0.05]}, {part: rocker, at: [0.3, 0.1]}],\n"
      "       stiffness: 300, free_length: 0.5, preload: -3}\n"
      "  torsional_springs:\n"
      "    - {name: t1, angle: \"atan2(yB - yA, xB - xA) - theta2\", stiffness: 20, free_angle: 0.3}\n"
      "    - {name: t2, coordinate: theta2, stiffness: 5}\n"
      "parts:\n"
      "  crank: {frame: {origin: O, x: A}}\n"
      "  rocker: {frame: {origin: C, x: B}}\n");
  expect_spring_forces_are_the_energys_gradient(
      "spatial/rssr.yaml",
      "  springs:\n"
      "    - {name: s1, between: [{part: crank, at: [a, 0.05, 0.02]}, {part: rocker, at: [0, b, 0.1]}],\n"
      "       stiffness: 500, free_length: 0.4}\n"
      "    - {name: s2, between: [{part: rocker, at: [0.1, 0.2, 0]}, {point: [0.3, 0.3, 0.3]}], stiffness: 50,\n"
      "       free_length: 0.1}\n"
      "  torsional_springs:\n"
      "    - {name: t1, joint: rocker_hinge, stiffness: 20, free_angle: 0.3, damping: 2}\n"
      "    - {name: t2, joint: crank_hinge, stiffness: 7, free_angle: -2.5}\n");
  // springs of laws of their deflection: a stiffening strut (k δ + k3 δ³, no free length), a table through a
  // quadratic, torsional ones on a relative angle and on a spatial hinge
  expect_spring_forces_are_the_energys_gradient(
      "seed/fourbar_reference_point.yaml",
      "  springs:\n"
      "    - {name: s1, between: [{part: crank, at: [0.1, 0.02]}, {part: rocker, at: [-0.2, 0.05]}],\n"
      "       law: {type: polynomial, coefficients: [0, 300, 0, 900]}, preload: 7}\n"
      "    - {name: s2, between: [{point: [0.5, 1.5]}, {part: coupler, at: [0.3, 0]}], free_length: 0.2,\n"
      "       law: {type: table, t: [-1, 0, 1, 2, 3], values: [-60, 0, 100, 240, 420]}}\n"
      "  torsional_springs:\n"
      "    - {name: t1, angle: psi3 - psi2, law: {type: polynomial, coefficients: [2, 20, 0, 8]}, free_angle: 0.3}\n");
  expect_spring_forces_are_the_energys_gradient(
      "spatial/rssr.yaml",
      "  springs:\n"
      "    - {name: s1, between: [{part: crank, at: [a, 0.05, 0.02]}, {part: rocker, at: [0, b, 0.1]}],\n"
      "       law: {type: harmonic, amplitude: 90, frequency: 2}, free_length: 0.4}\n"
      "  torsional_springs:\n"
      "    - {name: t1, joint: rocker_hinge, law: {type: polynomial, coefficients: [0, 20, 5]}, free_angle: 0.3}\n");
}

// Over a scene's sweep, whose driver turns at 1 rad/s: the largest |τ θ̇ − (d/dt kinetic energy + d/dt gravity's
// potential − the applied loads' power)|, the largest |τ| and the largest |applied power|.
struct LoadedPowerBalance {
  double balance = 0.0, scale = 0.0, loads_power = 0.0;
};
LoadedPowerBalance loaded_power_balance(const Scene& s) {
  LoadedPowerBalance b;
  const Model& m = *s.model;
  test::Trace tr;
  EXPECT_EQ(test::sweep(m, s.sweep, &tr), SolveStatus::kSuccess);
  Workspace ws(m);
  std::vector<double> efforts;
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    const double t = tr.t[k];
    ws.q = tr.q[k], ws.qd = tr.qd[k], ws.qdd = tr.qdd[k];
    std::string why;
    if (driver_efforts(m, s.parts, s.loads, t, ws, efforts, &why) != SolveStatus::kSuccess) {
      ADD_FAILURE() << why;
      return {INFINITY, 0.0, 0.0};
    }
    double energy_rate = 0.0;
    for (const Part& p : s.parts) {
      const PartMotion pm = part_motion(p.frame, ws.q.data(), ws.qd.data(), ws.qdd.data(), t);
      const auto [v, a] = pm.point(p.mass.center);
      energy_rate += p.mass.mass * kin3::dot(v, a) + test::rotational_energy_rate(p, pm) -
                     p.mass.mass * kin3::dot(s.loads.gravity, v);
    }
    const double power = applied_power(*s.loads.applied, ws.q.data(), ws.qd.data(), ws.qdd.data(), t);
    b.balance = std::max(b.balance, std::fabs(efforts[0] * 1.0 - (energy_rate - power)));
    b.scale = std::max(b.scale, std::fabs(efforts[0]));
    b.loads_power = std::max(b.loads_power, std::fabs(power));
  }
  return b;
}

TEST(AppliedLoads, DriverPowerBalancesEnergyAndTheLoadsPowerInEveryFormulation) {
  // Σ effort × driven rate = d(kinetic)/dt + d(gravity's potential)/dt − power of the applied loads, every row
  const std::string loads =
      "loads:\n"
      "  gravity: [0, -9.81]\n"
      "  forces:\n"
      "    - {name: wind, part: coupler, at: [0.1, 0.05], force: [3 + 2*sin(t), -5*cos(t)], axes: part}\n"
      "  torques:\n"
      "    - {name: brake, part: rocker, torque: -2 - 0.5*sin(t)}\n"
      "  springs:\n"
      "    - {name: spring, between: [{part: crank, at: [0.05, 0.02]}, {part: rocker, at: [0.2, 0.05]}],\n"
      "       stiffness: 300, free_length: 0.6, preload: 4}\n"
      "    - {name: damper, between: [{point: [0.5, 1.6]}, {part: coupler, at: [0.2, 0]}], stiffness: 0,\n"
      "       free_length: 0, damping: 25}\n";
  for (const std::string form : {"relative", "natural", "reference_point", "mixed"}) {
    Scene s = parse_scene(
        test::model_file_text("seed/fourbar_" + form + ".yaml") + "\nparts:\n" + test::fourbar_parts(form) + loads,
        form);
    const LoadedPowerBalance b = loaded_power_balance(s);
    const double balance = b.balance, scale = b.scale, loads_power = b.loads_power;
    EXPECT_GT(loads_power, 1.0) << form;  // watts: the loads take part in the balance
    EXPECT_LT(balance, 1e-9 * scale) << form;
  }
}

TEST(AppliedLoads, DriverPowerBalancesInSpaceWithAJointSpringAndLoadsInPartAxes) {
  Scene s = parse_scene(
      test::model_file_text("spatial/rssr.yaml") +
          "\nparts:\n"
          "  crank: {mass: 1.0, center_of_mass: [0.1, 0, 0], inertia: [0.01, 0.02, 0.025]}\n"
          "  rocker: {mass: 2.0, center_of_mass: [0, 0.25, 0], inertia: [0.05, 0.01, 0.05]}\n"
          "loads:\n"
          "  gravity: [0, 0, -9.81]\n"
          "  forces: [{part: crank, at: [a, 0, 0], force: [5, 2*sin(t), 3], axes: part}]\n"
          "  torques: [{part: rocker, torque: [1 + 0.5*cos(t), 0.5, -0.2], axes: part}]\n"
          "  torsional_springs: [{joint: rocker_hinge, stiffness: 15, free_angle: 1.2, damping: 3, friction: 0.4,\n"
          "                       inertia: 0.3}]\n",
      "rssr.yaml");
  const LoadedPowerBalance b = loaded_power_balance(s);
  const double balance = b.balance, scale = b.scale, loads_power = b.loads_power;
  EXPECT_GT(loads_power, 1.0);
  EXPECT_LT(balance, 1e-9 * scale);
}

TEST(AppliedLoads, AForceInPartAxesIsTheSameForceTurnedIntoWorldAxes) {
  // (30, 40) N in the crank's axes at a point of it, and the same written in world axes from the crank's angle
  struct Form {
    std::string rel, parts, world;
  };
  const Form forms[] = {
      {"seed/fourbar_reference_point.yaml", "", "[30*cos(psi2) - 40*sin(psi2), 30*sin(psi2) + 40*cos(psi2)]"},
      {"seed/fourbar_natural.yaml", "parts:\n  crank: {frame: {origin: O, x: A}}\n",
       "[(30*xA - 40*yA)/sqrt(xA^2 + yA^2), (30*yA + 40*xA)/sqrt(xA^2 + yA^2)]"}};
  for (const Form& f : forms) {
    auto with_force = [&](const std::string& force, const std::string& axes) {
      return parse_scene(test::model_file_text(f.rel) + "\n" + f.parts +
                             "loads:\n  forces:\n    - {part: crank, at: [0.1, 0.02], " + "force: " + force +
                             ", axes: " + axes + "}\n",
                         f.rel);
    };
    const Scene in_part = with_force("[30, 40]", "part"), in_world = with_force(f.world, "world");
    Eigen::VectorXd q = in_part.model->initial_positions();
    for (int trial = 0; trial < 3; ++trial) {
      for (Index k = 0; k < q.size(); ++k) q(k) += 0.1 * std::sin(1.0 + k + 7.0 * trial);  // a generic placement
      const Eigen::VectorXd a = applied_q(in_part, q, 0.0), b = applied_q(in_world, q, 0.0);
      EXPECT_GT(a.norm(), 1.0) << f.rel;
      EXPECT_LT((a - b).norm(), 1e-12 * a.norm()) << f.rel << "\n" << a.transpose() << "\n" << b.transpose();
    }
  }
}

TEST(AppliedLoads, ARateDependentForceOnTheSliderFollowsItsClosedForm) {
  // F = −7 ẋB − 3 ẋB |ẋB| (der(xB))
  const SliderBalance b = slider_force_balance(
      "  forces:\n    - {name: drag, part: slider, force: [-7*der(xB) - 3*der(xB)*abs(der(xB)), 0]}\n",
      [](double, double, double v) { return -7.0 * v - 3.0 * v * std::fabs(v); });
  EXPECT_GT(b.peak, 1.0);
  EXPECT_LT(b.worst, 1e-9 * b.peak);
}

TEST(AppliedLoads, ACoulombFrictionOnTheSliderFollowsItsClosedForm) {
  // F = −5 sign(ẋB): the motor carries 5 |∂xB/∂θ| (0 at the dead points, where the slider rests)
  const SliderBalance b =
      slider_force_balance("  forces:\n    - {name: friction, part: slider, force: [-5*sign(der(xB)), 0]}\n",
                           [](double, double, double v) { return -5.0 * ((v > 0) - (v < 0)); });
  EXPECT_GT(b.peak, 1.0);
  EXPECT_LT(b.worst, 1e-9 * b.peak);
}

TEST(AppliedLoads, AForceOfARateAlongItsLineIsADamper) {
  // −c der(xB) on the slider, on y = 0, is a damper from a world point on that line: the same efforts, with the
  // links' masses and gravity
  const std::string scene =
      test::model_file_text("seed/crank_slider_mixed.yaml") +
      "\nparts:\n"
      "  crank: {frame: {origin: O, x: A}, center_of_mass: [0.15, 0], mass: 0.5, inertia: 0.004}\n"
      "  rod: {frame: {origin: A, x: B}, center_of_mass: [0.5, 0], mass: 1.2, inertia: 0.1}\n"
      "  slider: {frame: {at: B}, mass: 0.8, center_of_mass: [0, 0], inertia: 0.001}\n"
      "loads:\n  gravity: [0, -9.81]\n";
  auto efforts = [](const std::string& text) {
    const Scene s = parse_scene(text, "crank_slider.yaml");
    test::Trace tr;
    EXPECT_EQ(test::sweep(*s.model, s.sweep, &tr), SolveStatus::kSuccess);
    Workspace ws(*s.model);
    std::vector<double> out, row;
    for (std::size_t k = 0; k < tr.t.size(); ++k) {
      ws.q = tr.q[k], ws.qd = tr.qd[k], ws.qdd = tr.qdd[k];
      EXPECT_EQ(driver_efforts(*s.model, s.parts, s.loads, tr.t[k], ws, row), SolveStatus::kSuccess);
      out.push_back(row.at(0));
    }
    return out;
  };
  const std::vector<double> force = efforts(scene + "  forces: [{name: drag, part: slider, force: [-7*der(xB), 0]}]\n");
  const std::vector<double> damper =
      efforts(scene +
              "  springs: [{name: drag, between: [{point: [-5, 0]}, {part: slider}], stiffness: 0, "
              "free_length: 0, damping: 7}]\n");
  const std::vector<double> none = efforts(scene);
  ASSERT_EQ(force.size(), damper.size());
  ASSERT_GT(force.size(), 100u);
  double worst = 0.0, peak = 0.0, effect = 0.0;
  for (std::size_t k = 0; k < force.size(); ++k) {
    worst = std::max(worst, std::fabs(force[k] - damper[k]));
    peak = std::max(peak, std::fabs(damper[k]));
    effect = std::max(effect, std::fabs(damper[k] - none[k]));
  }
  EXPECT_GT(effect, 0.5);  // the damper's share of the torque, N·m
  EXPECT_LT(worst, 1e-12 * peak);
}

TEST(AppliedLoads, DriverPowerBalancesWithForcesAndTorquesOfRatesInAFamily) {
  // forces and a torque reading q̇ (der()), written as a family and written out: the same efforts, and the power
  // balance with the loads' power F · v + M ω
  const std::string base = test::model_file_text("seed/fourbar_natural.yaml") + "\nparts:\n" +
                           test::fourbar_parts("natural") + "loads:\n  gravity: [0, -9.81]\n";
  const std::string torque = "  torques: [{name: brake, part: rocker, torque: \"-2*der(atan2(yB, xB - L1))\"}]\n";
  const std::string family =
      "  forces:\n"
      "    - for i in 0..1:\n"
      "        - {name: \"drag{i}\", part: coupler, at: [0.3*i, 0], force: [-4*(1 + i)*der(xA), "
      "-3*der(yB)*abs(der(yB))]}\n";
  const std::string written =
      "  forces:\n"
      "    - {name: drag0, part: coupler, at: [0, 0], force: [-4*der(xA), -3*der(yB)*abs(der(yB))]}\n"
      "    - {name: drag1, part: coupler, at: [0.3, 0], force: [-8*der(xA), -3*der(yB)*abs(der(yB))]}\n";
  const Scene a = parse_scene(base + torque + family, "fourbar.yaml");
  const Scene b = parse_scene(base + torque + written, "fourbar.yaml");
  const LoadedPowerBalance pa = loaded_power_balance(a), pb = loaded_power_balance(b);
  EXPECT_GT(pa.loads_power, 1.0);  // watts: the loads take part in the balance
  EXPECT_LT(pa.balance, 1e-9 * pa.scale);
  EXPECT_NEAR(pa.scale, pb.scale, 1e-12 * pb.scale);
  EXPECT_NEAR(pa.loads_power, pb.loads_power, 1e-12 * pb.loads_power);
}

TEST(AppliedLoads, ALawOfTheStrokeOnTheSliderFollowsItsClosedForm) {
  // a table of F(xB) through a cubic, 60 − 20 xB + 15 xB³ (the spline is exact for cubics), and a harmonic law of t
  const SliderBalance b = slider_force_balance(
      "  forces:\n    - {name: gas, part: slider, force: [{law: {type: table, t: [0.6, 0.8, 1.0, 1.2, 1.4], "
      "values: [51.24, 51.68, 55.0, 61.92, 73.16]}, of: xB}, 0]}\n"
      "    - {name: shake, part: slider, force: [{law: {type: harmonic, amplitude: 4, frequency: 3, phase: 0.5}}, "
      "0]}\n",
      [](double t, double xb, double) {
        return 60.0 - 20.0 * xb + 15.0 * xb * xb * xb + 4.0 * std::sin(3.0 * t + 0.5);
      });
  EXPECT_GT(b.peak, 10.0);
  EXPECT_LT(b.worst, 1e-9 * b.peak);
}

TEST(AppliedLoads, ALineActuatorOnTheSliderFollowsItsClosedForm) {
  // a cylinder from a world point on the slider's line, its tension an expression of t and the rate (and a law of
  // the stroke in a second one, with a linear spring): the slider feels −T along x
  const SliderBalance b = slider_force_balance(
      "  springs:\n"
      "    - {name: cylinder, between: [{point: [-5, 0]}, {part: slider}], tension: 30 + 10*sin(t) + 2*der(xB)}\n"
      "    - {name: strut, between: [{point: [-5, 0]}, {part: slider}], stiffness: 20, free_length: 5.5,\n"
      "       tension: {law: {type: polynomial, coefficients: [0, 0, 8]}, of: xB}}\n",
      [](double t, double xb, double v) {
        return -(30.0 + 10.0 * std::sin(t) + 2.0 * v) - (20.0 * (xb + 5.0 - 5.5) + 8.0 * xb * xb);
      });
  EXPECT_GT(b.peak, 10.0);
  EXPECT_LT(b.worst, 1e-9 * b.peak);
}

TEST(AppliedLoads, ALawsArgumentOutsideItsTableStopsTheEffortsNamingTheLoad) {
  Scene s = parse_scene(test::model_file_text("seed/crank_slider_mixed.yaml", "output:") +
                            "\nparts:\n  slider: {frame: {at: B}, mass: 1, center_of_mass: [0, 0], inertia: 0.01}\n"
                            "loads:\n  forces:\n    - {name: gas, part: slider, force: [{law: {type: table, "
                            "t: [0.8, 1.0, 1.2], values: [5, 6, 8]}, of: xB}, 0]}\n"
                            "output: {efforts: all}\n",
                        "crank_slider.yaml");
  const Model& m = *s.model;  // xB runs over [0.7, 1.3]: outside the table from the first row
  Workspace ws(m);
  ws.q = m.initial_positions();
  SweepSummary sum;
  EXPECT_EQ(run_sweep(
                m, s.sweep, ws, [](const StepView&) { return true; }, &sum),
            SolveStatus::kNonFinite);
  EXPECT_HAS(sum.message,
             "force 'gas' on part 'slider': its law's argument 'xB' is 1.3, outside the table's [0.8, 1.2]");
}

TEST(AppliedLoads, BadLoadsAreRefusedInOneLineNamingTheField) {
  const std::string base = test::model_file_text("seed/fourbar_reference_point.yaml") + "\nloads:\n";
  auto error = [&](const std::string& loads) { return test::scene_error(base + loads); };
  std::string m = error("  forces:\n    - {part: wheel, force: [1, 0]}\n");
  EXPECT_HAS(m, "loads.forces[0].part: unknown part 'wheel'");
  m = error("  torsional_springs:\n    - {coordinate: psi9, stiffness: 1}\n");
  EXPECT_HAS(m, "loads.torsional_springs[0].coordinate: unknown coordinate 'psi9'");
  m = error("  forces:\n    - {part: crank, force: [1, 0, 0]}\n");
  EXPECT_HAS(m, "loads.forces[0].force: force is [x, y]");
  m = error("  forces:\n    - {part: crank, at: [0.1, 0, 0], force: [1, 0]}\n");
  EXPECT_HAS(m, "loads.forces[0].at: at is [x, y]");
  m = error("  forces:\n    - {part: crank, force: [1, 0], where: 2}\n");
  EXPECT_HAS(m, "loads.forces[0].where: unknown field 'where'");
  m = error("  forces:\n    - {part: crank, force: [1, 0], axes: body}\n");
  EXPECT_HAS(m, "loads.forces[0].axes: axes is world or part, got 'body'");
  m = error("  torques:\n    - {part: crank, torque: [0, 0, 1]}\n");
  EXPECT_HAS(m, "loads.torques[0].torque: a torque in the plane is one number, expression or law");
  m = error(
      "  springs:\n    - {between: [{part: crank}, {point: [1, 0]}], stiffness: 10, free_length: 1, damping: -2}\n");
  EXPECT_HAS(m, "loads.springs[0].damping: must not be negative, got -2");
  m = error(
      "  springs:\n    - {between: [{part: crank, at: [0.1, 0]}, {part: crank, at: [0.1, 0]}], stiffness: 10, "
      "free_length: 1}\n");
  EXPECT_HAS(m, "loads.springs[0].between: the spring's two ends are the same point");
  m = error(
      "  springs:\n    - {between: [{part: crank, point: [1, 0]}, {part: rocker}], stiffness: 1, free_length: 1}\n");
  EXPECT_HAS(m, "loads.springs[0].between[0].point: an end is {part: P, at: [..]} or a world {point: [..]}");
  m = error("  torsional_springs:\n    - {angle: psi3 - psi2 + foo, stiffness: 1}\n");
  EXPECT_HAS(m, "loads.torsional_springs[0].angle:");
  EXPECT_HAS(m, "foo");
  m = error(
      "  springs:\n    - {between: [{part: crank}, {point: [1, 0]}], stiffness: 10, free_length: 1, "
      "law: {type: linear, initial: 0, rate: 1}}\n");
  EXPECT_HAS(m, "loads.springs[0].law: a spring has a stiffness or a law of its deflection, not both");
  m = error("  springs:\n    - {between: [{part: crank}, {point: [1, 0]}], free_length: 1}\n");
  EXPECT_HAS(m, "loads.springs[0]: missing field 'stiffness'");  // (a damper, a friction or an actuator needs none)
  m = error("  torsional_springs:\n    - {coordinate: psi2, law: {type: table, t: [0], values: [0]}}\n");
  EXPECT_HAS(m, "loads.torsional_springs[0].law.t: a table needs at least 2 points");
  m = error("  forces:\n    - {part: crank, force: [{law: {type: linear, initial: 0, rate: 1}, at: t}, 0]}\n");
  EXPECT_HAS(m, "loads.forces[0].force[0].at: unknown field 'at' (allowed: law, of)");
  m = error("  torques:\n    - {part: crank, torque: {law: {type: cubic}}}\n");
  EXPECT_HAS(m, "loads.torques[0].torque.law.type: unknown law type 'cubic'");
  m = error("  torsional_springs:\n    - {angle: psi3 - der(psi2), stiffness: 1}\n");
  EXPECT_HAS(m, "loads.torsional_springs[0].angle: expression \"psi3 - der(psi2)\": der() reads velocities");
  m = error("  forces:\n    - {part: crank, force: [der(der(psi2)), 0]}\n");
  EXPECT_HAS(m, "loads.forces[0].force[0]: expression \"der(der(psi2))\": der() of a rate: an acceleration");
  m = error("  torques:\n    - {name: a, part: crank, torque: 1}\n    - {name: a, part: rocker, torque: 1}\n");
  EXPECT_HAS(m, "loads.torques[1].name: duplicate load name 'a'");
  m = error("  torsional_springs:\n    - {joint: O, stiffness: 1}\n");
  EXPECT_HAS(m, "loads.torsional_springs[0].joint: a joint's angle is a spatial joint's");
  m = error("  torsional_springs:\n    - {coordinate: psi2, angle: psi2, stiffness: 1}\n");
  EXPECT_HAS(m, "loads.torsional_springs[0]: a torsional spring acts on one of");
  const std::string rssr = test::model_file_text("spatial/rssr.yaml") + "\nloads:\n  torsional_springs:\n";
  m = test::scene_error(rssr + "    - {joint: hinge, stiffness: 1}\n");
  EXPECT_HAS(m, "loads.torsional_springs[0].joint: unknown joint 'hinge'");
  m = test::scene_error(rssr + "    - {joint: coupler, stiffness: 1}\n");
  EXPECT_HAS(m, "loads.torsional_springs[0].joint: unknown joint 'coupler'");  // a distance: no joint
  m = test::scene_error(test::model_file_text("spatial/rssr.yaml") +
                        "\nloads:\n  torques: [{part: crank, torque: 1}]\n");
  EXPECT_HAS(m, "loads.torques[0].torque: torque is [x, y, z]");
}

}  // namespace
}  // namespace phiq
