// nonfinite_force_source() (engine/src/solve/force_diagnosis.cpp): which part or load made Q not finite at a row,
// named with the reason; driver_efforts() returning kNonFinite with it (it returned NaN efforts as kSuccess); and a
// frame of points that can never have a direction refused when the scene is read.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "phiq/inverse_dynamics.hpp"
#include "phiq/phiq.hpp"
#include "fourbar_parts.hpp"
#include "sensitivity_support.hpp"

namespace phiq {
namespace {

// The four-bar with masses (models/dynamics/fourbar_motor_torque.yaml: crank O→A, coupler A→B, rocker C→B), its
// `loads` line replaced by `loads`.
Scene motor_torque(const std::string& loads) {
  std::string text = test::model_file_text("dynamics/fourbar_motor_torque.yaml");
  const std::size_t at = text.find("loads: {gravity: [0, -9.81]}");
  text.replace(at, std::string("loads: {gravity: [0, -9.81]}").size(), loads);
  return parse_scene(text, "fourbar.yaml");
}

std::string source_at(const Scene& s, const Eigen::VectorXd& q, double t) {
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(q.size());
  return nonfinite_force_source(s.parts, s.loads, s.model->num_coordinates(), q.data(), zero.data(), zero.data(), t);
}

TEST(ForceDiagnosis, FiniteForcesNameNothing) {
  const Scene s = motor_torque("loads: {gravity: [0, -9.81], forces: [{name: cut, part: coupler, force: [t, 1]}]}");
  EXPECT_EQ(source_at(s, s.model->initial_positions(), 0.3), "");
}

TEST(ForceDiagnosis, AFramesPointsThatMeetNameThePart) {
  const Scene s = motor_torque("loads: {gravity: [0, -9.81]}");
  Eigen::VectorXd q = s.model->initial_positions();
  // B on A: the coupler (origin A, x B) has no direction; the crank (O → A) and the rocker (C → B) still do
  q(s.model->find_coordinate("xB")) = q(s.model->find_coordinate("xA"));
  q(s.model->find_coordinate("yB")) = q(s.model->find_coordinate("yA"));
  EXPECT_EQ(source_at(s, q, 0.0), "part 'coupler': its frame's x has no direction: x's point is on its origin");
}

TEST(ForceDiagnosis, ASpatialFrameWhoseYMeetsItsXHasNoPlane) {
  // rssr_natural: A = [xA, yA, 0], B = [d, yB, zB]; the frame's y toward [d, yB, 1], which is B where zB = 1
  const Scene s =
      parse_scene(test::model_file_text("spatial/rssr_natural.yaml") +
                      "\nparts:\n  c: {frame: {origin: A, x: B, y: [d, yB, 1]}, mass: 1, center_of_mass: [0.1, 0, 0], "
                      "inertia: [0.01, 0.01, 0.01]}\nloads: {gravity: [0, 0, -9.81]}\n",
                  "rssr.yaml");
  Eigen::VectorXd q = s.model->initial_positions();
  EXPECT_EQ(source_at(s, q, 0.0), "");
  q(s.model->find_coordinate("zB")) = 1.0;
  EXPECT_EQ(source_at(s, q, 0.0), "part 'c': its frame's y is along its x (or zero): the frame has no plane");
}

TEST(ForceDiagnosis, ALoadsValueIsPrintedAndAnOverflowIsSaidToBeOne) {
  const Eigen::VectorXd q0 = motor_torque("loads: {}").model->initial_positions();
  EXPECT_EQ(source_at(motor_torque("loads: {forces: [{name: cut, part: coupler, force: [exp(1000*t), 2]}]}"), q0, 1.0),
            "force 'cut' on part 'coupler': its value is not finite: (inf, 2)");
  EXPECT_EQ(source_at(motor_torque("loads: {torques: [{name: brake, part: rocker, torque: sqrt(t - 1)}]}"), q0, 0.0),
            "torque 'brake' on part 'rocker': its value is not finite: NaN");
  // each value finite, its generalized force not: 1e308 N at a lever arm
  EXPECT_EQ(source_at(motor_torque("loads: {forces: [{name: cut, part: coupler, at: [1e10, 0], force: [0, 1e308]}]}"),
                      q0, 0.0),
            "force 'cut' on part 'coupler': its generalized force overflows doubles");
  EXPECT_EQ(source_at(motor_torque("loads: {gravity: [0, 1e308]}"), q0, 0.0),
            "part 'coupler': its weight and inertia forces overflow doubles (its mass, inertia or gravity too large)");
}

TEST(ForceDiagnosis, DriverEffortsSayWhichLoadIsNotFiniteInsteadOfReturningNaN) {
  const Scene s = motor_torque("loads: {gravity: [0, -9.81], torques: [{name: brake, part: rocker, torque: log(t)}]}");
  const Model& m = *s.model;
  Workspace ws(m);
  ws.q = m.initial_positions();
  ASSERT_EQ(solve_position(m, 0.0, NewtonOptions{}, ws), SolveStatus::kSuccess);
  ws.qd.setZero(m.num_coordinates()), ws.qdd.setZero(m.num_coordinates());
  std::vector<double> efforts{1.0};
  std::string why;
  EXPECT_EQ(driver_efforts(m, s.parts, s.loads, 0.0, ws, efforts, &why), SolveStatus::kNonFinite);
  EXPECT_EQ(why, "torque 'brake' on part 'rocker': its value is not finite: -inf");
  EXPECT_TRUE(efforts.empty());
  // at t = 1 the same torque is finite: efforts come back
  ASSERT_EQ(solve_position(m, 1.0, NewtonOptions{}, ws), SolveStatus::kSuccess);
  EXPECT_EQ(driver_efforts(m, s.parts, s.loads, 1.0, ws, efforts, &why), SolveStatus::kSuccess) << why;
  ASSERT_EQ(efforts.size(), 1u);
  EXPECT_TRUE(std::isfinite(efforts[0]));
}

TEST(ForceDiagnosis, AFrameThatCanNeverHaveADirectionIsRefusedWhenRead) {
  const std::string text = test::model_file_text("dynamics/fourbar_motor_torque.yaml");
  auto refused = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    t.replace(t.find(from), from.size(), to);
    try {
      parse_scene(t, "fourbar.yaml");
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refused("coupler: {frame: {origin: A, x: B}", "coupler: {frame: {origin: A, x: A}")
                .find("parts.coupler.frame.x: x is the origin's point: the frame has no direction"),
            std::string::npos);
  // the same point by its coordinates, and a constant origin's
  EXPECT_NE(refused("coupler: {frame: {origin: A, x: B}", "coupler: {frame: {origin: A, x: [xA, yA]}")
                .find("x is the origin's point"),
            std::string::npos);
  EXPECT_NE(refused("rocker: {frame: {origin: C, x: B}", "rocker: {frame: {origin: C, x: [L1, 0]}")
                .find("parts.rocker.frame.x: x is the origin's point"),
            std::string::npos);
  // two names of points that only meet at some row are read (the row names them)
  EXPECT_EQ(refused("coupler: {frame: {origin: A, x: B}", "coupler: {frame: {origin: A, x: C}"), "accepted");
}

}  // namespace
}  // namespace phiq
