// Gear meshes in joint reactions (add_gear_mesh_forces(), phiq/joint_reactions.hpp): a gear's row relates angles,
// yet the bearings under its gears carry the push of its teeth. Each gear here is checked by Newton–Euler written
// in the test: the two-stage train's pivots (fixed centres, the motor's torque and the gears' inertia) and the
// planetary's sun, ring and planet under gravity with a turning carrier (the planet's centre accelerating, the
// internal mesh); three planets sharing a train's load, redundant, equally (minimum norm, by symmetry) and named
// indeterminate; a rack's teeth on its pinion's pivot and its guide. The drivers' efforts are the bits they are
// without the reactions.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>

#include "phiq/phiq.hpp"
#include "reaction_rows.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

using test::ReactionRows;

// The rows of `s`, whose output finds `meshes` gears or racks between bodies.
ReactionRows sweep_meshes(const Scene& s, std::size_t meshes, SweepSummary* sum = nullptr,
                          const Model** swept = nullptr) {
  EXPECT_EQ(s.sweep.efforts.meshes.size(), meshes);
  return test::sweep_reactions(s, sum, swept);
}

// `scene` (a model's text without its output) with `parts` (a YAML map's lines), gravity if asked, and the output
// of the efforts and, if asked, every reaction.
Scene with_reactions(const std::string& scene, const std::string& parts, bool gravity, bool reactions = true) {
  return parse_scene(scene + "parts:\n" + parts + (gravity ? "loads: {gravity: [0, -9.81]}\n" : "") +
                         "output: {velocities: true, accelerations: true, efforts: all" +
                         (reactions ? ", reactions: all}\n" : "}\n"),
                     "meshes.yaml");
}

using V2 = Eigen::Vector2d;
V2 perp(const V2& u) { return {-u.y(), u.x()}; }  // ẑ × u

// models/transmissions/gear_train.yaml with a mass and inertia on each gear (centres on the pivots, no gravity).
// The input gear turns under the motor's τ and the first mesh's push F1 at its pitch point (radius ρ1 = 0.03, on
// the line to the countershaft, along +x): I1 ψ̈1 = τ + ρ1 F1y, and the teeth's 20° pressure angle parts the gears
// by |F1y| tan 20° along that line, so its pivot holds it by −F1 = (|F1y| tan 20°, (τ − I1 ψ̈1)/ρ1). The output gear
// (ρ = 0.1125, the countershaft below it along −y) turns by the second mesh alone: I3 ψ̈3 = ρ F2x, and is parted
// upward by |F2x| tan 20°; its pivot holds −F2. The countershaft's pivot holds F1 + F2, the reactions of both.
TEST(GearMeshes, ATrainsPivotsCarryItsTeethsPushByNewtonEuler) {
  const std::string train = test::model_file_text("transmissions/gear_train.yaml", "\noutput:") + "\n";
  const std::string parts =
      "  input: {mass: 0.1, center_of_mass: [0, 0], inertia: 1e-4}\n"
      "  countershaft: {mass: 0.5, center_of_mass: [0, 0], inertia: 2e-3}\n"
      "  output: {mass: 0.8, center_of_mass: [0, 0], inertia: 5e-3}\n";
  const Scene s = with_reactions(train, parts, false), bare = with_reactions(train, parts, false, false);
  const ReactionRows r = sweep_meshes(s, 2), e = sweep_meshes(bare, 0);
  const Index psi1 = s.model->find_coordinate("psi1"), psi3 = s.model->find_coordinate("psi3");
  const double i1 = 1e-4, i3 = 5e-3, rho1 = 0.005 * 12 / 2, rho3 = 0.005 * 45 / 2;
  double largest = 0.0;
  for (std::size_t k = 0; k < r.values.size(); ++k) {
    const std::vector<double>& v = r.values[k];  // τ, power, then each pivot's Fx, Fy, Mz
    ASSERT_EQ(v.size(), 11u);
    EXPECT_EQ(v[0], e.values[k][0]) << k;  // the effort: the same bits
    const double tau = v[0], f1y = (i1 * r.qdd[k](psi1) - tau) / rho1, f2x = i3 * r.qdd[k](psi3) / rho3;
    const double scale = 1.0 + std::fabs(f1y) + std::fabs(f2x);
    const double a1 = std::fabs(f1y) * std::tan(20 * M_PI / 180), a2 = std::fabs(f2x) * std::tan(20 * M_PI / 180);
    const double expected[9] = {a1, -f1y, 0, f2x - a1, f1y + a2, 0, -f2x, -a2, 0};
    for (int c = 0; c < 9; ++c)
      EXPECT_NEAR(v[static_cast<std::size_t>(2 + c)], expected[c], 1e-12 * scale) << k << " " << c;
    largest = std::max(largest, std::fabs(f1y));
  }
  EXPECT_GT(largest, 0.05);
}

// models/transmissions/planetary.yaml with masses under gravity: the sun at 1 rad/s, the ring at −0.2, the carrier
// and the planet's centre turning (uniformly, so its centre accelerates toward the sun's). Each gear's teeth push at
// the pitch point on the line from the sun's centre to the planet's, n: the sun meshes at rs n, the ring (internal) at
// rr n, both about the origin. The sun and ring turn uniformly (ψ̈ = 0), so each mesh's torque on them is minus the
// motor's: the sun's mesh pushes it by −(τs/rs) ẑ × n and, at the teeth's 20°, toward its centre by |τs/rs| tan 20°,
// and its bearing holds it by the opposite and ms g↑; the ring's likewise, parted outward. The planet takes the
// opposite pushes at rp from its centre (parted outward by the sun and inward by the ring), its weight, and the pin's
// force (minus what the pin reports on the carrier): Newton for its centre's acceleration and Euler for its ψ̈.
TEST(GearMeshes, APlanetarysGearsMoveByNewtonEulerWithTheirTeethsPush) {
  const double ms = 0.3, mp = 0.2, mr = 0.8, ip = 2e-4, g = 9.81;
  const double rs = 0.004 * 24 / 2, rp = 0.004 * 18 / 2, rr = 0.004 * 60 / 2;
  const std::string parts =
      "  sun: {mass: 0.3, center_of_mass: [0, 0], inertia: 5e-4}\n"
      "  carrier: {mass: 0.5, center_of_mass: [0.042, 0], inertia: 1e-3}\n"
      "  planet: {mass: 0.2, center_of_mass: [0, 0], inertia: 2e-4}\n"
      "  ring: {mass: 0.8, center_of_mass: [0, 0], inertia: 6e-3}\n";
  const std::string planetary = test::model_file_text("transmissions/planetary.yaml", "output:");
  const Scene s = with_reactions(planetary, parts, true);
  SweepSummary sum;
  const ReactionRows r = sweep_meshes(s, 2, &sum);
  EXPECT_TRUE(sum.warnings.empty());
  // the sun–planet mesh without its carrier: a row of absolute angles, which the turning arm does not keep, so the
  // teeth's push does work in the motion: named at the first row
  const Scene armless = with_reactions(
      test::replace_first(planetary, "teeth: [24, 18], carrier: carrier}", "teeth: [24, 18]}"), parts, true);
  SweepSummary told;
  sweep_meshes(armless, 2, &told);
  ASSERT_EQ(told.warnings.size(), 1u);
  EXPECT_EQ(told.warnings[0].kind, "gear_centres");
  EXPECT_EQ(told.warnings[0].t, 0.0);
  EXPECT_NE(told.warnings[0].message.find("'sun_planet'"), std::string::npos) << told.warnings[0].message;
  EXPECT_HAS(told.warnings[0].message, "the same at the next");  // every row, said once
  // started from rest, the mesh does no work at the first row: told at the second
  const Scene from_rest = with_reactions(
      test::replace_first(
          test::replace_first(test::replace_first(planetary, "teeth: [24, 18], carrier: carrier}", "teeth: [24, 18]}"),
                              "law: {type: linear, initial: 0, rate: 1}",
                              "law: {type: polynomial, coefficients: [0, 0, 1]}"),
          "law: {type: linear, initial: 0, rate: -0.2}", "law: {type: polynomial, coefficients: [0, 0, -0.2]}"),
      parts, true);
  SweepSummary later;
  sweep_meshes(from_rest, 2, &later);
  ASSERT_EQ(later.warnings.size(), 1u);
  EXPECT_EQ(later.warnings[0].kind, "gear_centres");
  EXPECT_GT(later.warnings[0].t, 0.0);
  const Model& m = *s.model;
  const Index xp = m.find_coordinate("xp"), yp = m.find_coordinate("yp"), psip = m.find_coordinate("psip");
  // columns: τs, τr, two powers, then sun_bearing, carrier_bearing, ring_bearing, planet_pin (Fx, Fy, Mz each)
  const std::vector<Index>& drivers = s.sweep.efforts.constraints;
  ASSERT_EQ(drivers.size(), 2u);
  ASSERT_EQ(m.constraints()[static_cast<std::size_t>(drivers[0])].name, "sun_motor");
  double largest = 0.0;
  for (std::size_t k = 0; k < r.values.size(); ++k) {
    const std::vector<double>& v = r.values[k];
    ASSERT_EQ(v.size(), 16u);
    const double ts = v[0], tr = v[1];
    const V2 c(r.q[k](xp), r.q[k](yp)), n = c.normalized(), t = perp(n);
    const V2 sun = V2(v[4], v[5]), ring = V2(v[10], v[11]), pin_on_carrier = V2(v[13], v[14]);
    const V2 up(0, g);
    const double scale = 1.0 + (std::fabs(ts) / rs + std::fabs(tr) / rr);
    const double tan_a = std::tan(20 * M_PI / 180), sun_apart = std::fabs(ts / rs) * tan_a,
                 ring_apart = std::fabs(tr / rr) * tan_a;
    const V2 sun_expected = (ts / rs) * t + sun_apart * n + ms * up,
             ring_expected = (tr / rr) * t - ring_apart * n + mr * up;
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR(sun(i), sun_expected(i), 1e-11 * scale) << k;
      EXPECT_NEAR(ring(i), ring_expected(i), 1e-11 * scale) << k;
    }
    // the planet: the pushes the sun and ring take, reversed, at its pitch points c − rp n and c + rp n
    const V2 from_sun = (ts / rs) * t, from_ring = (tr / rr) * t;
    const V2 force = from_sun + from_ring + (sun_apart - ring_apart) * n - pin_on_carrier - mp * up;
    EXPECT_NEAR(force.x(), mp * r.qdd[k](xp), 1e-11 * scale) << k;
    EXPECT_NEAR(force.y(), mp * r.qdd[k](yp), 1e-11 * scale) << k;
    auto cross = [](const V2& a, const V2& b) { return a.x() * b.y() - a.y() * b.x(); };
    const double moment = cross(-rp * n, from_sun) + cross(rp * n, from_ring);
    EXPECT_NEAR(moment, ip * r.qdd[k](psip), 1e-11 * scale) << k;
    largest = std::max(largest, std::fabs(ts));
  }
  EXPECT_GT(largest, 1e-2);  // the carrier's and planet's weights turn the gears
}

// Three planets at 120° share an epicyclic train's load: their meshes are redundant (the model leaves rows out) and
// the shares are statically indeterminate, so the minimum-norm ones are written and named; by symmetry they are
// equal. Sun at 1 rad/s, ring held, the carrier loaded by 10 N·m, no gravity: every planet's pin carries the same
// force turned by 120°, the three together give the carrier the 10 N·m (Euler for it: its angle turns uniformly),
// and the sun's, ring's and carrier's bearings carry nothing (their pushes cancel). Were the shares those of the rows
// left in the solve, one planet would carry it all.
TEST(GearMeshes, ThreePlanetsShareTheLoadEquallyAndAreNamedIndeterminate) {
  std::string text =
      "phiq: 1\nname: three_planets\nparameters: {m: 0.004, arm: m*(24 + 18)/2}\ncoordinates:\n"
      "  xs: 0\n  ys: 0\n  ps: 0\n  xc: 0\n  yc: 0\n  pc: 0\n  xr: 0\n  yr: 0\n  pr: 0\n";
  std::string bodies = "bodies:\n  sun: [xs, ys, ps]\n  carrier: [xc, yc, pc]\n  ring: [xr, yr, pr]\n";
  std::string joints =
      "constraints:\n  - {name: sun_bearing, type: revolute, between: [{body: ground}, {body: sun}]}\n"
      "  - {name: carrier_bearing, type: revolute, between: [{body: ground}, {body: carrier}]}\n"
      "  - {name: ring_bearing, type: revolute, between: [{body: ground}, {body: ring}]}\n";
  std::string parts =
      "  sun: {mass: 0.3, center_of_mass: [0, 0], inertia: 5e-4}\n"
      "  carrier: {mass: 0.5, center_of_mass: [0, 0], inertia: 1e-3}\n"
      "  ring: {mass: 0.8, center_of_mass: [0, 0], inertia: 6e-3}\n";
  for (int k = 0; k < 3; ++k) {
    const std::string p = "p" + std::to_string(k),
                      at = "[arm*cos(" + std::to_string(2 * k) + "*pi/3), arm*sin(" + std::to_string(2 * k) + "*pi/3)]";
    text += "  x" + p + ": arm*cos(" + std::to_string(2 * k) + "*pi/3)\n  y" + p + ": arm*sin(" +
            std::to_string(2 * k) + "*pi/3)\n  a" + p + ": 0\n";
    bodies += "  " + p + ": [x" + p + ", y" + p + ", a" + p + "]\n";
    joints += "  - {name: " + p + "_pin, type: revolute, between: [{body: carrier, at: " + at + "}, {body: " + p +
              "}]}\n  - {name: sun_" + p + ", type: gear, between: [sun, " + p +
              "], teeth: [24, 18], carrier: carrier}\n  - {name: " + p + "_ring, type: gear, between: [" + p +
              ", ring], teeth: [18, 60], mesh: internal, carrier: carrier}\n";
    parts += "  " + p + ": {mass: 0.2, center_of_mass: [0, 0], inertia: 2e-4}\n";
  }
  const Scene s = parse_scene(text + bodies + joints +
                                  "drivers:\n  - {name: sun_motor, coordinate: ps, law: {type: linear, initial: 0, "
                                  "rate: 1}}\n  - {name: ring_hold, coordinate: pr, law: {type: linear, initial: 0, "
                                  "rate: 0}}\nparts:\n" +
                                  parts +
                                  "loads: {torques: [{name: out, part: carrier, torque: -10}]}\n"
                                  "time: {start: 0, end: 1, steps: 10}\noutput: {velocities: true, accelerations: "
                                  "true, efforts: all, reactions: all}\n",
                              "three_planets.yaml");
  SweepSummary sum;
  const Model* m = nullptr;
  const ReactionRows r = sweep_meshes(s, 6, &sum, &m);
  ASSERT_FALSE(m->dropped_rows().empty());  // the redundant mesh rows left out, as `phiq run` sweeps it
  ASSERT_EQ(sum.warnings.size(), 1u);
  EXPECT_EQ(sum.warnings[0].kind, "indeterminate");
  for (const char* g : {"'sun_p0'", "'p2_ring'"}) EXPECT_NE(sum.warnings[0].message.find(g), std::string::npos) << g;
  const double arm = 0.004 * 42 / 2;
  for (std::size_t row = 0; row < r.values.size(); ++row) {
    const std::vector<double>& v = r.values[row];  // 2 efforts, 2 powers, 3 bearings, 3 pins (Fx, Fy, Mz each)
    ASSERT_EQ(v.size(), 22u);
    for (int c = 4; c < 13; ++c) EXPECT_NEAR(v[static_cast<std::size_t>(c)], 0.0, 1e-9) << row << " " << c;
    const double psi = r.q[row](m->find_coordinate("pc"));
    double moment = 0.0;
    for (int k = 0; k < 3; ++k) {
      const V2 f(v[static_cast<std::size_t>(13 + 3 * k)], v[static_cast<std::size_t>(14 + 3 * k)]);
      const double turn = psi + 2 * M_PI * k / 3;
      const V2 at = arm * V2(std::cos(turn), std::sin(turn));
      moment += at.x() * f.y() - at.y() * f.x();
      const V2 first(v[13], v[14]), turned = Eigen::Rotation2Dd(2 * M_PI * k / 3) * first;
      EXPECT_NEAR(f.x(), turned.x(), 1e-9) << row << " planet " << k;
      EXPECT_NEAR(f.y(), turned.y(), 1e-9) << row << " planet " << k;
    }
    EXPECT_NEAR(moment, 10.0, 1e-9) << row;
  }
}

// models/transmissions/rack_pinion.yaml with masses under gravity and the rack's reference point 0.03 below its pitch
// line (its guide there): the rack moves along x by its teeth alone (its guide carries no x), so they push it by
// F = (mr ẍ, −|mr ẍ| tan 20°) at the pitch point P (below the pinion's centre by r; the teeth's pressure angle parts
// them), and the pinion by −F: its pivot holds (mr ẍ, mp g − |mr ẍ| tan 20°), and the guide the rack's weight, the
// parting and the moment about its point S that Euler asks for the rack, M = (com − S) × (mr a − W) − (P − S) × F.
TEST(GearMeshes, ARacksTeethPushThePinionsPivotAndTurnOnItsGuide) {
  const double mp = 0.2, mr = 1.5, g = 9.81, r = 0.04;
  std::string text = test::model_file_text("transmissions/rack_pinion.yaml", "output:");
  text = test::replace_first(text, "y_rack: 0", "y_rack: -0.03");
  text = test::replace_first(text, "between: [{body: ground}, {body: rack}]",
                             "between: [{body: ground, at: [0, -0.03]}, {body: rack}]");
  const Scene s = with_reactions(text,
                                 "  pinion: {mass: 0.2, center_of_mass: [0, 0], inertia: 2e-4}\n"
                                 "  rack: {mass: 1.5, center_of_mass: [0.1, -0.02], inertia: 0.01}\n",
                                 true);
  const ReactionRows rows = sweep_meshes(s, 1);
  const Model& m = *s.model;
  const Index x = m.find_coordinate("x_rack"), guide = m.find_constraint("guide");
  const Index xp = m.find_coordinate("xp"), yp = m.find_coordinate("yp");
  const auto [block, index] = m.constraint_block(guide);
  double largest = 0.0;
  for (std::size_t k = 0; k < rows.values.size(); ++k) {
    const std::vector<double>& v = rows.values[k];  // τ, power, pivot's Fx, Fy, Mz, guide's Fx, Fy, Mz
    ASSERT_EQ(v.size(), 8u);
    const double xdd = rows.qdd[k](x);
    const double apart = std::fabs(mr * xdd) * std::tan(20 * M_PI / 180);
    const V2 f(mr * xdd, -apart), weight(0.0, -mr * g), a(xdd, 0.0);
    const V2 rack(rows.q[k](x), -0.03), com = rack + V2(0.1, -0.02);
    const V2 pitch(rows.q[k](xp), rows.q[k](yp) - r);  // below the pinion's centre
    ReactionSite site;
    ASSERT_TRUE(block->reaction_site(index, rows.q[k].data(), site));
    const V2 at(site.point.x, site.point.y);
    auto cross = [](const V2& u, const V2& w) { return u.x() * w.y() - u.y() * w.x(); };
    const double moment = cross(com - at, mr * a - weight) - cross(pitch - at, f);
    const double expected[6] = {f.x(), mp * g - apart, 0.0, 0.0, mr * g + apart, moment};
    for (int c = 0; c < 6; ++c) EXPECT_NEAR(v[static_cast<std::size_t>(2 + c)], expected[c], 1e-11) << k << " " << c;
    largest = std::max(largest, std::fabs(f.x()));
  }
  EXPECT_GT(largest, 0.1);
}

// A reducer: the ring held by the ground (`between: [planet, ground]`), the sun driven at 1 rad/s, the carrier
// loaded by 10 N·m, no gravity. The fixed ring is coaxial with the carrier, so its teeth still push the planet:
// at the pitch points c ∓ rp n the sun and the ring push it by Fs t and Fr t (t = ẑ × n) and part it outward and
// inward by |Fs| and |Fr| tan 20°. The sun turns uniformly: the sun's mesh takes the motor's torque, Fs = τs/rs,
// and the sun's bearing holds the sun's opposite push. The planet turns uniformly too: Euler gives Fr = Fs, and
// Newton the pin's force for its centre's acceleration, which the carrier's bearing carries (its centre of mass on
// its axis); the carrier's Euler equation, that the pin's force turns it against the load.
TEST(GearMeshes, AFixedRingStillPushesThePlanetsPin) {
  const std::string scene =
      "phiq: 1\nname: reducer\nparameters: {m: 0.004, arm: m*(24 + 18)/2}\n"
      "coordinates: {xs: 0, ys: 0, ps: 0, xc: 0, yc: 0, pc: 0, xp: arm, yp: 0, pp: 0}\n"
      "bodies: {sun: [xs, ys, ps], carrier: [xc, yc, pc], planet: [xp, yp, pp]}\nconstraints:\n"
      "  - {name: sun_bearing, type: revolute, between: [{body: ground}, {body: sun}]}\n"
      "  - {name: carrier_bearing, type: revolute, between: [{body: ground}, {body: carrier}]}\n"
      "  - {name: pin, type: revolute, between: [{body: carrier, at: [arm, 0]}, {body: planet}]}\n"
      "  - {name: sun_planet, type: gear, between: [sun, planet], teeth: [24, 18], carrier: carrier}\n"
      "  - {name: planet_ring, type: gear, between: [planet, ground], teeth: [18, 60], mesh: internal, CARRIER}\n"
      "drivers:\n  - {name: motor, coordinate: ps, law: {type: linear, initial: 0, rate: 1}}\n"
      "time: {start: 0, end: 2, steps: 20}\n";
  const std::string parts =
      "  sun: {mass: 0.3, center_of_mass: [0, 0], inertia: 5e-4}\n"
      "  carrier: {mass: 0.5, center_of_mass: [0, 0], inertia: 1e-3}\n"
      "  planet: {mass: 0.2, center_of_mass: [0, 0], inertia: 2e-4}\n"
      "loads: {torques: [{name: out, part: carrier, torque: -10}]}\n";
  const Scene s = with_reactions(test::replace_first(scene, "CARRIER", "carrier: carrier"), parts, false);
  SweepSummary sum;
  const ReactionRows r = sweep_meshes(s, 2, &sum);
  EXPECT_TRUE(sum.warnings.empty());
  const Model& m = *s.model;
  const Index xp = m.find_coordinate("xp"), yp = m.find_coordinate("yp");
  const double mp = 0.2, rs = 0.004 * 24 / 2, rp = 0.004 * 18 / 2, arm = rs + rp, tan_a = std::tan(20 * M_PI / 180);
  double largest = 0.0;
  for (std::size_t k = 0; k < r.values.size(); ++k) {
    const std::vector<double>& v = r.values[k];  // τs, power, sun_bearing, carrier_bearing, pin (Fx, Fy, Mz each)
    ASSERT_EQ(v.size(), 11u);
    const V2 c(r.q[k](xp), r.q[k](yp)), n = c.normalized(), t = perp(n);
    const double fs = v[0] / rs, fr = fs;  // the planet's pushes along t
    const V2 on_planet = fs * t + fr * t + (std::fabs(fs) - std::fabs(fr)) * tan_a * n;
    const V2 pin = mp * V2(r.qdd[k](xp), r.qdd[k](yp)) - on_planet;  // on the planet
    const V2 sun = fs * t + std::fabs(fs) * tan_a * n;               // the sun's bearing holds its push
    const double scale = 1.0 + std::fabs(fs);
    const double expected[9] = {sun.x(), sun.y(), 0, pin.x(), pin.y(), 0, -pin.x(), -pin.y(), 0};
    for (int i = 0; i < 9; ++i)
      EXPECT_NEAR(v[static_cast<std::size_t>(2 + i)], expected[i], 1e-11 * scale) << k << " " << i;
    EXPECT_NEAR(arm * (n.y() * pin.x() - n.x() * pin.y()), 10.0, 1e-9) << k;  // the carrier: n × (−pin) turns it
    largest = std::max(largest, std::fabs(fs));
  }
  EXPECT_GT(largest, 10.0);
  // without its carrier the fixed ring's centre is not known: said, and its push left out
  SweepSummary told;
  sweep_meshes(with_reactions(test::replace_first(scene, ", CARRIER", ""), parts, false), 2, &told);
  ASSERT_FALSE(told.warnings.empty());
  EXPECT_EQ(told.warnings[0].kind, "unloaded_bearings");
  EXPECT_HAS(told.warnings[0].message, "'planet_ring'");
}

}  // namespace
}  // namespace phiq
