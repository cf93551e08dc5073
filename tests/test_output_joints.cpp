// Joint measures and body orientations as outputs (phiq/output_joints.hpp): against the drivers' laws and closed
// forms, the angles unwrapped over turns on every thread count and with rows left unwritten, and the joint angle's
// rate and acceleration against the body's angular velocity and acceleration (two independent routes).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// A screw on a cylindrical joint along (1, 1, 0)/√2 turning at 2 rad/s and advancing at 0.5 m/s, and a slider
// lifted to 1 + t² on a prismatic rail: over t ∈ [0, 4] the screw turns 8 rad, past ±π.
const char* kScrew = R"(phiq: 1
dimension: 3
parameters: {s: 0.7071067811865476}
bodies:
  screw: {at: [0, 0, 0]}
  slider: {at: [0, 0, 1]}
constraints:
  - {name: cyl, type: cylindrical, between: [{body: ground, axis: [s, s, 0]}, {body: screw, axis: [s, s, 0]}]}
  - {name: rail, type: prismatic, between: [{body: ground, at: [0, 0, 1], axis: [0, 0, 1]}, {body: slider, axis: [0, 0, 1]}]}
drivers:
  - {name: turn, joint: cyl, measure: angle, law: {type: linear, initial: 0, rate: 2}}
  - {name: travel, joint: cyl, measure: distance, law: {type: linear, initial: 0, rate: 0.5}}
  - {name: lift, joint: rail, law: {type: polynomial, coefficients: [0, 0, 1]}}
time: {start: 0, end: 4, steps: 40}
output: {velocities: true, accelerations: true, joints: [cyl, rail], orientations: {bodies: [screw], as: axis_angle}}
)";

struct JointRows {
  std::vector<double> t;
  std::vector<std::vector<JointMotion>> joints;
  std::vector<std::vector<OrientationMotion>> orientations;
};

JointRows sweep_rows(const Scene& s, int threads) {
  SweepOptions o = s.sweep;
  o.threads = threads;
  Workspace ws(*s.model);
  JointRows r;
  SweepSummary sum;
  const SolveStatus st = run_sweep(
      *s.model, o, ws,
      [&](const StepView& v) {
        r.t.push_back(v.t);
        r.joints.emplace_back(v.joints, v.joints + o.joints.size());
        if (v.orientations) r.orientations.emplace_back(v.orientations, v.orientations + o.orientations.size());
        return true;
      },
      &sum);
  EXPECT_EQ(st, SolveStatus::kSuccess) << sum.message;
  return r;
}

TEST(OutputJoints, AnglesAndDistancesFollowTheDriversThroughTurns) {
  const Scene s = parse_scene(kScrew, "screw.yaml");
  ASSERT_EQ(s.sweep.joints.size(), 3u);  // cyl's angle and distance, rail's distance
  EXPECT_EQ(s.sweep.joints[0].measure, JointMeasure::kAngle);
  EXPECT_EQ(s.sweep.joints[1].measure, JointMeasure::kDistance);
  for (int threads : {1, 2, 3}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    const JointRows r = sweep_rows(s, threads);
    ASSERT_EQ(r.t.size(), 41u);
    for (std::size_t k = 0; k < r.t.size(); ++k) {
      const double t = r.t[k];
      const JointMotion& angle = r.joints[k][0];
      EXPECT_NEAR(angle.value, 2 * t, 1e-9) << t;  // 8 rad at the end, not 8 − 2π
      EXPECT_NEAR(angle.rate, 2.0, 1e-9) << t;
      EXPECT_NEAR(angle.acceleration, 0.0, 1e-9) << t;
      EXPECT_NEAR(r.joints[k][1].value, 0.5 * t, 1e-9) << t;
      EXPECT_NEAR(r.joints[k][1].rate, 0.5, 1e-9) << t;
      EXPECT_NEAR(r.joints[k][2].value, t * t, 1e-9) << t;
      EXPECT_NEAR(r.joints[k][2].rate, 2 * t, 1e-9) << t;
      EXPECT_NEAR(r.joints[k][2].acceleration, 2.0, 1e-9) << t;
      // the screw's orientation: a turn of 2t (mod 2π, in [0, π]) about ±(1, 1, 0)/√2; ω = 2 (1, 1, 0)/√2
      const OrientationMotion& o = r.orientations[k][0];
      const double turned = std::fabs(std::remainder(2 * t, 2 * M_PI));
      EXPECT_NEAR(o.values[3], turned, 1e-9) << t;
      if (turned > 1e-3) {
        EXPECT_NEAR(std::fabs(o.values[0]), std::sqrt(0.5), 1e-9) << t;
      }
      EXPECT_NEAR(o.omega[0], std::sqrt(2.0), 1e-9) << t;
      EXPECT_NEAR(o.omega[2], 0.0, 1e-9) << t;
      EXPECT_NEAR(o.alpha[1], 0.0, 1e-9) << t;
    }
  }
}

TEST(OutputJoints, RowsLeftUnwrittenStillUnwrap) {
  // every 7th row only: the angle jumps 1.4 rad between written rows, and the unwritten ones carried it
  const Scene s = parse_scene(test::replace_first(kScrew, "output: {", "output: {every: 7, "), "every.yaml");
  for (int threads : {1, 2}) {
    const JointRows r = sweep_rows(s, threads);
    ASSERT_EQ(r.t.size(), 6u);
    for (std::size_t k = 0; k < r.t.size(); ++k) EXPECT_NEAR(r.joints[k][0].value, 2 * r.t[k], 1e-9) << threads;
  }
}

TEST(OutputJoints, RockerAngleAgreesWithItsAngularVelocity) {
  // RSSR: the rocker turns about x on its hinge. Its joint angle's rate and acceleration (dot products of the
  // hinge's attachments) equal its angular velocity and acceleration (2 E(e) ė, 2 E(e) ë) about x; its angle is
  // the rotation matrix's about x, from the reference y (the axis is x: the default reference moves to y).
  std::ifstream in(test::model_path("spatial/rssr.yaml"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text = test::replace_first(text, "output: {velocities: true, accelerations: true}",
                             "output: {velocities: true, accelerations: true, joints: [rocker_hinge, crank_hinge], "
                             "orientations: [rocker, crank]}");
  const Scene s = parse_scene(text, "rssr.yaml");
  const JointRows r = sweep_rows(s, 2);
  ASSERT_EQ(r.t.size(), 73u);
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    SCOPED_TRACE("t = " + std::to_string(r.t[k]));
    const JointMotion& rocker = r.joints[k][0];
    const OrientationMotion& R = r.orientations[k][0];  // rows R11 … R33
    EXPECT_NEAR(std::remainder(rocker.value - std::atan2(R.values[7], R.values[4]), 2 * M_PI), 0.0, 1e-9);
    EXPECT_NEAR(rocker.rate, R.omega[0], 1e-9);
    EXPECT_NEAR(rocker.acceleration, R.alpha[0], 1e-9);
    EXPECT_NEAR(R.omega[1], 0.0, 1e-9);
    // the crank: angle t from x about z, unwrapped up to 2π; rate 1
    EXPECT_NEAR(r.joints[k][1].value, r.t[k], 1e-9);
    EXPECT_NEAR(r.orientations[k][1].omega[2], 1.0, 1e-9);
  }
}

TEST(OutputJoints, ColumnsAreNamedAndBadEntriesRefused) {
  const Scene s = parse_scene(kScrew, "screw.yaml");
  CsvFormat f(*s.model, s.sweep);
  const std::vector<std::string> names = f.column_names();
  const std::vector<std::string> tail(names.end() - 19, names.end());
  EXPECT_EQ(tail, (std::vector<std::string>{"cyl.angle", "cyl.angle.v", "cyl.angle.a", "cyl.distance", "cyl.distance.v",
                                            "cyl.distance.a", "rail.distance", "rail.distance.v", "rail.distance.a",
                                            "screw.ux", "screw.uy", "screw.uz", "screw.angle", "screw.omega_x",
                                            "screw.omega_y", "screw.omega_z", "screw.alpha_x", "screw.alpha_y",
                                            "screw.alpha_z"}));
  auto with = [&](const std::string& output) {
    return test::scene_error(
        test::replace_first(kScrew, "joints: [cyl, rail], orientations: {bodies: [screw], as: axis_angle}", output));
  };
  EXPECT_HAS(with("joints: [cyl, cy]"), "output.joints[1]: unknown joint 'cy'");
  EXPECT_HAS(with("joints: [cyl, cyl]"), "joint listed twice");
  EXPECT_HAS(with("orientations: [screw, slidr]"), "output.orientations[1]: unknown body 'slidr'");
  EXPECT_HAS(with("orientations: {bodies: [screw], as: yaw}"), "'yaw' is not an orientation form");
  const std::string ball = test::replace_first(
      test::replace_first(kScrew, "joints: [cyl, rail]", "joints: [ball]"), "constraints:\n",
      "constraints:\n  - {name: ball, type: spherical, between: [{body: screw}, {body: slider, at: [0, 0, -1]}]}\n");
  EXPECT_HAS(test::scene_error(ball), "output.joints[0]: joint 'ball' is a spherical joint");
}

// A screw of pitch p = 4 mm driven through turns by its angle, then by its travel: its output angle and travel are
// the driven value and the helix's other coordinate, d = p θ / 2π, with their rates (the angle unwrapped past ±π).
TEST(OutputJoints, DrivenScrewAngleAndTravelFollowItsDriver) {
  const std::string by_angle = R"(phiq: 1
dimension: 3
bodies:
  nut: {at: [0, 0, 0]}
constraints:
  - {name: ls, type: screw, between: [{body: ground, axis: [0, 0, 1]}, {body: nut, axis: [0, 0, 1]}], pitch: 0.004}
drivers:
  - {name: crank, joint: ls, measure: angle, law: {type: linear, initial: 0, rate: 2}}
time: {start: 0, end: 4, steps: 40}
output: {velocities: true, accelerations: true, joints: [ls]}
)";
  const double p = 0.004, k = 2 * M_PI / p;  // radians per metre of travel
  const std::string by_travel =
      test::replace_first(by_angle, "measure: angle, law: {type: linear, initial: 0, rate: 2}",
                          "measure: distance, law: {type: linear, initial: 0, rate: 0.004}");
  for (const auto& [text, theta_rate] : {std::pair{by_angle, 2.0}, std::pair{by_travel, 0.004 * k}}) {
    const Scene s = parse_scene(text, "screw.yaml");
    ASSERT_EQ(s.sweep.joints.size(), 2u);  // the angle, then the travel
    for (int threads : {1, 2}) {
      SCOPED_TRACE("threads " + std::to_string(threads) + ", angle rate " + std::to_string(theta_rate));
      const JointRows r = sweep_rows(s, threads);
      ASSERT_EQ(r.t.size(), 41u);
      for (std::size_t i = 0; i < r.t.size(); ++i) {
        const double t = r.t[i];
        const JointMotion &angle = r.joints[i][0], &travel = r.joints[i][1];
        // (the rates and accelerations come from linear solves through the helix's k ≈ 1571 rad/m: rounding ×k)
        EXPECT_NEAR(angle.value, theta_rate * t, 1e-12) << t;  // up to 8 rad driven, 8π by the travel
        EXPECT_NEAR(angle.rate, theta_rate, 1e-11) << t;
        EXPECT_NEAR(angle.acceleration, 0.0, 1e-10) << t;
        EXPECT_NEAR(travel.value * k, theta_rate * t, 1e-12) << t;
        EXPECT_NEAR(travel.rate * k, theta_rate, 1e-11) << t;
        EXPECT_NEAR(travel.acceleration * k, 0.0, 1e-10) << t;
      }
    }
  }
}

}  // namespace
}  // namespace phiq
