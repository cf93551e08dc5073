// A torsional spring's rotor inertia J and dry friction f (phiq/applied_loads.hpp), and a linear spring's friction:
// the motor's extra torque against (J θ̈ + f sign θ̇) θ̇ / ω of the sprung angle, θ̇ and θ̈ by hand from each row's
// q, q̇, q̈ (a four-bar's rocker in natural coordinates, an expression; an RSSR's rocker hinge in space, a joint's
// angle), a linear spring's friction against f |L̇| / ω, and the fields the reader takes and refuses.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "phiq/applied_loads.hpp"
#include "phiq/inverse_dynamics.hpp"
#include "phiq/part_motion.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// The drivers' first effort at every row of the scene's sweep, and the rows' q, q̇, q̈.
struct RotorRows {
  std::vector<double> effort;
  test::Trace rows;
};
RotorRows rotor_rows(const Scene& s) {
  RotorRows out;
  test::Trace& tr = out.rows;
  EXPECT_EQ(test::sweep(*s.model, s.sweep, &tr), SolveStatus::kSuccess);
  Workspace ws(*s.model);
  std::vector<double> efforts;
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    ws.q = tr.q[k], ws.qd = tr.qd[k], ws.qdd = tr.qdd[k];
    std::string why;
    EXPECT_EQ(driver_efforts(*s.model, s.parts, s.loads, tr.t[k], ws, efforts, &why), SolveStatus::kSuccess) << why;
    out.effort.push_back(efforts.at(0));
  }
  return out;
}

// A measure's rate and acceleration at a row, by hand from q, q̇, q̈.
struct Jet {
  double rate = 0.0, accel = 0.0;
};
using Measure = std::function<Jet(const Eigen::VectorXd&, const Eigen::VectorXd&, const Eigen::VectorXd&)>;

// atan2(y, x)'s: θ̇ = (x ẏ − y ẋ)/r², θ̈ = (x ÿ − y ẍ)/r² − 2 (x ẋ + y ẏ)(x ẏ − y ẋ)/r⁴.
Jet atan2_jet(double x, double y, double xd, double yd, double xdd, double ydd) {
  const double r2 = x * x + y * y, w = x * yd - y * xd;
  return {w / r2, (x * ydd - y * xdd) / r2 - 2.0 * (x * xd + y * yd) * w / (r2 * r2)};
}

// The largest |Δτ − expected| over the rows and the largest |expected|: Δτ the motor's effort with the load
// `extra` less its effort without it, expected = (J ü + f sign u̇) u̇ / ω, u the loaded measure (an angle or a
// length), ω the driver's rate.
std::pair<double, double> extra_effort_error(const std::string& scene, const std::string& extra, double J, double f,
                                             double omega, const Measure& u) {
  const RotorRows plain = rotor_rows(parse_scene(scene, "plain.yaml"));
  const RotorRows loaded = rotor_rows(parse_scene(scene + extra, "loaded.yaml"));
  EXPECT_EQ(plain.effort.size(), loaded.effort.size());
  double worst = 0.0, scale = 0.0;
  for (std::size_t k = 0; k < plain.effort.size() && k < loaded.effort.size(); ++k) {
    EXPECT_EQ(plain.rows.q[k], loaded.rows.q[k]);  // (loads do not move the motion)
    const Jet m = u(plain.rows.q[k], plain.rows.qd[k], plain.rows.qdd[k]);
    const double expected = (J * m.accel + f * ((m.rate > 0.0) - (m.rate < 0.0))) * m.rate / omega;
    worst = std::max(worst, std::fabs(loaded.effort[k] - plain.effort[k] - expected));
    scale = std::max(scale, std::fabs(expected));
  }
  return {worst, scale};
}

// models/dynamics/fourbar_motor_torque.yaml (natural coordinates, its motor at 2π rad/s)
std::string fourbar_scene() {
  return test::model_file_text("dynamics/fourbar_motor_torque.yaml", "loads:") +
         "time: {start: 0, end: 1, steps: 100}\noutput: {velocities: true, accelerations: true}\n"
         "loads:\n  gravity: [0, -9.81]\n";
}

// models/spatial/rssr.yaml (Euler parameters, its motor at 1 rad/s) with massive links
std::string rssr_scene() {
  return test::model_file_text("spatial/rssr.yaml", "time:") +
         "parts:\n"
         "  crank: {mass: 0.8, center_of_mass: [a/2, 0, 0], inertia: [0.001, 0.8*a*a/12, 0.8*a*a/12]}\n"
         "  rocker: {mass: 1.1, center_of_mass: [0, b/2, 0], inertia: [1.1*b*b/12, 0.001, 1.1*b*b/12]}\n"
         "time: {start: 0, end: 6, steps: 60}\noutput: {velocities: true, accelerations: true}\n"
         "loads:\n  gravity: [0, -9.81, 0]\n";
}

TEST(RotorsAndFriction, ARotorAndADryFrictionOnTheRockerAddTheirMomentsAlongItsAngle) {
  // the four-bar's rocker angle, an expression (atan2 of its tip B about C = (1, 0))
  const Measure rocker = [](const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& a) {
    return atan2_jet(q[2] - 1.0, q[3], v[2], v[3], a[2], a[3]);
  };
  const std::string on_angle = "  torsional_springs: [{name: gearbox, angle: \"atan2(yB, xB - L1)\", ";
  for (const auto& [J, f] : {std::pair{0.35, 0.0}, std::pair{0.0, 2.5}, std::pair{0.35, 2.5}}) {
    SCOPED_TRACE(std::to_string(J) + " " + std::to_string(f));
    const auto [error, scale] = extra_effort_error(
        fourbar_scene(), on_angle + "inertia: " + std::to_string(J) + ", friction: " + std::to_string(f) + "}]\n", J, f,
        2.0 * M_PI, rocker);
    EXPECT_GT(scale, 1.0);
    EXPECT_LT(error, 1e-10 * scale);
  }
  // the RSSR's rocker hinge, a spatial joint's angle: the rocker turns about x, e = (cos φ/2, sin φ/2, 0, 0)
  const Measure hinge = [](const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& a) {
    const Jet half = atan2_jet(q[10], q[11], v[10], v[11], a[10], a[11]);
    return Jet{2.0 * half.rate, 2.0 * half.accel};
  };
  const auto [error, scale] =
      extra_effort_error(rssr_scene(), "  torsional_springs: [{joint: rocker_hinge, inertia: 0.8, friction: 0.3}]\n",
                         0.8, 0.3, 1.0, hinge);
  EXPECT_GT(scale, 0.1);
  EXPECT_LT(error, 1e-10 * scale);
}

TEST(RotorsAndFriction, ALinearSpringsFrictionResistsItsLengthsRate) {
  // a friction of 4 N between (0.3, 1.5) and the coupler's middle: 4 sign(L̇) along the line, L̇ = d · ḋ / L
  const Measure length = [](const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd&) {
    const double dx = 0.5 * (q[0] + q[2]) - 0.3, dy = 0.5 * (q[1] + q[3]) - 1.5;
    return Jet{(dx * 0.5 * (v[0] + v[2]) + dy * 0.5 * (v[1] + v[3])) / std::hypot(dx, dy), 0.0};
  };
  const auto [error, scale] = extra_effort_error(
      fourbar_scene(),
      "  springs: [{name: seal, between: [{point: [0.3, 1.5]}, {part: coupler, at: [L3/2, 0]}], friction: 4}]\n", 0.0,
      4.0, 2.0 * M_PI, length);
  EXPECT_GT(scale, 1.0);
  EXPECT_LT(error, 1e-10 * scale);
}

TEST(RotorsAndFriction, TheReaderTakesThemWithoutAStiffnessAndRefusesNegativeOnes) {
  const Scene s =
      parse_scene(fourbar_scene() +
                      "  torsional_springs: [{angle: \"atan2(yB, xB - L1)\", inertia: 0.2},\n"
                      "                      {coordinate: theta2, friction: 0.5}]\n"
                      "  springs: [{between: [{point: [0, 1]}, {part: rocker, at: [0.5, 0]}], damping: 2}]\n",
                  "rotor.yaml");
  ASSERT_TRUE(s.loads.applied);
  const AppliedLoads& a = *s.loads.applied;
  ASSERT_EQ(a.torsional_springs.size(), 2u);
  EXPECT_EQ(a.torsional_springs[0].inertia, 0.2);
  EXPECT_EQ(a.torsional_springs[0].stiffness, 0.0);
  EXPECT_EQ(a.torsional_springs[1].friction, 0.5);
  ASSERT_EQ(a.springs.size(), 1u);
  EXPECT_EQ(a.springs[0].damping, 2.0);
  auto error = [&](const std::string& loads) { return test::scene_error(fourbar_scene() + loads); };
  EXPECT_NE(
      error("  torsional_springs: [{coordinate: theta2, friction: -1}]\n").find("loads.torsional_springs[0].friction"),
      std::string::npos);
  EXPECT_NE(
      error("  torsional_springs: [{coordinate: theta2, inertia: -0.1}]\n").find("loads.torsional_springs[0].inertia"),
      std::string::npos);
  EXPECT_NE(error("  springs: [{between: [{point: [0, 1]}, {part: rocker, at: [0.5, 0]}], friction: -2}]\n")
                .find("loads.springs[0].friction"),
            std::string::npos);
  EXPECT_NE(error("  torsional_springs: [{coordinate: theta2, free_angle: 1}]\n").find("loads.torsional_springs[0]"),
            std::string::npos);  // nothing but a free angle: a stiffness is asked for
}

}  // namespace
}  // namespace phiq
