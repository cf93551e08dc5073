// Cams and slots against their closed forms (the scenes of models/cams and models/slots): an eccentric circular cam
// with a flat-faced, a knife-edge and a roller follower translating along y, a pin in a circular slot, and a pin in
// a spline slot through points of that circle; positions, velocities and accelerations to 1e-9. And the sweep that
// stops where the parameter of an open curve passes its end, with the constraint and the time named.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>

#include "test_support.hpp"

namespace phiq {
namespace {

// (value, first, second derivative) of a coordinate against time
struct Exact {
  double q, v, a;
};

// Sweeps the scene and compares coordinate `name` with `exact(t)` at every row: returns the rows compared.
int compare_with(const Scene& scene, const std::string& name, const std::function<Exact(double)>& exact,
                 double tol = 1e-9) {
  const Index j = scene.model->find_coordinate(name);
  EXPECT_GE(j, 0) << name;
  test::Trace tr;
  SweepSummary sum;
  EXPECT_EQ(test::sweep(*scene.model, scene.sweep, &tr, &sum), SolveStatus::kSuccess) << sum.message;
  double wq = 0, wv = 0, wa = 0;
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    const Exact e = exact(tr.t[k]);
    wq = std::max(wq, std::fabs(tr.q[k](j) - e.q));
    wv = std::max(wv, std::fabs(tr.qd[k](j) - e.v));
    wa = std::max(wa, std::fabs(tr.qdd[k](j) - e.a));
  }
  EXPECT_LT(wq, tol) << name;
  EXPECT_LT(wv, tol) << name;
  EXPECT_LT(wa, tol) << name;
  return static_cast<int>(tr.t.size());
}

// y = e sin θ + √(ρ² − e² cos² θ) with θ = ω t: where the y axis meets a circle of radius ρ about (e cos θ, e sin θ).
Exact axis_meets_circle(double t, double e, double rho, double omega) {
  const double th = omega * t, c = std::cos(th), s = std::sin(th);
  const double d = std::sqrt(rho * rho - e * e * c * c);
  const double d1 = e * e * c * s / d;
  const double d2 = e * e * (c * c - s * s) / d - std::pow(e, 4) * c * c * s * s / (d * d * d);
  return {e * s + d, omega * (e * c + d1), omega * omega * (-e * s + d2)};
}

constexpr double kR = 0.05, kE = 0.015, kOmega = 2.0;

TEST(Cams, EccentricCircleWithAFlatFollowerLiftsItToRPlusESinTheta) {
  const Scene s = load_scene(test::model_path("cams/eccentric_flat.yaml"));
  EXPECT_EQ(s.model->num_coordinates(), 7);  // six of the bodies and cam.s
  ASSERT_TRUE(s.model->grubler().has_value());
  EXPECT_EQ(*s.model->grubler(), 1);  // 3·2 − 2 − 2 − 1: the cam's turn
  const int rows = compare_with(s, "yf", [](double t) {
    return Exact{kR + kE * std::sin(kOmega * t), kE * kOmega * std::cos(kOmega * t),
                 -kE * kOmega * kOmega * std::sin(kOmega * t)};
  });
  EXPECT_EQ(rows, 73);
  // the contact is the top of the circle: its parameter (arc length from the circle's angle 0 in the disc's frame)
  // is R (π/2 − θ), continuous across the turn
  compare_with(s, "cam.s", [](double t) { return Exact{kR * (M_PI / 2 - kOmega * t), -kR * kOmega, 0.0}; });
}

TEST(Cams, EccentricCircleWithAKnifeEdgeFollowerMeetsTheCircle) {
  const Scene s = load_scene(test::model_path("cams/eccentric_knife.yaml"));
  compare_with(s, "yf", [](double t) { return axis_meets_circle(t, kE, kR, kOmega); });
}

TEST(Cams, ARollerFollowerRunsOnTheOffsetCurve) {
  const Scene s = load_scene(test::model_path("cams/eccentric_roller.yaml"));
  compare_with(s, "yf", [](double t) { return axis_meets_circle(t, kE, kR + 0.01, kOmega); });
}

TEST(Slots, APinInACircularSlotFollowsTheCircle) {
  const Scene s = load_scene(test::model_path("slots/circular_slot.yaml"));
  const double cx = 0.2, cy = 0.1, r = 0.5, v = 0.35;
  compare_with(s, "y", [&](double t) {
    const double dx = -0.15 + v * t - cx, h = std::sqrt(r * r - dx * dx);
    const double yd = -dx * v / h;
    return Exact{cy + h, yd, -(v * v + yd * yd) / h};
  });
}

// The circular slot of circular_slot.yaml as a closed spline through n of its points: the pin's height converges
// to the circle's at fourth order.
double spline_slot_error(int n) {
  std::string points;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    points += (k ? ", [" : "[") + shortest(0.2 + 0.5 * std::cos(a)) + ", " + shortest(0.1 + 0.5 * std::sin(a)) + "]";
  }
  std::ifstream in(test::model_path("slots/circular_slot.yaml"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text = test::replace_first(text, "circle: {centre: [cx, cy], radius: r}", "spline: [" + points + "], closed: true");
  const Scene s = parse_scene(text, "spline_slot.yaml");
  test::Trace tr;
  SweepSummary sum;
  EXPECT_EQ(test::sweep(*s.model, s.sweep, &tr, &sum), SolveStatus::kSuccess) << sum.message;
  double worst = 0;
  for (std::size_t k = 0; k < tr.t.size(); ++k)
    worst = std::max(worst, std::fabs(tr.q[k](1) - 0.1 - std::sqrt(0.25 - std::pow(tr.q[k](0) - 0.2, 2))));
  return worst;
}

TEST(Slots, ASplineSlotThroughPointsOfACircleConvergesToIt) {
  const double e12 = spline_slot_error(12), e24 = spline_slot_error(24), e48 = spline_slot_error(48);
  EXPECT_LT(e12, 2e-3);
  EXPECT_GT(e12 / e24, 8.0);
  EXPECT_GT(e24 / e48, 8.0);
  EXPECT_LT(e48, 2e-5);
}

TEST(Slots, ThePinLeavingAnOpenSlotStopsTheSweepNamingTheSlotAndTheTime) {
  // the pushed pin of circular_slot.yaml in an open slot y = 0.1 + 0.1 sin x from x = −0.2 to 0.4: pushed from
  // x = −0.15 at 0.35 m/s, it reaches the end at t = 0.55 / 0.35 = 1.571…, and the step to t = 1.6 passes it
  std::ifstream in(test::model_path("slots/circular_slot.yaml"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string points;
  for (int k = 0; k <= 6; ++k) {
    const double x = -0.2 + 0.1 * k;
    points += (k ? ", [" : "[") + shortest(x) + ", " + shortest(0.1 + 0.1 * std::sin(x)) + "]";
  }
  text = test::replace_first(text, "circle: {centre: [cx, cy], radius: r}", "spline: [" + points + "]");
  const Scene s = parse_scene(text, "open_slot.yaml");
  test::Trace tr;
  SweepSummary sum;
  EXPECT_EQ(test::sweep(*s.model, s.sweep, &tr, &sum), SolveStatus::kOutsideDomain);
  EXPECT_HAS(sum.message, "step 32, t = 1.6: constraint 'slot': the curve parameter s = ");
  EXPECT_HAS(sum.message, "has left the open curve past its end (s = ");
  EXPECT_EQ(tr.t.size(), 32u);  // t = 0 … 1.55
  EXPECT_STREQ(to_string(SolveStatus::kOutsideDomain), "outside a constraint's domain");
  for (std::size_t k = 0; k < tr.t.size(); ++k) EXPECT_LE(tr.q[k](0), 0.4) << tr.t[k];
}

TEST(Cams, BadCurvesNameTheConstraint) {
  std::ifstream in(test::model_path("cams/eccentric_flat.yaml"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string three = test::replace_first(text, "circle: {centre: [e, 0], radius: R}",
                                                "spline: [[0, 0], [1, 0], [0, 1]], closed: true");
  EXPECT_HAS(test::scene_error(three), "flat_cam 'cam': a spline needs at least 4 distinct points (3 given)");
  const std::string repeated = test::replace_first(text, "circle: {centre: [e, 0], radius: R}",
                                                   "spline: [[0, 0], [1, 0], [1, 0], [1, 1], [0, 1]], closed: true");
  EXPECT_HAS(test::scene_error(repeated), "spline points 2 and 3 are the same point");
  const std::string notch = test::replace_first(text, "circle: {centre: [e, 0], radius: R}",
                                                "spline: [[0, 0], [2, 0], [2, 2], [1, 0.5], [0, 2]], closed: true");
  EXPECT_HAS(test::scene_error(notch), "constraint 'cam': flat_cam: the profile is not convex");
  const std::string unnamed = test::replace_first(text, "{name: cam, type: flat_cam", "{type: flat_cam");
  EXPECT_HAS(test::scene_error(unnamed),
             "a constraint with a coordinate of its own needs a name (its coordinate "
             "is NAME.s)");
}

}  // namespace
}  // namespace phiq
