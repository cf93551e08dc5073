// Scenes of dimension 3: what a good scene builds (bodies with their Euler normalisation, natural points and unit
// vectors, joints, joint drivers, families) and the one-line errors of bad ones, as test_scene.cpp does in the
// plane.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// A door on one hinge, driven by its angle; a natural point and vector beside it.
const char* kGood3d = R"(phiq: 1
dimension: 3
parameters: {h: 2}
coordinates: {x: 0, y: 0, z: 0, e0: 1, e1: 0, e2: 0, e3: 0}
bodies:
  door: [x, y, z, e0, e1, e2, e3]
constraints:
  - {name: hinge, type: revolute, between: [{body: ground, at: [0, 0, h], axis: [0, 0, 1]}, {body: door, at: [0, 0, h]}]}
drivers:
  - {name: open, joint: hinge, law: {type: linear, initial: 0, rate: 1}}
time: {start: 0, end: 1, steps: 4}
)";

std::string edited(const std::string& from, const std::string& to) { return test::replace_first(kGood3d, from, to); }

TEST(Scene3d, GoodSceneBuildsBodiesJointsAndDrivers) {
  Scene s = parse_scene(kGood3d, "good.yaml");
  const Model& m = *s.model;
  EXPECT_EQ(m.num_coordinates(), 7);
  EXPECT_EQ(m.num_equations(), 7);
  ASSERT_EQ(m.constraints().size(), 3u);
  EXPECT_EQ(m.constraints()[0].name, "door.euler");
  EXPECT_EQ(m.constraints()[0].kind, "euler_parameters");
  EXPECT_EQ(m.constraints()[1].kind, "revolute");
  EXPECT_EQ(m.constraints()[1].rows, 5);
  EXPECT_EQ(m.constraints()[2].kind, "joint_angle_driver");
  EXPECT_EQ(*m.grubler(), 1);
  // it runs: the door turns by t about z
  Workspace ws(m);
  std::vector<double> last;
  const auto keep_last = [&](const StepView& v) {
    last.assign(v.q.data(), v.q.data() + 7);
    return true;
  };
  ASSERT_EQ(run_sweep(m, s.sweep, ws, keep_last, nullptr), SolveStatus::kSuccess);
  ASSERT_EQ(last.size(), 7u);
  EXPECT_NEAR(std::fabs(last[3]), std::cos(0.5), 1e-10);  // a turn of 1 rad about z at t = 1 (p up to sign)
  EXPECT_NEAR(std::fabs(last[6]), std::sin(0.5), 1e-10);
}

TEST(Scene3d, NaturalPointsVectorsDotAndDistance) {
  // a rigid body in 3D natural coordinates: two points and a unit vector, the point O fixed
  const char* text = R"(phiq: 1
dimension: 3
coordinates: {ax: 1, ay: 0, az: 0, ux: 0, uy: 0, uz: 1}
points: {O: [0, 0, 0], A: [ax, ay, az]}
vectors: {u: [ux, uy, uz]}
constraints:
  - {name: bar, type: distance, points: [O, A], length: 1}
  - {name: square, type: dot, directions: [u, [O, A]], value: 0}
  - {name: plane, type: equation, expr: "az", unit: length}
  - {name: up, type: dot, directions: [u, u], value: 1}
drivers:
  - {name: turn, expr: "ay", unit: length, law: {type: linear, initial: 0, rate: 0.5}}
  - {name: lock, coordinate: ux, law: {type: linear, initial: 0, rate: 0}}
time: {start: 0, end: 1, steps: 2}
)";
  Scene s = parse_scene(text, "natural.yaml");  // u.unit and `up` say the same: 7 equations for 6 coordinates
  const Model& m = *s.model;
  EXPECT_EQ(m.num_coordinates(), 6);
  EXPECT_EQ(m.num_equations(), 7);
  EXPECT_EQ(m.constraints()[0].name, "u.unit");
  EXPECT_FALSE(m.grubler().has_value());  // natural coordinates: no joints
  Eigen::VectorXd q(6);
  q << 0.8, 0.6, 0, 0, 0, 1;
  Eigen::VectorXd phi(7);
  m.residual(q.data(), 1.2, phi.data());
  EXPECT_LT(phi.lpNorm<Eigen::Infinity>(), 1e-15);  // ay = 0.5 · 1.2
}

TEST(Scene3d, FamiliesMakeChainsOfBodies) {
  const char* text = R"(phiq: 1
dimension: 3
parameters: {N: 3}
coordinates:
  for i in 1..N:
    x{i}: i - 1
    y{i}: 0
    z{i}: 0
    p{i}: 1
    q{i}: 0
    r{i}: 0
    s{i}: 0
bodies:
  for i in 1..N:
    B{i}: ["x{i}", "y{i}", "z{i}", "p{i}", "q{i}", "r{i}", "s{i}"]
constraints:
  - {name: base, type: spherical, between: [{body: ground}, {body: B1}]}
  - for i in 1..N-1:
      - {name: "link{i}", type: universal, between: [{body: "B{i}", at: [1, 0, 0], axis: [0, 0, 1]}, {body: "B{i+1}", axis: [0, 1, 0]}]}
time: {start: 0, end: 1, steps: 1}
)";
  Scene s = parse_scene(text, "chain.yaml");
  const Model& m = *s.model;
  EXPECT_EQ(m.num_coordinates(), 21);
  EXPECT_EQ(m.num_equations(), 3 + 3 + 2 * 4);
  EXPECT_EQ(*m.grubler(), 18 - 3 - 8);
  EXPECT_EQ(m.body_names(), (std::vector<std::string>{"B1", "B2", "B3"}));
  EXPECT_EQ(m.constraints()[4].name, "link1");
}

// A screw-like motion: a body on a cylindrical joint to ground along the axis (1, 1, 0)/√2, its turn and its travel
// driven separately (7 coordinates: 1 normalisation + 4 + 2 drivers); and a slider on a prismatic joint driven by
// its travel. Swept by the square solver; the body's origin must be at d · axis, turned by θ about the axis.
TEST(Scene3d, JointDriversTurnAndSlide) {
  const char* text = R"(phiq: 1
dimension: 3
parameters: {s: 0.7071067811865476}
coordinates: {x: 0, y: 0, z: 0, e0: 1, e1: 0, e2: 0, e3: 0, px: 0, py: 0, pz: 0, p0: 1, p1: 0, p2: 0, p3: 0}
bodies:
  screw: [x, y, z, e0, e1, e2, e3]
  slider: [px, py, pz, p0, p1, p2, p3]
constraints:
  - {name: cyl, type: cylindrical, between: [{body: ground, axis: [s, s, 0]}, {body: screw, axis: [s, s, 0]}]}
  - {name: rail, type: prismatic, between: [{body: ground, at: [0, 0, 1], axis: [0, 0, 1]}, {body: slider, axis: [0, 0, 1]}]}
drivers:
  - {name: turn, joint: cyl, measure: angle, law: {type: linear, initial: 0, rate: 2}}
  - {name: travel, joint: cyl, measure: distance, law: {type: linear, initial: 0, rate: 0.5}}
  - {name: lift, joint: rail, law: {type: polynomial, coefficients: [0, 0, 1]}}
time: {start: 0, end: 2, steps: 20}
output: {velocities: true}
)";
  Scene sc = parse_scene(text, "screw.yaml");
  const Model& m = *sc.model;
  EXPECT_EQ(m.num_coordinates(), 14);
  EXPECT_EQ(m.num_equations(), 14);
  EXPECT_EQ(*m.grubler(), 12 - 4 - 5);  // 3: the three drivers take them
  EXPECT_EQ(m.constraints()[5].kind, "joint_distance_driver");
  Workspace ws(m);
  std::vector<std::vector<double>> q, qd;
  const auto keep = [&](const StepView& v) {
    q.emplace_back(v.q.data(), v.q.data() + 14);
    qd.emplace_back(v.qd->data(), v.qd->data() + 14);
    return true;
  };
  ASSERT_EQ(run_sweep(m, sc.sweep, ws, keep, nullptr), SolveStatus::kSuccess);
  ASSERT_EQ(q.size(), 21u);
  const double s = std::sqrt(0.5);
  for (std::size_t k = 0; k < q.size(); ++k) {
    const double t = 0.1 * static_cast<double>(k), th = 2 * t, d = 0.5 * t;
    SCOPED_TRACE("t = " + std::to_string(t));
    EXPECT_NEAR(q[k][0], d * s, 1e-10);
    EXPECT_NEAR(q[k][1], d * s, 1e-10);
    EXPECT_NEAR(q[k][2], 0.0, 1e-10);
    // Euler parameters of a turn θ about the axis, up to the sign of the whole quaternion
    const double e[4] = {std::cos(th / 2), s * std::sin(th / 2), s * std::sin(th / 2), 0.0};
    const double sign = q[k][3] * e[0] + q[k][4] * e[1] + q[k][5] * e[2] + q[k][6] * e[3] < 0 ? -1.0 : 1.0;
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(sign * q[k][3 + i], e[i], 1e-10) << "e" << i;
    EXPECT_NEAR(qd[k][0], 0.5 * s, 1e-10);  // the travel's rate along the axis
    // the slider: lifted to 1 + t² along z, not turned
    EXPECT_NEAR(q[k][9], 1.0 + t * t, 1e-10);
    EXPECT_NEAR(qd[k][9], 2 * t, 1e-10);
    EXPECT_NEAR(std::fabs(q[k][10]), 1.0, 1e-10);
  }
}

TEST(Scene3d, ABodyTurningOnAHingeIsNeverReportedNearSingular) {
  // One body on a hinge about an oblique axis, turned through 5 turns: its Φq is as well conditioned at every angle
  // (a pivot search gives ratios 0.05 … 0.5), but the pivot order KLU kept from one angle let a pivot run to 5e-9
  // where an Euler parameter crossed zero, and the sweep warned of a near-singular position with 7 digits left.
  const char* text = R"(phiq: 1
dimension: 3
coordinates: {x: 0.068, y: -0.484, z: 0.843, e0: 1.317, e1: 0.017, e2: 0.068, e3: -0.239}
bodies:
  disk: [x, y, z, e0, e1, e2, e3]
constraints:
  - {name: hinge, type: revolute, between: [{body: ground, at: [0.3, -0.2, 0.5], axis: [1, 2, 2]}, {body: disk, at: [0.1, 0.4, -0.3], axis: [0, 1, 1]}]}
drivers:
  - {name: motor, joint: hinge, measure: angle, law: {type: polynomial, coefficients: [-0.3, 3, 0.5]}}
time: {start: 0, end: 6, steps: 1200}
output: {velocities: true, accelerations: true}
)";
  Scene sc = parse_scene(text, "hinge.yaml");
  Workspace ws(*sc.model);
  SweepSummary sum;
  ASSERT_EQ(run_sweep(*sc.model, sc.sweep, ws, nullptr, &sum), SolveStatus::kSuccess) << sum.message;
  for (const SweepWarning& w : sum.warnings) ADD_FAILURE() << w.kind << " at t = " << w.t << ": " << w.message;
  EXPECT_GT(sum.min_rcond, 1e-7);
}

TEST(Scene3d, BadInputIsOneLineNamingTheField) {
  EXPECT_HAS(error_of(edited("axis: [0, 0, 1]}", "axis: [0, 0, 0]}")), "between[0].axis: must not be the zero vector");
  EXPECT_HAS(error_of(edited("{body: door, at: [0, 0, h]}", "{body: dor, at: [0, 0, h]}")), "unknown body 'dor'");
  // all-zero Euler parameters are no orientation: refused at the body, not "Gauss-Newton step is not finite"
  EXPECT_HAS(error_of(edited("e0: 1,", "e0: 0,")),
             "bad.yaml:6:9: bodies.door: body 'door': its Euler parameters are all 0 in the placement");
  EXPECT_HAS(error_of(edited("{body: door, at: [0, 0, h]}", "{body: door, at: [0, h]}")),
             "between[1].at: expected a list of 3 numbers");
  EXPECT_HAS(error_of(edited("{body: door, at: [0, 0, h]}", "{body: door, ref: [0, 0, 3]}")),
             "ref must not be zero or along the axis");
  EXPECT_HAS(error_of(edited("door: [x, y, z, e0, e1, e2, e3]", "door: [x, y, z]")),
             "a body is [x, y, z, e0, e1, e2, e3], or {at: [x, y, z], orientation: {...}} (dimension: 3)");
  EXPECT_HAS(error_of(edited("type: revolute", "type: loop")), "'loop' is a planar constraint");
  EXPECT_HAS(error_of(edited("type: revolute", "type: hinge")), "unknown constraint type 'hinge'");
  EXPECT_HAS(error_of(edited("joint: hinge", "joint: hing")), "drivers[0].joint: unknown joint 'hing'");
  EXPECT_HAS(error_of(edited("joint: hinge,", "joint: hinge, measure: distance,")),
             "joint 'hinge' is a revolute joint");
  EXPECT_HAS(error_of(edited("type: revolute", "type: cylindrical")), "needs 'measure: angle' or 'measure: distance'");
  EXPECT_HAS(error_of(edited("type: revolute", "type: spherical")), "joint 'hinge' is a spherical joint");
  EXPECT_HAS(error_of(edited("joint: hinge,", "joint: hinge, coordinate: x,")),
             "one of 'coordinate', 'expr' or 'joint'");
  EXPECT_HAS(error_of(edited("{body: ground, at: [0, 0, h], axis: [0, 0, 1]}", "{point: P}")), "unknown point 'P'");
  const std::string with_point = edited("bodies:", "points: {P: [1, 2, 3]}\nbodies:");
  const std::string natural_a = with_point.substr(0, with_point.find("{body: ground")) + "{point: P}" +
                                with_point.substr(with_point.find(", {body: door"));
  EXPECT_HAS(error_of(natural_a), "side a: needs a body or ground");
  EXPECT_HAS(error_of(edited("bodies:", "points: {P: [1, 2]}\nbodies:")), "a point is [x, y, z] (dimension: 3)");
  EXPECT_HAS(error_of(edited("bodies:", "vectors: {u: [1, 2]}\nbodies:")), "a vector is [ux, uy, uz]");
  EXPECT_HAS(error_of(edited("bodies:", "points: {door: [1, 2, 3]}\nbodies:")), "duplicate point, body or vector name");
  EXPECT_HAS(error_of(edited("dimension: 3", "dimension: 4")), "dimension");
}

// The door of kGood3d written as a map: phiq adds door_x … door_e3 with the placement and orientation as initial
// guesses; every form of orientation gives the Euler parameters of the same rotation.
TEST(Scene3d, BodiesWrittenAsMapsBringTheirCoordinates) {
  auto door = [](const std::string& body) {
    std::string s = test::replace_first(kGood3d, "coordinates: {x: 0, y: 0, z: 0, e0: 1, e1: 0, e2: 0, e3: 0}\n", "");
    return test::replace_first(s, "door: [x, y, z, e0, e1, e2, e3]", "door: " + body);
  };
  const double c = std::cos(0.15), sn = std::sin(0.15);  // a turn of 0.3 about z
  for (const std::string& body :
       {std::string("{at: [0, 0, h], orientation: {axis: [0, 0, 2], angle: 0.3}}"),
        std::string("{at: [0, 0, h], orientation: {euler: zyx, angles: [0.3, 0, 0]}}"),
        std::string("{at: [0, 0, h], orientation: {euler: zxz, angles: [0.1, 0, 0.2]}}"),
        std::string("{at: [0, 0, h], orientation: {x: [cos(0.3), sin(0.3), 0]}}"),
        std::string("{at: [0, 0, h], orientation: {z: [0, 0, 1], x: [cos(0.3), sin(0.3), 5]}}"),
        std::string("{at: [0, 0, h], orientation: {euler_parameters: [2*cos(0.15), 0, 0, "
                    "2*sin(0.15)]}}")}) {
    SCOPED_TRACE(body);
    const Scene s = parse_scene(door(body), "map.yaml");
    const Model& m = *s.model;
    ASSERT_EQ(m.num_coordinates(), 7);
    EXPECT_EQ(m.coordinate_names(),
              (std::vector<std::string>{"door_x", "door_y", "door_z", "door_e0", "door_e1", "door_e2", "door_e3"}));
    const std::vector<double> want{0, 0, 2, c, 0, 0, sn};
    for (Index i = 0; i < 7; ++i) EXPECT_NEAR(m.initial_positions()[i], want[static_cast<std::size_t>(i)], 1e-15) << i;
    EXPECT_EQ(m.constraints()[0].name, "door.euler");
    EXPECT_EQ(*m.grubler(), 1);
  }
  // a fixed body adds no coordinate: a frame of constants, here a hinge's ground side turned by 90° about x
  const std::string fixed = test::replace_first(
      door("{at: [0, 0, h]}"), "bodies:\n",
      "bodies:\n  wall: {at: [0, 0, h], orientation: {axis: [1, 0, 0], angle: pi/2}, fixed: true}\n");
  const Scene f = parse_scene(
      test::replace_first(fixed, "{body: ground, at: [0, 0, h], axis: [0, 0, 1]}", "{body: wall, axis: [0, -1, 0]}"),
      "fixed.yaml");
  EXPECT_EQ(f.model->num_coordinates(), 7);
  Workspace ws(*f.model);
  SweepSummary sum;
  ASSERT_EQ(run_sweep(*f.model, f.sweep, ws, nullptr, &sum), SolveStatus::kSuccess) << sum.message;
  EXPECT_NEAR(ws.q[5], 0.0, 1e-12);  // the wall's −y is the world's z: the door still turns about z
  // bad maps: one line naming the field
  EXPECT_HAS(error_of(door("{at: [0, 0, h], orientation: {axis: [0, 0, 1], angle: 1, z: [0, 0, 1]}}")),
             "bodies.door.orientation: an orientation is one of {axis: [ux, uy, uz], angle: a}");
  EXPECT_HAS(error_of(door("{orientation: {euler: zzx, angles: [1, 2, 3]}}")),
             "bodies.door.orientation.euler: 'zzx' is not an Euler sequence");
  EXPECT_HAS(error_of(door("{orientation: {x: [1, 0, 0], y: [2, 0, 0]}}")),
             "bodies.door.orientation: the second direction lies along the first");
  EXPECT_HAS(error_of(door("{orientation: {axis: [0, 0, 0], angle: 1}}")),
             "bodies.door.orientation: the rotation axis must be a non-zero finite vector");
  EXPECT_HAS(error_of(door("{at: [0, 0]}")), "bodies.door.at: expected a list of 3 numbers");
  EXPECT_HAS(error_of(door("{at: [0, 0, 0], angle: 1}")),
             "bodies.door.angle: unknown field 'angle' (allowed: at, orientation, fixed)");
  EXPECT_HAS(error_of(test::replace_first(door("{}"), "parameters: {h: 2}", "parameters: {h: 2, door_z: 1}")),
             "bodies.door: its coordinate 'door_z' is already a parameter");
  EXPECT_HAS(error_of(test::replace_first(door("{}"), "bodies:", "coordinates: {door_e1: 0}\nbodies:")),
             "bodies.door: its coordinate 'door_e1' is already a coordinate");
  EXPECT_HAS(error_of(test::replace_first(door("{fixed: true}"), "  - {name: open", "  - {name: x")),
             "at least one coordinate is needed: a `coordinates` section, or bodies written as maps");
}

// A hinge about x measures its angle from y on both sides unless the scene says otherwise; the scene records it.
TEST(Scene3d, JointAngleReferencesAreRecorded) {
  const Scene s = parse_scene(kGood3d, "good.yaml");
  ASSERT_EQ(s.joint_angles.size(), 1u);
  EXPECT_EQ(s.joint_angles[0].driver, "open");
  EXPECT_EQ(s.joint_angles[0].joint, "hinge");
  EXPECT_EQ(s.joint_angles[0].ref_a, (std::array<double, 3>{1, 0, 0}));
  EXPECT_FALSE(s.joint_angles[0].stated_a);
  std::string about_x = edited("axis: [0, 0, 1]}", "axis: [1, 0, 0]}");
  about_x = test::replace_first(about_x, "{body: door, at: [0, 0, h]}",
                                "{body: door, at: [0, 0, h], axis: [0.95, 0.1, 0], ref: [0, 0, 1]}");
  const Scene x = parse_scene(about_x, "x.yaml");
  ASSERT_EQ(x.joint_angles.size(), 1u);
  EXPECT_EQ(x.joint_angles[0].ref_a, (std::array<double, 3>{0, 1, 0}));  // within 25° of x: y
  EXPECT_EQ(x.joint_angles[0].ref_b, (std::array<double, 3>{0, 0, 1}));
  EXPECT_FALSE(x.joint_angles[0].stated_a);
  EXPECT_TRUE(x.joint_angles[0].stated_b);
  // the axis of a spatial joint is on its sides: a prismatic's planar `axis` field says where it goes
  EXPECT_HAS(error_of(edited("type: revolute, between:", "type: prismatic, axis: [0, 0, 1], between:")),
             "constraints[0].axis: in dimension 3 a joint's axis is given on each side");
}

TEST(Scene3d, SpatialInputInAPlanarSceneIsAnError) {
  const std::string planar = R"(phiq: 1
coordinates: {x: 0, y: 0, psi: 0}
bodies: {B: [x, y, psi]}
constraints:
  - {name: pin, type: revolute, between: [{body: ground}, {body: B}]}
drivers:
  - {name: motor, coordinate: psi, law: {type: linear, initial: 0, rate: 1}}
time: {start: 0, end: 1, steps: 1}
)";
  auto planar_variant = [&](const std::string& from, const std::string& to) {
    std::string s = planar;
    return s.replace(s.find(from), from.size(), to);
  };
  EXPECT_HAS(error_of(planar_variant("type: revolute", "type: spherical")),
             "'spherical' is a spatial constraint: it needs 'dimension: 3'");
  EXPECT_HAS(error_of(planar_variant("bodies:", "vectors: {u: [1, 0, 0]}\nbodies:")), "need 'dimension: 3'");
  EXPECT_HAS(error_of(planar_variant("coordinate: psi,", "joint: pin,")), "joint drivers need 'dimension: 3'");
  // a planar reference-point body is counted: one body, one pin: 3 − 2 = 1
  EXPECT_EQ(*parse_scene(planar, "planar.yaml").model->grubler(), 1);
}

}  // namespace
}  // namespace phiq
