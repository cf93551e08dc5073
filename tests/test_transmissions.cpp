// The transmissions (kinds/transmissions.hpp): gear pairs, racks and pinions, belts and chains. Their derivatives
// against finite differences, the scenes of models/transmissions/ against their closed forms (a two-stage train's
// output angle, Willis' formula on a planetary train with a moving carrier, x = r θ of a rack, the ratios of open
// and crossed belts and of a chain) to 1e-9 in position, velocity and acceleration, their Grübler counts, and the
// data they refuse with one line naming the constraint.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>

#include "constraint_check.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

TEST(Transmissions, GearDerivatives) {
  GearSpec external{{}, S(0), S(1), Slot::constant(0.0), 0.03, 0.09, false, 0.2, 2};
  CheckSpec(external, 2, Opts(2701));
  GearSpec planet_ring{{}, S(2), S(0), S(1), 18.0, 60.0, true, -0.1, 2};  // with a moving carrier
  CheckSpec(planet_ring, 3, Opts(2702));
  GearSpec fixed_sun{{}, Slot::constant(0.4), S(0), S(1), 24.0, 18.0, false, 0.0, 2};  // the sun held
  CheckSpec(fixed_sun, 2, Opts(2703));
}

TEST(Transmissions, RackAndBeltDerivatives) {
  CheckSpec(RackPinionSpec{{}, S(1), S(0), 0.04, 0.01, false, 2}, 2, Opts(2711));
  CheckSpec(RackPinionSpec{{}, S(0), S(1), 0.5, 0.0, true, 3}, 2, Opts(2712));
  CheckSpec(BeltSpec{{}, S(0), S(1), 0.08, 0.05, false, 0.0, 2}, 2, Opts(2713));
  CheckSpec(BeltSpec{{}, S(1), S(0), 0.08, 0.12, true, 0.3, 2}, 2, Opts(2714));
}

TEST(Transmissions, AlongTheirData) {
  const Slot Z = Slot::constant(0.0);
  // the radii and the phase move; then a held sun that turns with the parameter
  CheckDataDerivative(GearSpec{{}, S(0), S(1), Slot::constant(0.0), 0.03, 0.09, false, 0.2, 2},
                      GearSpec{{}, Z, Z, Z, 0.01, -0.02, false, 0.7, 2}, 2, 2721);
  CheckDataDerivative(GearSpec{{}, S(2), S(0), S(1), 18.0, 60.0, true, -0.1, 2},
                      GearSpec{{}, Z, Z, Z, 1.0, 3.0, true, 0.0, 2}, 3, 2722);
  CheckDataDerivative(GearSpec{{}, Slot::constant(0.4), S(0), S(1), 24.0, 18.0, false, 0.0, 2},
                      GearSpec{{}, Slot::constant(1.3), Z, Z, -2.0, 1.0, false, 0.5, 2}, 2, 2723);
  CheckDataDerivative(RackPinionSpec{{}, S(1), S(0), 0.04, 0.01, false, 2},
                      RackPinionSpec{{}, Z, Z, 0.5, -0.3, false, 2}, 2, 2724);
  CheckDataDerivative(RackPinionSpec{{}, S(0), S(1), 0.5, 0.0, true, 3}, RackPinionSpec{{}, Z, Z, -0.2, 0.4, true, 3},
                      2, 2725);
  CheckDataDerivative(BeltSpec{{}, S(0), S(1), 0.08, 0.05, false, 0.0, 2}, BeltSpec{{}, Z, Z, 0.3, -0.1, false, 0.2, 2},
                      2, 2726);
  CheckDataDerivative(BeltSpec{{}, S(1), S(0), 0.08, 0.12, true, 0.3, 2}, BeltSpec{{}, Z, Z, -0.05, 0.2, true, 1.0, 2},
                      2, 2727);
}

// The values of one row of a kind at q (the relation it states, whatever its scaling).
template <class Spec>
double Row(const Spec& s, std::initializer_list<double> q) {
  double phi = 0.0;
  s.residual(std::data(q), 0.0, &phi);
  return phi;
}

TEST(Transmissions, RowsStateTheRelationsOfTheirHeaders) {
  // external: r1 (θ1 − θc) + r2 (θ2 − θc) = r1 φ; internal: r1 (θ1 − θc) − r2 (θ2 − θc) = r1 φ, per radian of gear 1
  const GearSpec ext{{}, S(0), S(1), S(2), 2.0, 3.0, false, 0.5, 2}, inl{{}, S(0), S(1), S(2), 2.0, 3.0, true, 0.5, 2};
  EXPECT_DOUBLE_EQ(Row(ext, {1.0, 2.0, 0.25}), (2.0 * 0.75 + 3.0 * 1.75) / 2.0 - 0.5);
  EXPECT_DOUBLE_EQ(Row(inl, {1.0, 2.0, 0.25}), (2.0 * 0.75 - 3.0 * 1.75) / 2.0 - 0.5);
  EXPECT_DOUBLE_EQ(Row(RackPinionSpec{{}, S(0), S(1), 0.04, 0.01, false, 2}, {0.3, 2.0}), 0.3 - 0.08 - 0.01);
  EXPECT_DOUBLE_EQ(Row(RackPinionSpec{{}, S(0), S(1), 0.04, 0.01, true, 2}, {0.3, 2.0}), 0.3 + 0.08 - 0.01);
  EXPECT_DOUBLE_EQ(Row(BeltSpec{{}, S(0), S(1), 0.08, 0.05, false, 0.0, 2}, {1.0, 1.6}), 1.0 - 0.05 / 0.08 * 1.6);
  EXPECT_DOUBLE_EQ(Row(BeltSpec{{}, S(0), S(1), 0.08, 0.05, true, 0.0, 2}, {1.0, 1.6}), 1.0 + 0.05 / 0.08 * 1.6);
}

TEST(Transmissions, TwoStageTrainTurnsItsOutputAtOneNinth) {
  const test::SweptScene run = test::sweep_scene("transmissions/gear_train.yaml");
  const Model& m = *run.scene.model;
  ASSERT_EQ(run.status, SolveStatus::kSuccess) << run.summary.message;
  const test::Trace& tr = run.trace;
  EXPECT_EQ(m.grubler(), std::optional<Index>(1));
  const Index p1 = m.coordinate_index("psi1"), p2 = m.coordinate_index("psi2"), p3 = m.coordinate_index("psi3");
  ASSERT_EQ(tr.t.size(), 121u);
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    const double t = tr.t[k], a = 6.0 * M_PI;  // psi1 = a sin t: three turns each way
    EXPECT_NEAR(tr.q[k](p1), a * std::sin(t), 1e-9);
    EXPECT_NEAR(tr.q[k](p2), -a * std::sin(t) / 3.0, 1e-9);
    EXPECT_NEAR(tr.q[k](p3), a * std::sin(t) / 9.0, 1e-9);
    EXPECT_NEAR(tr.qd[k](p3), a * std::cos(t) / 9.0, 1e-9);
    EXPECT_NEAR(tr.qdd[k](p3), -a * std::sin(t) / 9.0, 1e-9);
  }
}

TEST(Transmissions, PlanetaryTrainWithAMovingCarrierObeysWillis) {
  const test::SweptScene run = test::sweep_scene("transmissions/planetary.yaml");
  const Model& m = *run.scene.model;
  ASSERT_EQ(run.status, SolveStatus::kSuccess) << run.summary.message;
  const test::Trace& tr = run.trace;
  EXPECT_EQ(m.grubler(), std::optional<Index>(2));
  CheckModel(m, 2704);  // the whole model's Jacobian, Φt and γ through its CSC pattern
  const Index ps = m.coordinate_index("psis"), pc = m.coordinate_index("psic"), pp = m.coordinate_index("psip"),
              pr = m.coordinate_index("psir"), xp = m.coordinate_index("xp"), yp = m.coordinate_index("yp");
  ASSERT_EQ(tr.t.size(), 141u);
  const double zs = 24, zp = 18, zr = 60, ws = 1.0, wr = -0.2, arm = 0.004 * (zs + zp) / 2.0;
  const double wc = (zs * ws + zr * wr) / (zs + zr);  // Willis: (ws − wc)/(wr − wc) = −zr/zs
  ASSERT_DOUBLE_EQ(wc, 1.0 / 7.0);
  const double wp = wc - zs / zp * (ws - wc);  // the planet against the sun, relative to the carrier
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    const double t = tr.t[k];
    EXPECT_NEAR(tr.q[k](pc), wc * t, 1e-9);
    EXPECT_NEAR(tr.q[k](pp), wp * t, 1e-9);
    EXPECT_NEAR(tr.qd[k](pc), wc, 1e-9);
    EXPECT_NEAR(tr.qd[k](pp), wp, 1e-9);
    EXPECT_NEAR(tr.qdd[k](pc), 0.0, 1e-9);
    // the ratio of the relative speeds, Willis' formula itself
    EXPECT_NEAR((tr.qd[k](ps) - tr.qd[k](pc)) / (tr.qd[k](pr) - tr.qd[k](pc)), -zr / zs, 1e-9);
    // the planet's centre rides the carrier's arm
    EXPECT_NEAR(tr.q[k](xp), arm * std::cos(wc * t), 1e-9);
    EXPECT_NEAR(tr.q[k](yp), arm * std::sin(wc * t), 1e-9);
    EXPECT_NEAR(tr.qdd[k](xp), -arm * wc * wc * std::cos(wc * t), 1e-9);
  }
}

TEST(Transmissions, RackTravelsTheRadiusTimesThePinionsTurn) {
  const test::SweptScene run = test::sweep_scene("transmissions/rack_pinion.yaml");
  const Model& m = *run.scene.model;
  ASSERT_EQ(run.status, SolveStatus::kSuccess) << run.summary.message;
  const test::Trace& tr = run.trace;
  EXPECT_EQ(m.grubler(), std::optional<Index>(1));
  const Index x = m.coordinate_index("x_rack");
  EXPECT_EQ(m.row_unit(m.constraints()[2].first_row), Unit::kLength);
  ASSERT_EQ(tr.t.size(), 61u);
  const double r = 0.04;
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    const double t = tr.t[k];
    EXPECT_NEAR(tr.q[k](x), r * 0.8 * std::sin(2 * t), 1e-9);
    EXPECT_NEAR(tr.qd[k](x), r * 1.6 * std::cos(2 * t), 1e-9);
    EXPECT_NEAR(tr.qdd[k](x), -r * 3.2 * std::sin(2 * t), 1e-9);
  }
}

TEST(Transmissions, OpenAndCrossedBeltsAndAChain) {
  const test::SweptScene run = test::sweep_scene("transmissions/belts.yaml");
  const Model& m = *run.scene.model;
  ASSERT_EQ(run.status, SolveStatus::kSuccess) << run.summary.message;
  const test::Trace& tr = run.trace;
  EXPECT_FALSE(m.grubler().has_value());  // angles without bodies: no count
  ASSERT_EQ(tr.t.size(), 41u);
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    const double t = tr.t[k], th = t + 0.5 * t * t, w = 1 + t, a = 1.0;
    const double open = 0.08 / 0.05, crossed = -0.08 / 0.12, chain = open * 44.0 / 16.0;
    for (auto [c, ratio] : {std::pair{1, open}, std::pair{2, crossed}, std::pair{3, chain}}) {
      EXPECT_NEAR(tr.q[k](c), ratio * th, 1e-9) << c;
      EXPECT_NEAR(tr.qd[k](c), ratio * w, 1e-9) << c;
      EXPECT_NEAR(tr.qdd[k](c), ratio * a, 1e-9) << c;
    }
  }
}

// The message a spec's data is refused with when added to a model.
template <class Spec>
std::string Refused(const Spec& spec) {
  ModelBuilder b;
  b.add_coordinate("a", 0), b.add_coordinate("b", 0), b.add_coordinate("c", 0);
  try {
    b.add("t1", spec);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Transmissions, RefusesBadData) {
  EXPECT_EQ(Refused(GearSpec{{}, S(0), S(1), Slot::constant(0), 0.0, 1.0, false, 0.0, 2}),
            "constraint 't1': gear: the radii (or tooth counts) must be positive");
  EXPECT_EQ(Refused(GearSpec{{}, S(0), S(1), Slot::constant(0), 1.0, -2.0, false, 0.0, 2}),
            "constraint 't1': gear: the radii (or tooth counts) must be positive");
  EXPECT_EQ(Refused(GearSpec{{}, S(0), S(1), Slot::constant(0), 3.0, 2.0, true, 0.0, 2}),
            "constraint 't1': gear: an internal pair's second gear is the ring: its radius must exceed the first's");
  EXPECT_EQ(Refused(GearSpec{{}, S(0), S(0), Slot::constant(0), 1.0, 2.0, false, 0.0, 2}),
            "constraint 't1': gear: the two gears must be different angles");
  EXPECT_EQ(Refused(GearSpec{{}, S(0), S(1), S(1), 1.0, 2.0, false, 0.0, 2}),
            "constraint 't1': gear: the carrier must not be one of the gears");
  EXPECT_EQ(Refused(GearSpec{{}, S(0), S(1), S(2), 1.0, 2.0, true, 0.0, 2}), "");
  EXPECT_EQ(Refused(RackPinionSpec{{}, S(0), S(1), 0.0, 0.0, false, 2}),
            "constraint 't1': rack_pinion: the radius must be positive");
  EXPECT_EQ(Refused(RackPinionSpec{{}, S(0), S(0), 0.1, 0.0, false, 2}),
            "constraint 't1': rack_pinion: the rack's travel and the pinion's angle must be different coordinates");
  EXPECT_EQ(Refused(BeltSpec{{}, S(0), S(1), 0.1, NAN, false, 0.0, 2}),
            "constraint 't1': belt: the radii (or tooth counts) must be positive");
}

TEST(Transmissions, SceneErrorsNameTheField) {
  const std::string head =
      "phiq: 1\ncoordinates: {x: 0, y: 0, psi: 0}\nbodies: {g: [x, y, psi]}\n"
      "time: {start: 0, end: 1, steps: 1}\nconstraints:\n";
  EXPECT_EQ(test::scene_error(head + "  - {name: m, type: gear, between: [g, psi], radii: [1, 2], teeth: [1, 2]}\n"),
            "bad.yaml:6:5: constraints[0]: give either 'radii: [r1, r2]' or 'teeth: [z1, z2]'");
  EXPECT_EQ(test::scene_error(head + "  - {name: m, type: gear, between: [g, nope], teeth: [12, 30]}\n"),
            "bad.yaml:6:40: constraints[0].between[1]: unknown body or angle coordinate 'nope'");
  EXPECT_EQ(test::scene_error(head + "  - {name: m, type: gear, between: [g, x], teeth: [12.5, 30]}\n"),
            "bad.yaml:6:52: constraints[0].teeth[0]: expected a whole number, got '12.5'");
  EXPECT_EQ(test::scene_error(head + "  - {name: m, type: gear, between: [g, x], teeth: [12, 30], mesh: inner}\n"),
            "bad.yaml:6:67: constraints[0].mesh: expected one of external, internal, got 'inner'");
  EXPECT_EQ(test::scene_error(head + "  - {name: m, type: belt, between: [g, x], radii: [0, 1]}\n"),
            "bad.yaml:6:5: constraints[0]: constraint 'm': belt: the radii (or tooth counts) must be positive");
  EXPECT_EQ(
      test::scene_error(head + "  - {name: m, type: gear, between: [g, x], teeth: [12, 30], pressure_angle: 2}\n"),
      "bad.yaml:6:5: constraints[0]: constraint 'm': gear: pressure_angle must be in [0, pi/2) rad");
}

}  // namespace
}  // namespace phiq
