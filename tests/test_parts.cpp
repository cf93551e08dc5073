// Parts on bodies (phiq/parts.hpp, the scene's `parts` section): a part's frame follows its body in every coordinate
// family, exactly; the four four-bars of the notes carry one coupler that is the same part in the world; the
// mass a part states or takes from its density; and bad parts refused in one line naming the file and the field.
#include <gtest/gtest.h>

#include <cmath>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// A scene file's text without its own `parts` section (cardan.yaml's; its last): each test appends its own.
std::string text_before_parts(const std::string& path) {
  const std::string text = test::file_text(path);
  return text.substr(0, text.find("\nparts:\n"));
}

// A seed scene's text with a `parts` section appended.
Scene seed_with_parts(const std::string& name, const std::string& parts) {
  return parse_scene(text_before_parts(test::model_path("seed/" + name)) + "\nparts:\n" + parts, "seed_" + name);
}

const Part& part_named(const Scene& s, const std::string& name) {
  for (const Part& p : s.parts)
    if (p.name == name) return p;
  throw std::runtime_error("no part " + name);
}

double distance(kin3::V3 a, kin3::V3 b) { return kin3::norm(a - b); }

// The rotation's columns are orthonormal and right-handed.
double orthonormality_error(const RotationMatrix& r) {
  double worst = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double d = 0.0;
      for (int k = 0; k < 3; ++k) d += r[3 * k + i] * r[3 * k + j];
      worst = std::max(worst, std::fabs(d - (i == j ? 1.0 : 0.0)));
    }
  const double det =
      r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6]) + r[2] * (r[3] * r[7] - r[4] * r[6]);
  return std::max(worst, std::fabs(det - 1.0));
}

// The coupler A→B of the notes' four-bar as a part in each coordinate family: in relative coordinates a frame of
// expressions (A = L2 (cos ψ2, sin ψ2), angle ψ2 + ψ3), in natural ones a frame of points (origin A, x toward B), in
// reference-point and mixed ones the body `coupler` (centred: A is at x = −L3/2). The world positions of its two
// ends agree across the families, and each frame is exact in its own family.
TEST(PartFrames, TheCouplerIsOnePartInAllFourCoordinateFamilies) {
  const std::string relative = "  coupler: {frame: {at: [L2*cos(psi2), L2*sin(psi2)], angle: psi2 + psi3}}\n";
  const std::string natural = "  coupler: {frame: {origin: A, x: B}}\n";
  const std::string body = "  coupler: {}\n";
  const char* forms[] = {"relative", "natural", "reference_point", "mixed"};
  const std::string parts[] = {relative, natural, body, body};
  const double L2 = 0.4, L3 = 1.2;
  std::vector<test::Trace> traces(4);
  std::vector<Scene> scenes;
  for (int f = 0; f < 4; ++f) {
    scenes.push_back(seed_with_parts(std::string("fourbar_") + forms[f] + ".yaml", parts[f]));
    ASSERT_EQ(test::sweep(*scenes[f].model, scenes[f].sweep, &traces[f]), SolveStatus::kSuccess) << forms[f];
  }
  // the coupler's ends in its own frame: A, B (frames at A) or −L3/2, +L3/2 (the centred body)
  auto ends = [&](int f, const Eigen::VectorXd& q, double t) {
    const Pose p = part_pose(part_named(scenes[f], "coupler").frame, q.data(), t);
    const double a = f < 2 ? 0.0 : -L3 / 2;
    return std::pair{p.apply({a, 0, 0}), p.apply({a + L3, 0, 0})};
  };
  double across = 0.0, own = 0.0;
  for (std::size_t k = 0; k < traces[0].t.size(); ++k) {
    const double t = traces[0].t[k];
    const auto [a0, b0] = ends(0, traces[0].q[k], t);
    for (int f = 1; f < 4; ++f) {
      const auto [a, b] = ends(f, traces[f].q[k], t);
      across = std::max({across, distance(a, a0), distance(b, b0)});
    }
    // relative: A and B of the loop's closed form in its own coordinates
    const Model& mr = *scenes[0].model;
    const Eigen::VectorXd& qr = traces[0].q[k];
    const double p2 = qr(mr.coordinate_index("psi2")), p23 = p2 + qr(mr.coordinate_index("psi3"));
    own = std::max(own,
                   distance(b0, {L2 * std::cos(p2) + L3 * std::cos(p23), L2 * std::sin(p2) + L3 * std::sin(p23), 0}));
    // natural: the frame's origin is A and its x axis runs through B, which the distance constraint keeps at L3
    const Model& mn = *scenes[1].model;
    const Eigen::VectorXd& qn = traces[1].q[k];
    const auto [an, bn] = ends(1, qn, t);
    own = std::max(own, distance(an, {qn(mn.coordinate_index("xA")), qn(mn.coordinate_index("yA")), 0}));
    const kin3::V3 B{qn(mn.coordinate_index("xB")), qn(mn.coordinate_index("yB")), 0};
    own = std::max(own, kin3::norm(kin3::cross((1.0 / L3) * (bn - an), (1.0 / kin3::norm(B - an)) * (B - an))));
    // reference point: the part's point is the body point the revolute joints use
    const PointMotion pb = evaluate_point(planar_body_point("B", scenes[2].planar_bodies[1], L3 / 2, 0.0),
                                          traces[2].q[k].data(), nullptr, nullptr);
    own = std::max(own, distance(ends(2, traces[2].q[k], t).second, {pb.r[0], pb.r[1], 0}));
  }
  EXPECT_LT(across, 1e-9);  // four solutions of one mechanism, each to the solver's tolerance
  EXPECT_LT(own, 1e-12);    // each frame is exact in its own coordinates
}

// A spatial body's part: its pose is R(e) and r, the point a joint uses is pose.apply of it, the rotation
// orthonormal; a frame of natural points and a vector in space has x along the points and y in their plane.
TEST(PartFrames, SpatialBodiesAndNaturalFramesFollowTheirCoordinates) {
  Scene cardan = parse_scene(text_before_parts(test::model_path("spatial/cardan.yaml")) +
                                 "\nparts:\n  s2: {shapes: [{type: cylinder, radius: 0.02, length: 1.0}]}\n",
                             "cardan.yaml");
  test::Trace tr;
  ASSERT_EQ(test::sweep(*cardan.model, cardan.sweep, &tr), SolveStatus::kSuccess);
  // the pose is r + R(e/|e|) s: a rotation, where the joints' R(e) is scaled by |e|², within the normalisation
  // constraint's tolerance of 1
  double exact = 0.0, joints = 0.0;
  const Model& mc = *cardan.model;
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    const Eigen::VectorXd& q = tr.q[k];
    const Pose p = part_pose(part_named(cardan, "s2").frame, q.data(), tr.t[k]);
    const kin3::V3 s{0.1, -0.2, 0.7};
    double e[4] = {q(mc.coordinate_index("s2_e0")), q(mc.coordinate_index("s2_e1")), q(mc.coordinate_index("s2_e2")),
                   q(mc.coordinate_index("s2_e3"))};
    const double n = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3]);
    for (double& x : e) x /= n;
    const kin3::V3 r{q(mc.coordinate_index("s2_x")), q(mc.coordinate_index("s2_y")), q(mc.coordinate_index("s2_z"))};
    exact = std::max({exact, distance(p.apply(s), r + kin3::rotate(e, s)), orthonormality_error(p.rotation)});
    const PointMotion m =
        evaluate_point(spatial_body_point("P", cardan.spatial_bodies[1], s), q.data(), nullptr, nullptr);
    joints = std::max(joints, distance(p.apply(s), {m.r[0], m.r[1], m.r[2]}));
  }
  EXPECT_LT(exact, 1e-13);  // two ways of rounding one rotation
  EXPECT_LT(joints, 1e-9);

  // rssr_natural: the coupler A→B, y toward the rocker pivot C
  Scene rssr = parse_scene(text_before_parts(test::model_path("spatial/rssr_natural.yaml")) +
                               "\nparts:\n  coupler: {frame: {origin: A, x: B, y: C}}\n",
                           "rssr_natural.yaml");
  tr = {};
  ASSERT_EQ(test::sweep(*rssr.model, rssr.sweep, &tr), SolveStatus::kSuccess);
  const Model& m = *rssr.model;
  double along = 0.0, in_plane = 0.0, ortho = 0.0;
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    const Eigen::VectorXd& q = tr.q[k];
    const kin3::V3 A{q(m.coordinate_index("xA")), q(m.coordinate_index("yA")), 0.0};
    const kin3::V3 B{0.5, q(m.coordinate_index("yB")), q(m.coordinate_index("zB"))}, C{0.5, 0.6, 0.0};
    const Pose p = part_pose(part_named(rssr, "coupler").frame, q.data(), tr.t[k]);
    along = std::max({along, distance(p.apply({0, 0, 0}), A), distance(p.apply({0.92, 0, 0}), B)});
    // C lies in the frame's x–y plane, on its +y side
    const kin3::V3 z{p.rotation[2], p.rotation[5], p.rotation[8]}, y{p.rotation[1], p.rotation[4], p.rotation[7]};
    in_plane = std::max(in_plane, std::fabs(kin3::dot(C - A, z)));
    EXPECT_GT(kin3::dot(C - A, y), 0.0);
    ortho = std::max(ortho, orthonormality_error(p.rotation));
  }
  EXPECT_LT(along, 1e-9);  // B at the coupler's length: the distance constraint's tolerance
  EXPECT_LT(in_plane, 1e-12);
  EXPECT_LT(ortho, 1e-12);
}

// Mass stated, from a density, and completed from the shapes.
TEST(PartMass, StatedDensityAndCompletedFromShapes) {
  const Scene s =
      seed_with_parts("fourbar_reference_point.yaml",
                      "  crank: {mass: 2.0, center_of_mass: [0.01, 0], inertia: 0.03}\n"
                      "  coupler: {density: 7850, shapes: [{type: box, size: [1.2, 0.04, 0.01]}]}\n"
                      "  rocker: {mass: 3.0, shapes: [{type: box, size: [1.0, 0.05, 0.02], at: [0.1, 0]}]}\n");
  const Part& crank = part_named(s, "crank");
  EXPECT_EQ(crank.mass_source, MassSource::kStated);
  EXPECT_EQ(crank.mass.mass, 2.0);
  EXPECT_EQ(crank.mass.center.x, 0.01);
  EXPECT_EQ(crank.mass.inertia[8], 0.03);
  const Part& coupler = part_named(s, "coupler");
  EXPECT_EQ(coupler.mass_source, MassSource::kDensity);
  const double m = 7850 * 1.2 * 0.04 * 0.01;
  EXPECT_NEAR(coupler.mass.mass, m, 1e-12 * m);
  EXPECT_NEAR(coupler.mass.inertia[8], m * (1.2 * 1.2 + 0.04 * 0.04) / 12, 1e-12 * m);
  // the rocker's mass is stated; its centre and inertia are its box's at the density that gives that mass
  const Part& rocker = part_named(s, "rocker");
  EXPECT_EQ(rocker.mass.mass, 3.0);
  EXPECT_NEAR(rocker.mass.center.x, 0.1, 1e-15);
  EXPECT_NEAR(rocker.mass.inertia[8], 3.0 * (1.0 + 0.05 * 0.05) / 12, 1e-14);
  EXPECT_NEAR(rocker.mass.inertia[0], 3.0 * (0.05 * 0.05 + 0.02 * 0.02) / 12, 1e-14);
}

TEST(PartMass, ASpatialInertiaIsAFullTensor) {
  const std::string text = text_before_parts(test::model_path("spatial/cardan.yaml")) + "\nparts:\n  s1: {mass: 1.5, " +
                           "center_of_mass: [0, 0, 0.5], inertia: [[0.2, 0.01, 0], [0.01, 0.3, 0], [0, 0, 0.4]]}\n";
  const Scene s = parse_scene(text, "cardan.yaml");
  const Part& p = part_named(s, "s1");
  EXPECT_EQ(p.mass.inertia[1], 0.01);
  EXPECT_EQ(p.mass.inertia[3], 0.01);
  EXPECT_EQ(p.mass.inertia[8], 0.4);
  EXPECT_EQ(p.mass.center.z, 0.5);
}

TEST(PartErrors, EachIsOneLineNamingTheFileThePartAndTheField) {
  const std::string base = text_before_parts(test::model_path("seed/fourbar_reference_point.yaml")) + "\nparts:\n";
  const std::string spatial = text_before_parts(test::model_path("spatial/cardan.yaml")) + "\nparts:\n";
  struct Case {
    std::string parts, where, says;
    bool in_space = false;
  };
  const Case cases[] = {
      {"  crank: {shapes: [{type: torus, radius: 1}]}", "parts.crank.shapes[0].type", "unknown shape type 'torus'"},
      {"  crank: {shapes: [{type: box, size: [1, -0.1, 0.1]}]}", "parts.crank.shapes[0].size[1]", "positive"},
      {"  crank: {shapes: [{type: sphere, radius: 0.1, height: 2}]}", "parts.crank.shapes[0].height", "unknown field"},
      {"  crank: {shapes: [{type: mesh, file: no_such.stl}]}", "parts.crank.shapes[0].file", "no_such.stl"},
      {"  crank: {mass: 1, inertia: -0.5}", "parts.crank.inertia", "positive"},
      {"  crank: {center_of_mass: [0, 0]}", "parts.crank.center_of_mass", "needs the part's `mass`"},
      {"  crank: {mass: 1, density: 7800}", "parts.crank.density", "not both"},
      {"  crank: {mass: 1}", "parts.crank.center_of_mass", "no solid shape"},
      {"  crank: {density: 7800}", "parts.crank.density", "no solid shape"},
      {"  handle: {shapes: []}", "parts.handle", "'handle' is no body"},
      {"  crank: {body: nowhere}", "parts.crank.body", "unknown body 'nowhere'"},
      {"  crank: {frame: {origin: A, x: B}}", "parts.crank.frame.origin", "unknown point 'A'"},
      {"  crank: {colour: [1, 0, 2]}", "parts.crank.colour[2]", "from 0 to 1"},
      {"  s1: {mass: 1, center_of_mass: [0, 0, 0], inertia: [1, 1, -1]}", "parts.s1.inertia", "not positive definite",
       true},
      {"  s1: {mass: 1, center_of_mass: [0, 0, 0], inertia: [1, 1, 3]}", "parts.s1.inertia", "sum of the other two",
       true},
      {"  s1: {mass: 1, center_of_mass: [0, 0, 0], inertia: [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]}", "parts.s1.inertia",
       "not symmetric", true},
  };
  for (const Case& c : cases) {
    const std::string m = test::scene_error((c.in_space ? spatial : base) + c.parts + "\n");
    EXPECT_HAS(m, c.where + ":");
    EXPECT_HAS(m, c.says);
  }
}

}  // namespace
}  // namespace phiq
