// Bevel gears and worms in joint reactions (add_gear_mesh_forces(), phiq/joint_reactions.hpp): a spatial gear's
// rows turn its shafts by torques about their axes, yet their bearings carry the push of its teeth at the pitch
// point. Checked by Newton–Euler written in the test, with the pitch point and the textbook split of a bevel
// pinion's load (tangential W, radial W tan α cos δ1 toward its axis, axial W tan α sin δ1 away from the apex), in a
// fixed and a turning housing, and a frictionless worm's. Pitch points that cannot be placed are told.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "phiq/phiq.hpp"
#include "reaction_rows.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

using test::ReactionRows;
using Vec3 = Eigen::Vector3d;

// models/transmissions/bevel_gears.yaml (the input about x, the output about y, the apex at the origin) with `mesh`
// for its gear's entry, a heavy output shaft (a disc about y) and a massless input, no gravity, every reaction.
Scene bevel_pair(const std::string& mesh) {
  std::string text = test::model_file_text("transmissions/bevel_gears.yaml", "output:");
  text = test::replace_first(
      text,
      "{name: bevel, type: spatial_gear, shafts: [input_bearing, output_bearing], angles: [theta1, theta2], "
      "teeth: [15, 30]}",
      mesh);
  return parse_scene(text +
                         "parts:\n  output_shaft: {mass: 2, center_of_mass: [0, 0, 0], inertia: [0.01, 0.02, 0.01]}\n"
                         "output: {velocities: true, accelerations: true, efforts: all, reactions: all}\n",
                     "bevel.yaml");
}

// A row's two bearings (values 2…13: the input's force and moment, then the output's) against the expected four.
void expect_bearings(const std::vector<double>& v, const std::array<Vec3, 4>& expected, double tol, std::size_t k) {
  for (std::size_t b = 0; b < 4; ++b)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(v[2 + 3 * b + static_cast<std::size_t>(c)], expected[b](c), tol) << k << " " << b << " " << c;
}

// Mean pitch radii 0.03 (input) and 0.06: the teeth push at P = (0.06, 0.03, 0), at 0.03 from the x axis and 0.06
// from the y axis. The output shaft turns by their moment alone, I ψ̈2 = y · (P × (−F)), which sets W; the bearing
// holds −(−F) and the moment Euler asks for about its point, the origin; the input's bearing holds the opposite
// push, and the motor turns the massless input against the push's moment about x.
TEST(BevelMeshes, ABevelPairsBearingsCarryItsTeethsPushByNewtonEuler) {
  SweepSummary sum;
  const Scene s = bevel_pair(
      "{name: bevel, type: spatial_gear, shafts: [input_bearing, output_bearing], angles: [theta1, theta2], "
      "radii: [0.03, 0.06]}");
  ASSERT_EQ(s.sweep.efforts.meshes.size(), 1u);
  const ReactionRows r = test::sweep_reactions(s, &sum);
  EXPECT_TRUE(sum.warnings.empty()) << sum.warnings[0].kind << ": " << sum.warnings[0].message;
  const Index theta2 = s.model->find_coordinate("theta2");
  const double r1 = 0.03, r2 = 0.06, i2 = 0.02, tan_a = std::tan(20 * M_PI / 180), delta1 = std::atan2(r1, r2);
  const Vec3 p(r2, r1, 0), x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  double largest = 0.0;
  for (std::size_t k = 0; k < r.values.size(); ++k) {
    const std::vector<double>& v = r.values[k];  // τ, power, input_bearing's Fx…Mz, output_bearing's
    ASSERT_EQ(v.size(), 14u);
    const double w = i2 * r.qdd[k](theta2) / r2;  // along z on the input's teeth
    const Vec3 f = w * z + std::fabs(w) * tan_a * (std::sin(delta1) * x - std::cos(delta1) * y);
    EXPECT_NEAR(y.dot(p.cross(-f)), i2 * r.qdd[k](theta2), 1e-12);  // (the output's Euler equation about y)
    const double motor = -x.dot(p.cross(f));
    const Vec3 in_force = -f, in_moment = -p.cross(f) - motor * x;
    const Vec3 out_force = f, out_moment = i2 * r.qdd[k](theta2) * y + p.cross(f);
    const double scale = 1.0 + std::fabs(w);
    EXPECT_NEAR(v[0], motor, 1e-11 * scale) << k;
    expect_bearings(v, {in_force, in_moment, out_force, out_moment}, 1e-10 * scale, k);
    largest = std::max(largest, std::fabs(w));
  }
  EXPECT_GT(largest, 0.1);
}

// Tooth counts place no pitch point, a reversed pair does not say which axis points away from its gear, a worm's
// axes do not cross, and a `gear` between rotation angles does not know its shafts: each is told at the first row,
// its bearings carrying only the shafts' torques.
TEST(BevelMeshes, PushesThatCannotBePlacedAreTold) {
  const std::string head =
      "{name: bevel, type: spatial_gear, shafts: [input_bearing, output_bearing], angles: [theta1, theta2], ";
  for (const auto& [tail, words] : std::vector<std::pair<std::string, std::string>>{
           {"teeth: [15, 30]}", "its teeth do not place"}, {"radii: [0.03, 0.06], reversed: true}", "reversed"}}) {
    SweepSummary sum;
    const Scene s = bevel_pair(head + tail);
    test::sweep_reactions(s, &sum);
    ASSERT_EQ(sum.warnings.size(), 1u) << tail;
    EXPECT_EQ(sum.warnings[0].kind, "unloaded_bearings");
    EXPECT_HAS(sum.warnings[0].message, words);
  }
  // the output's bearing 0.05 above the apex along z: the axes no longer cross, and its radii do not span them
  std::string text = test::model_file_text("transmissions/bevel_gears.yaml", "output:");
  text =
      test::replace_first(text, "{body: ground, axis: [0, 1, 0]}", "{body: ground, at: [0, 0, 0.05], axis: [0, 1, 0]}");
  text = test::replace_first(text, "s2_z: 0", "s2_z: 0.05");
  text = test::replace_first(text, "teeth: [15, 30]", "radii: [0.03, 0.06]");
  SweepSummary sum;
  test::sweep_reactions(parse_scene(text + "parts:\n  output_shaft: {mass: 2, center_of_mass: [0, 0, 0], inertia: "
                                           "[0.01, 0.02, 0.01]}\noutput: {velocities: true, accelerations: true, "
                                           "efforts: all, reactions: all}\n",
                                    "worm.yaml"),
                        &sum);
  ASSERT_EQ(sum.warnings.size(), 1u);
  EXPECT_EQ(sum.warnings[0].kind, "unloaded_bearings");
  EXPECT_HAS(sum.warnings[0].message, "neither cross nor stand its two pitch radii apart");
  // a `gear` between the shafts' rotation angles relates coordinates whose shafts it does not know
  SweepSummary angles;
  test::sweep_reactions(bevel_pair("{name: turn1, type: rotation_angle, joint: input_bearing, angle: theta1}\n"
                                   "  - {name: turn2, type: rotation_angle, joint: output_bearing, angle: theta2}\n"
                                   "  - {name: pair, type: gear, between: [theta1, theta2], radii: [0.03, 0.06]}"),
                        &angles);
  ASSERT_EQ(angles.warnings.size(), 1u);
  EXPECT_EQ(angles.warnings[0].kind, "unloaded_bearings");
  EXPECT_HAS(angles.warnings[0].message, "'pair'");
  EXPECT_HAS(angles.warnings[0].message, "whose shafts it does not know");
}

// A bevel pair in a turning housing (a carrier spun about z, the shafts' bearings on it, both driven): the pitch
// point and the push move with the housing, and the push does no work in the motion (the pitch points roll on each
// other), which the sweep checks at every row: no gear_centres; and the output shaft's bearing carries the push.
TEST(BevelMeshes, APairInATurningHousingPushesWithoutWork) {
  const std::string text =
      "phiq: 1\nname: turning\ndimension: 3\n"
      "coordinates: {c_x: 0, c_y: 0, c_z: 0, c_e0: 1, c_e1: 0, c_e2: 0, c_e3: 0, s1_x: 0, s1_y: 0, s1_z: 0, s1_e0: 1,"
      " s1_e1: 0, s1_e2: 0, s1_e3: 0, s2_x: 0, s2_y: 0, s2_z: 0, s2_e0: 1, s2_e1: 0, s2_e2: 0, s2_e3: 0, theta1: 0,"
      " theta2: 0}\n"
      "bodies:\n  carrier: [c_x, c_y, c_z, c_e0, c_e1, c_e2, c_e3]\n"
      "  input_shaft: [s1_x, s1_y, s1_z, s1_e0, s1_e1, s1_e2, s1_e3]\n"
      "  output_shaft: [s2_x, s2_y, s2_z, s2_e0, s2_e1, s2_e2, s2_e3]\nconstraints:\n"
      "  - {name: carrier_bearing, type: revolute, between: [{body: ground}, {body: carrier}]}\n"
      "  - {name: input_bearing, type: revolute, between: [{body: carrier, axis: [1, 0, 0]}, "
      "{body: input_shaft, axis: [1, 0, 0]}]}\n"
      "  - {name: output_bearing, type: revolute, between: [{body: carrier, axis: [0, 1, 0]}, "
      "{body: output_shaft, axis: [0, 1, 0]}]}\n"
      "  - {name: bevel, type: spatial_gear, shafts: [input_bearing, output_bearing], angles: [theta1, theta2], "
      "radii: [0.03, 0.06]}\n"
      "drivers:\n  - {name: spin, joint: carrier_bearing, measure: angle, law: {type: linear, initial: 0, rate: 2}}\n"
      "  - {name: motor, coordinate: theta1, law: {type: polynomial, coefficients: [0, 3, 0.5]}}\n"
      "parts:\n  carrier: {mass: 3, center_of_mass: [0, 0, 0], inertia: [0.05, 0.05, 0.08]}\n"
      "  input_shaft: {mass: 1, center_of_mass: [0.05, 0, 0], inertia: [0.002, 0.004, 0.004]}\n"
      "  output_shaft: {mass: 2, center_of_mass: [0, 0, 0], inertia: [0.01, 0.02, 0.01]}\n"
      "loads: {gravity: [0, 0, -9.81]}\ntime: {start: 0, end: 2, steps: 40}\n"
      "output: {velocities: true, accelerations: true, efforts: all, reactions: [output_bearing]}\n";
  SweepSummary sum;
  const Scene s = parse_scene(text, "turning.yaml");
  ASSERT_EQ(s.sweep.efforts.meshes.size(), 1u);
  const ReactionRows r = test::sweep_reactions(s, &sum);
  for (const SweepWarning& w : sum.warnings) ADD_FAILURE() << w.kind << ": " << w.message;
  // The output shaft, axisymmetric about its axis y' (the carrier's y), turns about it by the teeth alone:
  // I θ̈2 = τ2 = f r2 sets the push F = f z + |f| tan 20° (sin δ1 x' − cos δ1 y') on the input's teeth, −F on its
  // own; its centre stays at the origin, so the bearing holds F and its weight, and reports the opposite on the
  // carrier (side 1).
  const Model& m = *s.model;
  const Index theta2 = m.find_coordinate("theta2"), e0 = m.find_coordinate("c_e0"), e3 = m.find_coordinate("c_e3");
  const double r1 = 0.03, r2 = 0.06, tan_a = std::tan(20 * M_PI / 180), delta1 = std::atan2(r1, r2);
  double largest = 0.0;
  for (std::size_t k = 0; k < r.values.size(); ++k) {
    const std::vector<double>& v = r.values[k];  // spin, motor, their powers, output_bearing's Fx…Mz
    ASSERT_EQ(v.size(), 10u);
    const double turn = 2 * std::atan2(r.q[k](e3), r.q[k](e0));
    const Vec3 x1(std::cos(turn), std::sin(turn), 0), y1(-std::sin(turn), std::cos(turn), 0), z(0, 0, 1);
    const double f = 0.02 * r.qdd[k](theta2) / r2;
    const Vec3 push = f * z + std::fabs(f) * tan_a * (std::sin(delta1) * x1 - std::cos(delta1) * y1);
    const Vec3 on_carrier = -(push + Vec3(0, 0, 2 * 9.81));
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(v[static_cast<std::size_t>(4 + c)], on_carrier(c), 1e-9 * (1 + std::fabs(f))) << k << " " << c;
    largest = std::max(largest, std::fabs(f));
  }
  EXPECT_GT(largest, 0.01);  // the motor's 1 rad/s² turns the output at 0.5
}

// A worm (one start, pitch radius 0.01, about x at the origin) and its 30-tooth wheel (pitch radius 0.05, about y
// through (0, 0, 0.06)): the teeth push at P = (0, 0, 0.01) on the common perpendicular, frictionless. The wheel
// turns by their moment alone, I θ̈2 = 0.05 Fx; the massless worm's motor balances theirs, τ = 0.01 Fy, and is, by
// the ideal drive's power, −I θ̈2 / 30; the teeth part worm and wheel by |(Fx, Fy)| tan 20°. Each bearing holds
// its shaft against them, the wheel's with the moment Euler asks about its point.
TEST(BevelMeshes, AWormsBearingsCarryItsTeethsPushByNewtonEuler) {
  const std::string text = test::worm_scene_text(100);
  SweepSummary sum;
  const Scene s =
      parse_scene(text +
                      "parts:\n  output_shaft: {mass: 2, center_of_mass: [0, 0, 0], inertia: [0.3, 0.5, "
                      "0.3]}\noutput: {velocities: true, accelerations: true, efforts: all, reactions: all}\n",
                  "worm.yaml");
  const ReactionRows r = test::sweep_reactions(s, &sum);
  for (const SweepWarning& w : sum.warnings) ADD_FAILURE() << w.kind << ": " << w.message;
  const Index theta2 = s.model->find_coordinate("theta2");
  const double i2 = 0.5, tan_a = std::tan(20 * M_PI / 180);
  const Vec3 p(0, 0, 0.01), a2(0, 0, 0.06), x(1, 0, 0), y(0, 1, 0);
  double largest = 0.0;
  for (std::size_t k = 0; k < r.values.size(); ++k) {
    const std::vector<double>& v = r.values[k];  // τ, power, input_bearing's Fx…Mz, output_bearing's
    ASSERT_EQ(v.size(), 14u);
    const double motor = -i2 * r.qdd[k](theta2) / 30, fx = i2 * r.qdd[k](theta2) / 0.05, fy = motor / 0.01;
    const Vec3 f(fx, fy, -std::hypot(fx, fy) * tan_a);
    EXPECT_NEAR(v[0], motor, 1e-10) << k;
    const Vec3 in_force = -f, in_moment = -p.cross(f) - motor * x;
    const Vec3 out_force = f, out_moment = i2 * r.qdd[k](theta2) * y - (p - a2).cross(-f);
    const double scale = 1.0 + f.norm();
    expect_bearings(v, {in_force, in_moment, out_force, out_moment}, 1e-10 * scale, k);
    largest = std::max(largest, std::fabs(fy));
  }
  EXPECT_GT(largest, 1.0);
}

}  // namespace
}  // namespace phiq
