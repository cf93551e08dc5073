// Spur and helical gears on parallel shafts in joint reactions (add_gear_mesh_forces(), phiq/joint_reactions.hpp):
// a spatial_gear between parallel shafts turns them by its ratio row's torques, yet their bearings carry the push
// of its teeth at the pitch point, in the gears' mid-plane: the tangential load, the radial load parting the gears
// (tan α / cos ψ of it: α the normal pressure angle) and a helix's axial thrust (tan ψ of it, its direction by the
// hand of the teeth). Checked by Newton–Euler written in the test for external and internal pairs, radii and tooth
// counts, either hand; pitch points that cannot be placed are told.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "phiq/drawn_parts.hpp"
#include "phiq/phiq.hpp"
#include "reaction_rows.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

using test::ReactionRows;
using Vec3 = Eigen::Vector3d;

// Two shafts along z: the input at the origin, massless, driven; the output, a disc (I = 0.02 about z) on a bearing
// at (0.12, 0, 0). `mesh` is the rest of the spatial_gear's entry. (`parts` false: no parts, only the derived ones.)
Scene parallel_pair(const std::string& mesh, bool parts = true) {
  return parse_scene(
      "phiq: 1\nname: parallel\ndimension: 3\n"
      "coordinates: {s1_x: 0, s1_y: 0, s1_z: 0, s1_e0: 1, s1_e1: 0, s1_e2: 0, s1_e3: 0, s2_x: 0.12, s2_y: 0, s2_z: 0,"
      " s2_e0: 1, s2_e1: 0, s2_e2: 0, s2_e3: 0, theta1: 0, theta2: 0}\n"
      "bodies:\n  input_shaft: [s1_x, s1_y, s1_z, s1_e0, s1_e1, s1_e2, s1_e3]\n"
      "  output_shaft: [s2_x, s2_y, s2_z, s2_e0, s2_e1, s2_e2, s2_e3]\nconstraints:\n"
      "  - {name: input_bearing, type: revolute, between: [{body: ground, axis: [0, 0, 1]}, "
      "{body: input_shaft, axis: [0, 0, 1]}]}\n"
      "  - {name: output_bearing, type: revolute, between: [{body: ground, at: [0.12, 0, 0], axis: [0, 0, 1]}, "
      "{body: output_shaft, axis: [0, 0, 1]}]}\n"
      "  - {name: mesh, type: spatial_gear, shafts: [input_bearing, output_bearing], angles: [theta1, theta2], " +
          mesh +
          "}\n"
          "drivers:\n  - {name: motor, coordinate: theta1, law: {type: polynomial, coefficients: [0, 2, 0.5]}}\n"
          "time: {start: 0, end: 3, steps: 120}\n" +
          (parts ? "parts:\n  output_shaft: {mass: 2, center_of_mass: [0, 0, 0], inertia: [0.01, 0.01, 0.02]}\n"
                   "output: {velocities: true, accelerations: true, efforts: all, reactions: all}\n"
                 : "output: {velocities: true}\n"),
      "parallel.yaml");
}

struct ParallelCase {
  std::string mesh;
  Vec3 p;           // the pitch point
  bool ring_first;  // gear 1 has internal teeth (it is the ring)
  double helix;     // gear 1's helix angle, right-handed > 0
  double ratio;     // θ2 / θ1
};

// The output turns by the teeth alone: I θ̈2 = z · ((P − O2) × (−F)), which sets F's component F_t along t, the way
// P moves on gear 1 turning about z; the thrust is −F_t tan ψ along z (F normal to the tooth line cos ψ z + sin ψ t
// of a right-handed gear), the parting |F_t| tan α / cos ψ toward gear 1's axis (away from it on a ring). The
// massless input's motor balances F's moment about z; each bearing holds its shaft, the output's with the moment
// Euler asks about its point.
void expect_newton_euler(const ParallelCase& c) {
  SCOPED_TRACE(c.mesh);
  SweepSummary sum;
  const Scene s = parallel_pair(c.mesh);
  ASSERT_EQ(s.sweep.efforts.meshes.size(), 1u);
  const ReactionRows r = test::sweep_reactions(s, &sum);
  for (const SweepWarning& w : sum.warnings) ADD_FAILURE() << w.kind << ": " << w.message;
  const Index theta1 = s.model->find_coordinate("theta1"), theta2 = s.model->find_coordinate("theta2");
  const double i2 = 0.02, tan_a = std::tan(20 * M_PI / 180);
  const Vec3 o1(0, 0, 0), o2(0.12, 0, 0), z(0, 0, 1);
  const Vec3 from_axis1 = Vec3(c.p.x(), c.p.y(), 0) - o1, t = z.cross(from_axis1).normalized();
  double largest = 0.0;
  for (std::size_t k = 0; k < r.values.size(); ++k) {
    const std::vector<double>& v = r.values[k];  // τ, power, input_bearing's Fx…Mz, output_bearing's
    ASSERT_EQ(v.size(), 14u);
    EXPECT_NEAR(r.qdd[k](theta2), c.ratio * r.qdd[k](theta1), 1e-9);
    const double alpha2 = r.qdd[k](theta2), ft = -i2 * alpha2 / z.dot((c.p - o2).cross(t));
    const Vec3 parting = (c.ring_first ? 1.0 : -1.0) * from_axis1.normalized();  // on gear 1
    const Vec3 f = ft * t - ft * std::tan(c.helix) * z + std::fabs(ft) * tan_a / std::cos(c.helix) * parting;
    EXPECT_NEAR(z.dot((c.p - o2).cross(-f)), i2 * alpha2, 1e-12);
    const double motor = -z.dot((c.p - o1).cross(f));
    const Vec3 in_force = -f, in_moment = -(c.p - o1).cross(f) - motor * z;
    const Vec3 out_force = f, out_moment = i2 * alpha2 * z + (c.p - o2).cross(f);
    // (q̈ known to the positions' tolerance times ω²: the ring first turns its pinion at 4 times its speed)
    const double scale = (1.0 + f.norm()) * (1.0 + r.qd[k](theta2) * r.qd[k](theta2));
    EXPECT_NEAR(v[0], motor, 1e-11 * scale) << k;
    const std::array<Vec3, 4> expected{in_force, in_moment, out_force, out_moment};
    for (std::size_t b = 0; b < 4; ++b)
      for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(v[2 + 3 * b + static_cast<std::size_t>(i)], expected[b](i), 1e-10 * scale) << k << " " << b;
    largest = std::max(largest, std::fabs(ft));
  }
  EXPECT_GT(largest, 0.02);  // (the motor's 1 rad/s² turns the output at a quarter to four times it)
}

TEST(HelicalMeshes, ParallelShaftsBearingsCarryTheTeethsPushByNewtonEuler) {
  // external: P between the axes, r1 = 0.04 from axis 1, in the mid-plane 0.05 above shaft 1's point
  expect_newton_euler({"radii: [0.04, 0.08], helix_angle: 0.3, mesh_offset: 0.05", {0.04, 0, 0.05}, false, 0.3, -0.5});
  // the same by tooth counts (radii from the centre distance), left-handed
  expect_newton_euler({"teeth: [20, 40], helix_angle: -0.3, mesh_offset: 0.05", {0.04, 0, 0.05}, false, -0.3, -0.5});
  // internal, the pinion first: P beyond it, away from the ring's axis; the shafts turn the same way
  expect_newton_euler({"radii: [0.04, 0.16], reversed: true, helix_angle: 0.3", {-0.04, 0, 0}, false, 0.3, 0.25});
  expect_newton_euler({"teeth: [20, 80], reversed: true, mesh_offset: -0.02", {-0.04, 0, -0.02}, false, 0.0, 0.25});
  // internal, the ring first (its axis at the origin, the pinion's 0.12 off): P beyond the pinion
  expect_newton_euler({"radii: [0.16, 0.04], reversed: true, helix_angle: 0.2", {0.16, 0, 0}, true, 0.2, 4.0});
}

// Radii that do not span the axes, pitch radii out of the teeth's ratio, and an internal pair of equal gears are
// told at the first row, the bearings carrying only the shafts' torques.
TEST(HelicalMeshes, PushesThatCannotBePlacedAreTold) {
  for (const auto& [mesh, words] : std::vector<std::pair<std::string, std::string>>{
           {"radii: [0.04, 0.09]", "do not stand its two pitch radii apart"},
           {"radii: [0.04, 0.06], reversed: true", "the difference of its pitch radii"},
           {"teeth: [20, 40], pitch_radii: [0.04, 0.09]", "not in its teeth's ratio"},
           {"teeth: [20, 20], reversed: true", "internal pair of equal gears"}}) {
    SweepSummary sum;
    test::sweep_reactions(parallel_pair(mesh), &sum);
    ASSERT_EQ(sum.warnings.size(), 1u) << mesh;
    EXPECT_EQ(sum.warnings[0].kind, "unloaded_bearings");
    EXPECT_HAS(sum.warnings[0].message, words);
    EXPECT_HAS(sum.warnings[0].message, "'mesh'");
  }
}

// The derived parts draw the pair's pitch circles in its mid-plane, of radii that fill the distance between the
// axes in the teeth's ratio: two discs for an external pair; for an internal one the ring gear as a ring (a closed
// polyline about its axis).
TEST(HelicalMeshes, ParallelShaftsDrawTheirPitchCirclesInTheMidPlane) {
  auto pitch_circle = [](const std::vector<Part>& parts, const std::string& body) -> const Shape* {
    for (const Part& p : parts)
      if (p.name == body)
        for (const Shape& s : p.shapes)
          if (s.name == "mesh.pitch_circle") return &s;
    return nullptr;
  };
  const std::vector<Part> external = drawn_parts(parallel_pair("teeth: [20, 40], mesh_offset: 0.05", false));
  const Shape *g1 = pitch_circle(external, "input_shaft"), *g2 = pitch_circle(external, "output_shaft");
  ASSERT_TRUE(g1 && g2);
  EXPECT_NEAR(g1->radius, 0.04, 1e-15);
  EXPECT_NEAR(g2->radius, 0.08, 1e-15);
  for (const Shape* g : {g1, g2}) {  // each about its shaft's reference point, on its axis, 0.05 up
    EXPECT_NEAR(std::hypot(g->at.x, g->at.y), 0.0, 1e-15);
    EXPECT_NEAR(g->at.z, 0.05, 1e-15);
  }
  const std::vector<Part> internal = drawn_parts(parallel_pair("teeth: [20, 80], reversed: true", false));
  const Shape *pinion = pitch_circle(internal, "input_shaft"), *ring = pitch_circle(internal, "output_shaft");
  ASSERT_TRUE(pinion && ring);
  EXPECT_NEAR(pinion->radius, 0.04, 1e-15);
  ASSERT_EQ(ring->kind, ShapeKind::kCurve);
  EXPECT_TRUE(ring->closed);
  ASSERT_GT(ring->points.size(), 100u);
  for (const kin3::V3& v : ring->points) EXPECT_NEAR(std::hypot(v.x + ring->at.x, v.y + ring->at.y), 0.16, 1e-12);
}

}  // namespace
}  // namespace phiq
