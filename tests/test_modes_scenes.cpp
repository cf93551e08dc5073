// Every assembly mode of the scenes with gears and spatial joint-angle drivers (phiq/modes.hpp): the planetary
// train's one assembly at Willis' carrier angle, the RSSR linkage's eight and the Cardan joint's eight against their
// geometry, a wheel geared to a four-bar's coupler against Freudenstein's closed form, each mode on the model's own
// Φ = 0 to 1e-10, the geared system side by side with PHCpack (skipped, with the reason, when phc is absent), a
// rack whose pinion a linkage turns refused with its constraint named, and a triple root of one unknown singular.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "modes_phc.hpp"
#include "phiq/phiq.hpp"

namespace phiq {
namespace {

std::string modes_scenes_path(const std::string& rel) { return std::string(PHIQ_MODELS_DIR) + "/" + rel; }

// The rotation of a body's Euler parameters (e0, e1, e2, e3) (any norm: normalised here) applied to v.
Eigen::Vector3d modes_scenes_rotate(const Model& model, const Eigen::VectorXd& q, const std::string& body,
                                    const Eigen::Vector3d& v) {
  auto at = [&](const char* k) { return q(model.coordinate_index(body + "_" + k)); };
  const Eigen::Quaterniond e(at("e0"), at("e1"), at("e2"), at("e3"));
  return e.normalized() * v;
}

Eigen::Vector3d modes_scenes_position(const Model& model, const Eigen::VectorXd& q, const std::string& body) {
  auto at = [&](const char* k) { return q(model.coordinate_index(body + "_" + k)); };
  return {at("x"), at("y"), at("z")};
}

TEST(ModesScenes, PlanetaryTrainHasOneAssemblyAtWillisCarrierAngle) {
  const Scene scene = load_scene(modes_scenes_path("transmissions/planetary.yaml"));
  const Model& model = *scene.model;
  ModesOptions o;
  o.time = 0.7;  // the sun at 0.7 rad, the ring at −0.14 rad
  const AssemblyModes r = find_assembly_modes(model, o);
  ASSERT_EQ(r.summary.status, ModesStatus::kSuccess) << r.summary.message;
  // the gears are linear in the angles: the driven sun and ring fix the carrier and the planet, the pin the rest
  EXPECT_EQ(r.polynomials.system.variables, 0);
  ASSERT_EQ(r.modes.size(), 1u);
  const Eigen::VectorXd& q = r.modes[0].q;
  const double sun = 0.7, ring = -0.2 * 0.7, carrier = (24.0 * sun + 60.0 * ring) / 84.0;  // Willis
  const double planet = carrier - 24.0 / 18.0 * (sun - carrier);                           // the sun's mesh
  EXPECT_NEAR(q(model.coordinate_index("psic")), carrier, 1e-14);
  EXPECT_NEAR(q(model.coordinate_index("psip")), planet, 1e-14);
  EXPECT_NEAR((q(model.coordinate_index("psip")) - carrier) * 18.0, (ring - carrier) * 60.0, 1e-13);  // the ring's
  const double arm = 0.004 * (24 + 18) / 2.0;
  EXPECT_NEAR(q(model.coordinate_index("xp")), arm * std::cos(carrier), 1e-15);
  EXPECT_NEAR(q(model.coordinate_index("yp")), arm * std::sin(carrier), 1e-15);
  EXPECT_LT(r.modes[0].residual, 1e-10);
}

// A spatial revolute holds the two axes parallel by two dot products: they may also be opposite, a body mounted
// upside down on its pin. The RSSR's crank (its x axis fixed by the driver) is up or down, its rocker up or down
// and at ±φ, the rocker's angle from the coupler's length (the mirror image in the crank's plane): eight
// assemblies, each found once (±e merged).
TEST(ModesScenes, RssrHasEightAssembliesAsItsClosedForm) {
  const Scene scene = load_scene(modes_scenes_path("spatial/rssr.yaml"));
  const Model& model = *scene.model;
  const double a = 0.2, b = 0.5, d = 0.5, e = 0.6, L = 0.92, theta = 0.4;
  ModesOptions o;
  o.time = theta;  // the crank's angle
  const AssemblyModes r = find_assembly_modes(model, o);
  ASSERT_EQ(r.summary.status, ModesStatus::kSuccess) << r.summary.message;
  ASSERT_EQ(r.modes.size(), 8u);
  auto rocker_cosine = [&](double crank) {
    return (L * L - std::pow(d - a * std::cos(crank), 2) - std::pow(e - a * std::sin(crank), 2) - b * b) /
           (2.0 * b * (e - a * std::sin(crank)));
  };
  const double phi = std::acos(rocker_cosine(theta));
  std::array<int, 8> hits{};
  for (const AssemblyMode& m : r.modes) {
    EXPECT_LT(m.residual, 1e-10);
    const Eigen::Vector3d A = modes_scenes_rotate(model, m.q, "crank", {a, 0, 0});
    EXPECT_LT((A - Eigen::Vector3d(a * std::cos(theta), a * std::sin(theta), 0)).norm(), 1e-12);
    const Eigen::Vector3d crank_z = modes_scenes_rotate(model, m.q, "crank", {0, 0, 1});
    const Eigen::Vector3d rocker_x = modes_scenes_rotate(model, m.q, "rocker", {1, 0, 0});
    const Eigen::Vector3d B =
        modes_scenes_position(model, m.q, "rocker") + modes_scenes_rotate(model, m.q, "rocker", {0, b, 0});
    for (int k = 0; k < 8; ++k) {
      const double sign_phi = k & 1 ? -1.0 : 1.0, up = k & 2 ? -1.0 : 1.0, rocker_up = k & 4 ? -1.0 : 1.0;
      const Eigen::Vector3d expected_b(d, e + b * std::cos(phi), sign_phi * b * std::sin(phi));
      hits[static_cast<std::size_t>(k)] += (B - expected_b).norm() < 1e-12 &&
                                           (crank_z - Eigen::Vector3d(0, 0, up)).norm() < 1e-12 &&
                                           (rocker_x - Eigen::Vector3d(rocker_up, 0, 0)).norm() < 1e-12;
    }
  }
  EXPECT_EQ(hits, (std::array<int, 8>{1, 1, 1, 1, 1, 1, 1, 1}));
  // the driver's polynomial form s cos f − c sin f also vanishes at θ + π, where the coupler closes too
  // (|cos φ| < 1): eight more placements of the same kinds, not assemblies
  ASSERT_LT(std::abs(rocker_cosine(theta + std::numbers::pi)), 1.0);
  EXPECT_EQ(r.rejected, 8);
  // solved block by block: the crank's four equations in its Euler parameters (2⁴ paths) have four real solutions
  // of one sign (up or down, at θ or θ + π), and the rocker's (three quadrics and the coupler's quartic) 32 paths
  // each, 16 with the quartic lowered (ModesOptions::lower_degrees)
  EXPECT_EQ(r.summary.total_degree, 16 + 4 * 32);
  EXPECT_EQ(r.summary.paths, 16 + 4 * 16);
}

TEST(ModesScenes, CardanJointHasEightAssembliesTheCrossTwoWaysTheShaftsUpOrDown) {
  const Scene scene = load_scene(modes_scenes_path("spatial/cardan.yaml"));
  const Model& model = *scene.model;
  const double beta = std::numbers::pi / 6.0, theta = 0.3;
  ModesOptions o;
  o.time = theta;  // the input shaft's angle (W = 1)
  const AssemblyModes r = find_assembly_modes(model, o);
  ASSERT_EQ(r.summary.status, ModesStatus::kSuccess) << r.summary.message;
  ASSERT_EQ(r.modes.size(), 8u);
  // the input shaft's fork x1 at θ, its axis up or down (its hinge's axes parallel or opposite); the output shaft's
  // axis ±a2 (its point (0, 0, 1) on the line along a2), its fork ⊥ both it and the input fork: ±(a2 × x1)
  const Eigen::Vector3d a2(std::sin(beta), 0, std::cos(beta)), x1(std::cos(theta), std::sin(theta), 0);
  std::array<int, 8> hits{};
  for (const AssemblyMode& m : r.modes) {
    EXPECT_LT(m.residual, 1e-10);
    EXPECT_LT((modes_scenes_rotate(model, m.q, "s1", {1, 0, 0}) - x1).norm(), 1e-12);
    EXPECT_LT(modes_scenes_position(model, m.q, "s2").norm(), 1e-12);
    const Eigen::Vector3d z1 = modes_scenes_rotate(model, m.q, "s1", {0, 0, 1});
    const Eigen::Vector3d z2 = modes_scenes_rotate(model, m.q, "s2", {0, 0, 1});
    const Eigen::Vector3d y2 = modes_scenes_rotate(model, m.q, "s2", {0, 1, 0});
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d z = (k & 1 ? -1.0 : 1.0) * a2, y = (k & 2 ? -1.0 : 1.0) * z.cross(x1).normalized();
      const Eigen::Vector3d up(0, 0, k & 4 ? -1.0 : 1.0);
      hits[static_cast<std::size_t>(k)] +=
          (z2 - z).norm() < 1e-12 && (y2 - y).norm() < 1e-12 && (z1 - up).norm() < 1e-12;
    }
  }
  EXPECT_EQ(hits, (std::array<int, 8>{1, 1, 1, 1, 1, 1, 1, 1}));
  EXPECT_EQ(r.rejected, 8);  // the input shaft at θ + π: the driver's polynomial form only
  // block by block: the input shaft's four quadrics (16 paths, four real of one sign), the output shaft's four (16
  // paths for each)
  EXPECT_EQ(r.summary.paths, 16 + 4 * 16);
}

// The four-bar of seed/fourbar_mixed.yaml with a wheel w geared to its coupler (20 teeth on the coupler, 30 on the
// wheel): ψ3 + (30/20) w = 0, a relation between two angles the linkage turns, solved modulo 2π as
// (c3 + i s3)² (cw + i sw)³ = 1. Each of the loop's two assemblies (Freudenstein's θ4) takes the wheel in three
// places, w = (2πk − 2ψ3)/3: six assemblies, the gear's own row holding exactly with whole turns of the angles.
const char* const kModesScenesGearedFourBar = R"(phiq: 1
name: geared_fourbar
parameters: {L1: 1.0, L2: 0.4, L3: 1.2, L4: 1.0}
coordinates: {theta2: 0.0, xA: 0.4, yA: 0.0, x3: 0.7, y3: 0.5, psi3: 1.0, xB: 1.1, yB: 1.0, w: -0.6}
points: {O: [0, 0], A: [xA, yA], B: [xB, yB], C: [L1, 0]}
bodies: {coupler: [x3, y3, psi3]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}
  - {name: A, type: revolute, between: [{body: coupler, at: [-L3/2, 0]}, {point: A}]}
  - {name: B, type: revolute, between: [{body: coupler, at: [L3/2, 0]}, {point: B}]}
  - {name: rocker, type: distance, points: [C, B], length: L4}
  - {name: wheel, type: gear, between: [psi3, w], teeth: [20, 30]}
drivers:
  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 1}}
time: {start: 0, end: 1, steps: 1}
)";

TEST(ModesScenes, AWheelGearedToAFourBarsCouplerTakesThreePlacesPerAssembly) {
  const Scene scene = parse_scene(kModesScenesGearedFourBar, "geared_fourbar.yaml");
  const Model& model = *scene.model;
  const double theta2 = 0.7;
  ModesOptions o;
  o.time = theta2;
  const AssemblyModes r = find_assembly_modes(model, o);
  ASSERT_EQ(r.summary.status, ModesStatus::kSuccess) << r.summary.message;
  ASSERT_EQ(r.polynomials.angle_relations.size(), 1u);
  EXPECT_EQ(r.polynomials.angle_relations[0].multiples, (std::vector<int>{2, 3}));
  ASSERT_EQ(r.modes.size(), 6u);
  // Freudenstein's two rocker angles (crank a = 0.4, coupler b = 1.2, rocker c = 1, ground d = 1)
  const double a = 0.4, b = 1.2, c = 1.0, d = 1.0;
  const double k1 = d / a, k2 = d / c, k3 = (a * a - b * b + c * c + d * d) / (2.0 * a * c);
  const double fa = std::cos(theta2) - k1 - k2 * std::cos(theta2) + k3, fb = -2.0 * std::sin(theta2),
               fc = k1 - (k2 + 1.0) * std::cos(theta2) + k3, root = std::sqrt(fb * fb - 4.0 * fa * fc);
  const double xa = a * std::cos(theta2), ya = a * std::sin(theta2);
  std::array<int, 6> hits{};
  for (const AssemblyMode& m : r.modes) {
    EXPECT_LT(m.residual, 1e-10);
    for (int loop = 0; loop < 2; ++loop) {
      const double theta4 = 2.0 * std::atan2(-fb + (loop ? -root : root), 2.0 * fa);
      const double xb = d + c * std::cos(theta4), yb = c * std::sin(theta4), psi3 = std::atan2(yb - ya, xb - xa);
      if (std::hypot(m.q(model.coordinate_index("xB")) - xb, m.q(model.coordinate_index("yB")) - yb) > 1e-10) continue;
      EXPECT_NEAR(std::remainder(m.q(model.coordinate_index("psi3")) - psi3, 2.0 * std::numbers::pi), 0.0, 1e-10);
      for (int k = 0; k < 3; ++k) {
        const double w = (2.0 * std::numbers::pi * k - 2.0 * psi3) / 3.0;
        hits[static_cast<std::size_t>(3 * loop + k)] +=
            std::abs(std::remainder(m.q(model.coordinate_index("w")) - w, 2.0 * std::numbers::pi)) < 1e-10;
      }
    }
  }
  EXPECT_EQ(hits, (std::array<int, 6>{1, 1, 1, 1, 1, 1}));
}

// A crank-slider whose slider is a rack turning a pinion: the pinion's angle is the slider's travel over its radius,
// and the travel enters the loop as a length, the crank through (c, s): no polynomial in (c, s) of the pinion holds
// the rack's row. Refused, the constraint named; without the rack the same scene has its two modes.
TEST(ModesScenes, ARackOnALinkageIsRefusedWithItsConstraintNamed) {
  const std::string scene_text = R"(phiq: 1
name: rack_on_slider
parameters: {L2: 0.3, L3: 1.0}
coordinates: {theta2: 0.0, xA: 0.28, yA: 0.03, xB: 1.25, psi: 0.0}
points: {O: [0, 0], A: [xA, yA], B: [xB, 0]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}
  - {name: rod, type: distance, points: [A, B], length: L3}
  - {name: mesh, type: rack_pinion, rack: xB, pinion: psi, radius: 0.1}
drivers:
  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 2}}
time: {start: 0, end: 1, steps: 1}
)";
  const Scene scene = parse_scene(scene_text, "rack_on_slider.yaml");
  const AssemblyModes r = find_assembly_modes(*scene.model, {});
  EXPECT_EQ(r.summary.status, ModesStatus::kNotPolynomial);
  EXPECT_NE(r.summary.message.find("constraint 'mesh' is not polynomial"), std::string::npos) << r.summary.message;
  EXPECT_TRUE(r.modes.empty());
}

// The geared four-bar's system, its complex multiple-angle equation among them, solved by PHCpack too: the same
// finite regular solutions, the same real ones. (The spatial scenes' systems take phc 20 s: their counts are
// checked against their geometry above.)
// A multiple root of one equation in one unknown, (x − 1)³ = 0 (y fixed by its own row): its three paths meet at
// x = 1, where the derivative 3 (x − 1)² vanishes. A 1 × 1 Jacobian's σ_max / σ_min is 1 however small it is: the
// mode is singular by its smallest singular value against the equation's scale, one endpoint of multiplicity 3, not
// a regular one reached three times.
TEST(ModesScenes, ATripleRootInOneUnknownIsOneSingularModeOfThreePaths) {
  const Scene scene = parse_scene(
      "phiq: 1\ncoordinates: {x: 0.5, y: 1.0}\nconstraints:\n"
      "  - {name: triple, type: equation, expr: \"(x - 1)^3\"}\n"
      "  - {name: level, type: equation, expr: \"y - 2\"}\ntime: {start: 0, end: 0, steps: 0}\n",
      "triple.yaml");
  ModesOptions o;
  o.threads = 1;
  const AssemblyModes r = find_assembly_modes(*scene.model, o);
  ASSERT_EQ(r.summary.status, ModesStatus::kSuccess) << r.summary.message;
  EXPECT_EQ(r.summary.paths, 3);
  EXPECT_EQ(r.summary.singular, 1);
  EXPECT_EQ(r.summary.real + r.summary.complex + r.summary.failed_paths + r.summary.duplicate_paths, 0);
  ASSERT_EQ(r.summary.endpoints.size(), 1u);
  EXPECT_EQ(r.summary.endpoints[0].multiplicity, 3);
  EXPECT_GT(r.summary.endpoints[0].condition, o.singular_condition);
  ASSERT_EQ(r.modes.size(), 1u);
  EXPECT_TRUE(r.modes[0].singular);
  EXPECT_NEAR(r.modes[0].q(scene.model->coordinate_index("x")), 1.0, 1e-6);  // (a triple root: to ε^(1/3))
  EXPECT_EQ(r.modes[0].q(scene.model->coordinate_index("y")), 2.0);
}

TEST(ModesScenes, GearedFourBarAsPhcSolvesIt) {
  if (!modes_phc::phc_installed()) GTEST_SKIP() << "phc (Debian package phcpack) is not installed";
  const Scene scene = parse_scene(kModesScenesGearedFourBar, "geared_fourbar.yaml");
  ModesOptions o;
  o.time = 0.7;
  const AssemblyModes r = find_assembly_modes(*scene.model, o);
  ASSERT_EQ(r.summary.status, ModesStatus::kSuccess) << r.summary.message;
  modes_phc::modes_expect_same_as_phc(r.polynomials.system, r.summary);
}

}  // namespace
}  // namespace phiq
