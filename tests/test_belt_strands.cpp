// Belts and chains in joint reactions (add_gear_mesh_forces(), phiq/joint_reactions.hpp): a belt's row relates
// angles, yet its two strands pull its pulleys' centres. Each drive here is checked by Newton–Euler written in the
// test, with the strands drawn as tangents found by their own condition (each strand's ends on it, ⟂ to the radii):
// the driven pulley's Euler equation and the strands' rule (a belt's sum 2 T0, a chain's slack strand T0) give the
// tensions; the pivots hold what the strands and the weights leave; the driver's Euler equation gives the motor's
// torque. A slack belt, a belt without tension and teeth without a pitch are told.
#include <gtest/gtest.h>

#include <cmath>

#include "phiq/phiq.hpp"
#include "reaction_rows.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

using test::ReactionRows;
using V2 = Eigen::Vector2d;
V2 left_of(const V2& u) { return {-u.y(), u.x()}; }  // ẑ × u
double moment_of(const V2& a, const V2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Two pulleys on ground pivots, the driver at the origin turned three times each way in a second by the motor, the
// driven one at (0.4, 0.1) with inertia, under gravity; `belt` is the transmission's entry.
Scene belt_drive(const std::string& belt, bool reactions = true) {
  return parse_scene(
      "phiq: 1\nname: belt_drive\ncoordinates: {x1: 0, y1: 0, psi1: 0, x2: 0.4, y2: 0.1, psi2: 0}\n"
      "bodies: {driver: [x1, y1, psi1], driven: [x2, y2, psi2]}\nconstraints:\n"
      "  - {name: driver_pivot, type: revolute, between: [{body: ground}, {body: driver}]}\n"
      "  - {name: driven_pivot, type: revolute, between: [{body: ground, at: [0.4, 0.1]}, {body: driven}]}\n"
      "  - " +
          belt +
          "\ndrivers:\n  - {name: motor, coordinate: psi1, law: {type: harmonic, amplitude: 6*pi, frequency: 2*pi}}\n"
          "parts:\n  driver: {mass: 0.4, center_of_mass: [0, 0], inertia: 2e-4}\n"
          "  driven: {mass: 0.9, center_of_mass: [0, 0], inertia: 5e-3}\nloads: {gravity: [0, -9.81]}\n"
          "time: {start: 0, end: 1, steps: 40}\noutput: {velocities: true, accelerations: true, efforts: all" +
          (reactions ? ", reactions: all}\n" : "}\n"),
      "belt_drive.yaml");
}

// A strand: its direction u from pulley 1 to pulley 2 and where it touches them, on the sides σ1, σ2 (±1 along
// ẑ × u) of centres c1, c2 with radii r1, r2: P_i = c_i + σ_i r_i ẑ × u, with P2 − P1 along u.
struct Strand {
  V2 u, p1, p2;
};
Strand strand(const V2& c1, const V2& c2, double r1, double r2, double s1, double s2) {
  const V2 d = c2 - c1;
  // (ẑ × u)·d = σ1 r1 − σ2 r2 for u at angle a: |d| sin(φ − a) = σ1 r1 − σ2 r2, u leaving toward pulley 2
  const double a = std::atan2(d.y(), d.x()) - std::asin((s1 * r1 - s2 * r2) / d.norm());
  Strand s;
  s.u = V2(std::cos(a), std::sin(a));
  s.p1 = c1 + s1 * r1 * left_of(s.u), s.p2 = c2 + s2 * r2 * left_of(s.u);
  EXPECT_NEAR(moment_of(s.p2 - s.p1, s.u), 0.0, 1e-14);  // a tangent: its ends on its line
  EXPECT_GT((s.p2 - s.p1).dot(s.u), 0.0);
  return s;
}

// The drive's rows checked by Newton–Euler: tensions (T₊ on the strand touching pulley 1 on its +ẑ×u side, T₋)
// from the driven pulley's Euler equation and `rule` (given T₊ − T₋ = δ, the pair), then both pivots and the motor.
template <class Rule>
void expect_newton_euler(const Scene& s, double r1, double r2, bool crossed, Rule rule, double* largest) {
  const ReactionRows rows = test::sweep_reactions(s);
  const Model& m = *s.model;
  const double m1 = 0.4, m2 = 0.9, i1 = 2e-4, i2 = 5e-3, g = 9.81;
  const Index psi1 = m.find_coordinate("psi1"), psi2 = m.find_coordinate("psi2");
  const V2 c1(0, 0), c2(0.4, 0.1), up(0, g);
  const Strand plus = strand(c1, c2, r1, r2, 1, crossed ? -1 : 1), minus = strand(c1, c2, r1, r2, -1, crossed ? 1 : -1);
  // on pulley 2 the strands pull toward pulley 1 (−u): I2 ψ̈2 = Σ (P2 − c2) × (−T u) = a T₊ + b T₋
  const double a = moment_of(plus.p2 - c2, -plus.u), b = moment_of(minus.p2 - c2, -minus.u);
  ASSERT_GT(std::fabs(a - b), 1e-3);
  for (std::size_t k = 0; k < rows.values.size(); ++k) {
    const std::vector<double>& v = rows.values[k];  // τ, power, driver_pivot's Fx, Fy, Mz, driven_pivot's
    ASSERT_EQ(v.size(), 8u);
    // a T₊ + b T₋ = I2 ψ̈2 with T₊ − T₋ = δ: the strands' rule picks the pair; δ from the sum's form
    const double tau2 = i2 * rows.qdd[k](psi2);
    const auto [tp, tm] = rule(tau2, a, b);
    EXPECT_NEAR(a * tp + b * tm, tau2, 1e-9 * (1 + std::fabs(tau2))) << k;
    const V2 pull = tp * plus.u + tm * minus.u;  // on pulley 1's centre, toward pulley 2
    const double scale = 1.0 + std::fabs(tp) + std::fabs(tm);
    const V2 driver = -pull + m1 * up, driven = pull + m2 * up;
    const double expected[6] = {driver.x(), driver.y(), 0.0, driven.x(), driven.y(), 0.0};
    for (int c = 0; c < 6; ++c) EXPECT_NEAR(v[static_cast<std::size_t>(2 + c)], expected[c], 1e-11 * scale) << k;
    // the motor: I1 ψ̈1 = τ + Σ (P1 − c1) × T u
    const double strands = moment_of(plus.p1 - c1, tp * plus.u) + moment_of(minus.p1 - c1, tm * minus.u);
    EXPECT_NEAR(v[0] + strands, i1 * rows.qdd[k](psi1), 1e-11 * scale) << k;
    *largest = std::max(*largest, std::fabs(tp - tm));
  }
}

// An open belt at 200 N: T₊ + T₋ = 400, the inertia of the driven pulley alone sets T₊ − T₋, whose sign turns with
// the motion (the tight strand changes). The motor's torque is the bits it is without the reactions.
TEST(BeltStrands, AnOpenBeltsStrandsPullThePivotsByNewtonEuler) {
  const std::string belt = "{name: belt, type: belt, between: [driver, driven], radii: [0.08, 0.05], tension: 200}";
  double largest = 0.0;
  expect_newton_euler(
      belt_drive(belt), 0.08, 0.05, false,
      [](double tau2, double a, double b) {
        const double tm = (tau2 - 400 * a) / (b - a);  // a (400 − T₋) + b T₋ = τ2
        return std::pair{400 - tm, tm};
      },
      &largest);
  EXPECT_GT(largest, 50.0);
  const ReactionRows with = test::sweep_reactions(belt_drive(belt)),
                     without = test::sweep_reactions(belt_drive(belt, false));
  ASSERT_EQ(with.values.size(), without.values.size());
  for (std::size_t k = 0; k < with.values.size(); ++k) EXPECT_EQ(with.values[k][0], without.values[k][0]) << k;
}

TEST(BeltStrands, ACrossedBeltsStrandsPullThePivotsByNewtonEuler) {
  double largest = 0.0;
  expect_newton_euler(
      belt_drive("{name: belt, type: belt, between: [driver, driven], radii: [0.08, 0.05], crossed: true, "
                 "tension: 150}"),
      0.08, 0.05, true,
      [](double tau2, double a, double b) {
        const double tm = (tau2 - 300 * a) / (b - a);
        return std::pair{300 - tm, tm};
      },
      &largest);
  EXPECT_GT(largest, 50.0);
}

// A chain of pitch 12.7 mm on 24 and 15 teeth (radii z p / 2π: it travels z p a turn), its slack strand at 0: the
// tight one carries all, and which one is tight turns with the torque.
TEST(BeltStrands, AChainsTightStrandCarriesItAllAndItsSlackOneNothing) {
  const double p = 0.0127, r1 = 24 * p / (2 * M_PI), r2 = 15 * p / (2 * M_PI);
  double largest = 0.0;
  int tight_plus = 0, tight_minus = 0;
  expect_newton_euler(
      belt_drive("{name: chain, type: chain, between: [driver, driven], teeth: [24, 15], pitch: 0.0127}"), r1, r2,
      false,
      [&](double tau2, double a, double b) {
        // one strand carries τ2 alone: the one whose share has τ2's sign
        if (tau2 / a >= 0) return ++tight_plus, std::pair{tau2 / a, 0.0};
        return ++tight_minus, std::pair{0.0, tau2 / b};
      },
      &largest);
  EXPECT_GT(largest, 50.0);
  EXPECT_GT(tight_plus, 5);
  EXPECT_GT(tight_minus, 5);
}

// A belt tensioned too little for the torque: the rows where its slack strand would push are named once per
// stretch; its loads are still those of the strands' rule (a negative tension, so that they balance the torque).
TEST(BeltStrands, ASlackBeltIsToldOncePerStretch) {
  SweepSummary sum;
  const Scene s = belt_drive("{name: loose, type: belt, between: [driver, driven], radii: [0.08, 0.05], tension: 20}");
  test::sweep_reactions(s, &sum);
  int slack = 0;
  for (const SweepWarning& w : sum.warnings) {
    ASSERT_EQ(w.kind, "belt_slack") << w.message;
    EXPECT_HAS(w.message, "'loose'");
    EXPECT_HAS(w.message, "the same at");
    ++slack;
  }
  EXPECT_GE(slack, 2);  // the torque passes through zero between stretches
  EXPECT_LT(slack, 10);
}

// Without a tension (a belt's) or a pitch (teeth), the strands are not known: the pivots carry the weights alone,
// as without the belt's pull, and that is said at the first row.
TEST(BeltStrands, StrandsNotKnownAreToldAndPullNothing) {
  for (const std::string belt : {"{name: vee, type: belt, between: [driver, driven], radii: [0.08, 0.05]}",
                                 "{name: vee, type: belt, between: [driver, driven], teeth: [24, 15], tension: 50}"}) {
    SweepSummary sum;
    const ReactionRows r = test::sweep_reactions(belt_drive(belt), &sum);
    ASSERT_EQ(sum.warnings.size(), 1u) << belt;
    EXPECT_EQ(sum.warnings[0].kind, "unloaded_bearings");
    EXPECT_EQ(sum.warnings[0].t, 0.0);
    EXPECT_HAS(sum.warnings[0].message, "'vee'");
    EXPECT_HAS(sum.warnings[0].message, belt.find("teeth") == std::string::npos ? "no tension" : "no pitch");
    for (const std::vector<double>& v : r.values) {
      EXPECT_NEAR(v[3], 0.4 * 9.81, 1e-9);
      EXPECT_NEAR(v[6], 0.9 * 9.81, 1e-9);
    }
  }
  const std::string head = "phiq: 1\nname: b\ncoordinates: {a: 0, b: 0}\nconstraints:\n";
  EXPECT_EQ(test::scene_error(head + "  - {name: m, type: belt, between: [a, b], radii: [1, 2], tension: -1}\n"),
            "bad.yaml:5:5: constraints[0]: constraint 'm': belt: tension must be a force >= 0");
  EXPECT_EQ(test::scene_error(head + "  - {name: m, type: chain, between: [a, b], radii: [1, 2], pitch: 0.01}\n"),
            "bad.yaml:5:5: constraints[0]: constraint 'm': belt: a pitch goes with teeth");
}

}  // namespace
}  // namespace phiq
