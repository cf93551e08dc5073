// The higher pairs on curves (kinds/curve.hpp, kinds/point_on_curve.hpp, kinds/flat_follower.hpp): the spline's
// fit and its convergence to the circle it samples, finite-difference checks of Φq, Φt and γ of both kinds with
// their added coordinate, the coordinate the model adds and its initial guess, and the checks of bad curves.
// Closed forms of whole mechanisms are in test_cams.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "constraint_check.hpp"
#include "phiq/constraint_kinds.hpp"
#include "phiq/model.hpp"

namespace {

using phiq::Curve;
using phiq::kin::V2;

std::vector<V2> circle_points(int n, V2 centre, double r, double phase = 0.3) {
  std::vector<V2> p;
  for (int k = 0; k < n; ++k) {
    const double a = phase + 2.0 * M_PI * k / n;
    p.push_back({centre.x + r * std::cos(a), centre.y + r * std::sin(a)});
  }
  return p;
}

// The largest distance from the circle of the closed spline through n of its points (sampled 50 times a piece).
double spline_circle_error(int n) {
  const V2 centre{0.1, -0.2};
  const double r = 0.5;
  auto c = Curve::spline(circle_points(n, centre, r), true);
  double worst = 0.0;
  V2 d[4];
  for (int k = 0; k < 50 * n; ++k) {
    c->evaluate(c->length() * k / (50.0 * n), d);
    worst = std::max(worst, std::fabs(std::hypot(d[0].x - centre.x, d[0].y - centre.y) - r));
  }
  return worst;
}

TEST(Curves, ClosedSplineThroughACircleConvergesToItAtFourthOrder) {
  const double e16 = spline_circle_error(16), e32 = spline_circle_error(32), e64 = spline_circle_error(64);
  // chord-length periodic cubic: error O(h⁴), a factor 16 per halving of the spacing
  EXPECT_LT(e16, 2e-4);
  EXPECT_GT(e16 / e32, 12.0);
  EXPECT_GT(e32 / e64, 12.0);
  EXPECT_LT(e64, 1e-6);
}

TEST(Curves, SplinePassesThroughItsPointsAndIsTwiceContinuous) {
  const std::vector<V2> p = {{0, 0}, {1, 0.5}, {2, 0.4}, {3, 0}, {3.5, -1}};
  for (bool closed : {false, true}) {
    auto c = Curve::spline(p, closed);
    EXPECT_EQ(c->closed(), closed);
    V2 d[4], lo[4], hi[4];
    double s = 0.0;
    for (std::size_t k = 0; k < p.size(); ++k) {
      c->evaluate(s, d);
      EXPECT_NEAR(d[0].x, p[k].x, 1e-14);
      EXPECT_NEAR(d[0].y, p[k].y, 1e-14);
      if (k > 0) {  // C² across the knot: c, c′, c″ from both pieces agree
        c->evaluate(s - 1e-12, lo), c->evaluate(s + 1e-12, hi);
        for (int o = 0; o < 3; ++o) {
          EXPECT_NEAR(lo[o].x, hi[o].x, 1e-9) << "order " << o;
          EXPECT_NEAR(lo[o].y, hi[o].y, 1e-9) << "order " << o;
        }
      }
      const V2 next = p[(k + 1) % p.size()];
      s += std::hypot(next.x - p[k].x, next.y - p[k].y);  // chord-length knots
    }
    if (closed) {
      EXPECT_NEAR(s, c->length(), 1e-14);
      c->evaluate(c->length() + 0.3, hi), c->evaluate(0.3, lo);  // periodic
      EXPECT_NEAR(hi[0].x, lo[0].x, 1e-14);
      EXPECT_NEAR(hi[2].y, lo[2].y, 1e-12);
    } else {
      c->evaluate(0.0, lo), c->evaluate(c->length(), hi);  // natural ends
      EXPECT_NEAR(std::hypot(lo[2].x, lo[2].y), 0.0, 1e-12);
      EXPECT_NEAR(std::hypot(hi[2].x, hi[2].y), 0.0, 1e-12);
    }
  }
}

TEST(Curves, CircleIsParameterisedByArcLength) {
  auto c = Curve::circle({0.2, 0.1}, 0.5);
  EXPECT_TRUE(c->closed());
  EXPECT_DOUBLE_EQ(c->length(), M_PI);
  V2 d[4];
  c->evaluate(0.5 * M_PI / 2, d);  // a quarter turn
  EXPECT_NEAR(d[0].x, 0.2, 1e-15);
  EXPECT_NEAR(d[0].y, 0.6, 1e-15);
  EXPECT_NEAR(std::hypot(d[1].x, d[1].y), 1.0, 1e-15);
  EXPECT_NEAR(c->nearest({0.2 + 3.0, 0.1 + 3.0}), 0.5 * M_PI / 4, 1e-12);
  EXPECT_NEAR(c->extreme({0.0, -1.0}), 0.5 * 3 * M_PI / 2, 1e-9);
}

TEST(Curves, NearestPointOfASpline) {
  auto c = Curve::spline(circle_points(24, {0, 0}, 1.0, 0.0), true);
  const double s = c->nearest({2.0 * std::cos(1.0), 2.0 * std::sin(1.0)});
  V2 d[4];
  c->evaluate(s, d);
  EXPECT_NEAR(std::atan2(d[0].y, d[0].x), 1.0, 1e-4);  // on the sampled circle, to its O(h⁴)
  // stationary: the distance is along the normal
  EXPECT_NEAR(phiq::kin::dot(d[0] - V2{2.0 * std::cos(1.0), 2.0 * std::sin(1.0)}, d[1]), 0.0, 1e-12);
}

TEST(Curves, BadCurvesAreRefusedWithOneLine) {
  auto message = [](auto make) {
    try {
      make();
    } catch (const phiq::Error& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  EXPECT_EQ(message([] {
              Curve::spline({{0, 0}, {1, 0}, {1, 1}}, true);
            }),
            "a spline needs at least 4 distinct points (3 given)");
  EXPECT_EQ(message([] {
              Curve::spline({{0, 0}, {1, 0}, {1, 0}, {1, 1}, {0, 1}}, false);
            }),
            "spline points 2 and 3 are the same point");
  // a closed spline's last point may repeat its first: it is dropped, leaving 3 here
  EXPECT_EQ(message([] {
              Curve::spline({{0, 0}, {1, 0}, {1, 1}, {0, 0}}, true);
            }),
            "a spline needs at least 4 distinct points (3 given)");
  EXPECT_EQ(message([] { Curve::circle({0, 0}, 0.0); }), "the circle's radius must be positive and finite");
  EXPECT_EQ(message([] {
              Curve::radius_table({0, 1, 1, 2}, {1, 1, 1, 1});
            }),
            "profile entry 3: the angles must increase");
  EXPECT_FALSE(Curve::spline({{0, 0}, {2, 0}, {2, 2}, {1, 0.5}, {0, 2}}, true)->convex());  // a notch
  EXPECT_TRUE(Curve::spline(circle_points(8, {0.3, 0}, 1.0), true)->convex());
}

// ---- finite-difference checks ---------------------------------------------------------------------------------

TEST(ConstraintKinds, PointOnCurveBodyOnBodySpline) {
  // a pin of body a (0..2) in a closed spline slot of body b (3..5), s = 6
  phiq::PointOnCurveSpec k{phiq::Frame2{S(0), S(1), S(2)},
                           {0.3, -0.2},
                           {phiq::Frame2{S(3), S(4), S(5)}, Curve::spline(circle_points(5, {0.1, 0}, 2.0), true)},
                           0.0,
                           S(6)};
  CheckSpec(k, 7, Opts(2701));
}

TEST(ConstraintKinds, PointOnCurveRollerOnACircleAndOnAGroundSpline) {
  // a roller (offset curve) of a body on a circle of a turning body
  phiq::PointOnCurveSpec roller{phiq::Frame2{S(0), S(1), S(2)},
                                {0.1, 0.25},
                                {phiq::Frame2{S(3), C(0.5), S(4)}, Curve::circle({0.3, -0.1}, 1.3)},
                                0.2,
                                S(5)};
  CheckSpec(roller, 6, Opts(2702));
  // a natural point on an open ground spline, offset: the spline continues its end pieces past its ends
  phiq::PointOnCurveSpec point{
      phiq::Frame2{S(1), S(0), C(0.0)},
      {0, 0},
      {phiq::Frame2{C(0.2), C(-0.1), C(0.4)}, Curve::spline({{-3, 0}, {-1, 1.5}, {1, 1.2}, {3.5, -0.5}}, false)},
      -0.15,
      S(2)};
  CheckSpec(point, 3, Opts(2703));
}

TEST(ConstraintKinds, FlatFollowerOnCircleAndSpline) {
  phiq::FlatFollowerSpec k{phiq::Frame2{S(0), S(1), S(2)},
                           {0.2, -0.1},
                           {0.6, 0.8},
                           {phiq::Frame2{S(3), S(4), S(5)}, Curve::circle({0.3, 0.1}, 0.9)},
                           S(6)};
  CheckSpec(k, 7, Opts(2704));
  phiq::FlatFollowerSpec g{phiq::Frame2{C(0.1), S(0), C(0.0)},
                           {0, 0},
                           {1, 0},
                           {phiq::Frame2{C(0), C(0), S(1)}, Curve::spline(circle_points(5, {0.2, 0}, 2.5), true)},
                           S(2)};
  CheckSpec(g, 3, Opts(2705));
}

// ---- derivatives along the data ----------------------------------------------------------------------------------

TEST(ConstraintKinds, PointOnCurveAlongItsData) {
  // a roller of a body on a circle of a turning cam whose pivot moves: the pivot, the roller's point and radius
  const auto circle = Curve::circle({0.3, -0.1}, 1.3);
  phiq::PointOnCurveSpec roller{
      phiq::Frame2{S(0), S(1), S(2)}, {0.1, 0.25}, {phiq::Frame2{C(0.2), C(0.5), S(3)}, circle}, 0.2, S(4)};
  phiq::PointOnCurveSpec rate{
      phiq::Frame2{C(0), C(0), C(0)}, {0.3, -0.7}, {phiq::Frame2{C(0.4), C(-0.6), C(0)}, circle}, 0.9, S(4)};
  CheckDataDerivative(roller, rate, 5, 2711);
  // a point at a constant angle (its turn a datum) on an open ground spline turned by a datum, offset
  const auto spline = Curve::spline({{-3, 0}, {-1, 1.5}, {1, 1.2}, {3.5, -0.5}}, false);
  phiq::PointOnCurveSpec point{
      phiq::Frame2{S(0), S(1), C(0.3)}, {0.2, -0.4}, {phiq::Frame2{C(0.2), C(-0.1), C(0.4)}, spline}, -0.15, S(2)};
  phiq::PointOnCurveSpec turns{
      phiq::Frame2{C(0), C(0), C(0.8)}, {-0.5, 0.6}, {phiq::Frame2{C(0.1), C(0.2), C(-0.5)}, spline}, 0.3, S(2)};
  CheckDataDerivative(point, turns, 3, 2712);
  // a pin in a slot of a moving body: only its local point moves (no offset, no frame data)
  phiq::PointOnCurveSpec pin{phiq::Frame2{S(0), S(1), S(2)},
                             {0.3, -0.2},
                             {phiq::Frame2{S(3), S(4), S(5)}, Curve::spline(circle_points(5, {0.1, 0}, 2.0), true)},
                             0.0,
                             S(6)};
  phiq::PointOnCurveSpec arm = pin;
  arm.a = phiq::Frame2{C(0), C(0), C(0)}, arm.sa = {1.0, 0.5}, arm.on.frame = arm.a;
  CheckDataDerivative(pin, arm, 7, 2713);
}

TEST(ConstraintKinds, FlatFollowerAlongItsData) {
  // a follower body on a circle of a cam turning about a pivot that moves: the face's point and direction, the pivot
  const auto circle = Curve::circle({0.3, 0.1}, 0.9);
  phiq::FlatFollowerSpec k{
      phiq::Frame2{S(0), S(1), S(2)}, {0.2, -0.1}, {0.6, 0.8}, {phiq::Frame2{C(0.1), C(0.2), S(3)}, circle}, S(4)};
  phiq::FlatFollowerSpec rate{
      phiq::Frame2{C(0), C(0), C(0)}, {0.2, 0.5}, {-0.3, 0.4}, {phiq::Frame2{C(0.3), C(-0.2), C(0)}, circle}, S(4)};
  CheckDataDerivative(k, rate, 5, 2714);
  // a translating follower at a constant angle (a datum) on a ground profile turned by a datum
  const auto profile = Curve::spline(circle_points(5, {0.2, 0}, 2.5), true);
  phiq::FlatFollowerSpec g{
      phiq::Frame2{C(0.1), S(0), C(0.2)}, {0.1, 0.3}, {1, 0}, {phiq::Frame2{C(0.05), C(-0.02), C(0.3)}, profile}, S(1)};
  phiq::FlatFollowerSpec every{phiq::Frame2{C(0.4), C(0), C(0.7)},
                               {-0.3, 0.2},
                               {0.1, 0.9},
                               {phiq::Frame2{C(-0.2), C(0.6), C(-0.4)}, profile},
                               S(1)};
  CheckDataDerivative(g, every, 2, 2715);
  // a follower on a cam, both bodies free: only the face's point moves (every frame slot is a coordinate)
  phiq::FlatFollowerSpec both{
      phiq::Frame2{S(0), S(1), S(2)}, {0, 0}, {1, 0}, {phiq::Frame2{S(3), S(4), S(5)}, profile}, S(6)};
  phiq::FlatFollowerSpec point = both;
  point.a = phiq::Frame2{C(0), C(0), C(0)}, point.sa = {0.7, -0.2}, point.axis = {0, 0}, point.on.frame = point.a;
  CheckDataDerivative(both, point, 7, 2716);
}

// ---- the added coordinate -------------------------------------------------------------------------------------

TEST(CurveKinds, TheModelAddsTheCurveParameterWithItsNearestPointAsGuess) {
  phiq::ModelBuilder b;
  const Index x = b.add_coordinate("x", 0.3), y = b.add_coordinate("y", 2.0);
  const Index id = b.add("slot", phiq::PointOnCurveSpec{phiq::Frame2{S(x), S(y), C(0)},
                                                        {0, 0},
                                                        {phiq::Frame2{C(0), C(0), C(0)}, Curve::circle({0, 0}, 1.0)},
                                                        0.0,
                                                        C(0)});
  b.add_driver("drive", x, phiq::MotionLaw::linear(0.3, 0.0));
  EXPECT_EQ(b.num_coordinates(), 3);
  EXPECT_EQ(b.coordinate_name(2), "slot.s");
  // a second constraint of that name adds nothing
  EXPECT_THROW(b.add("slot", phiq::PointOnCurveSpec{phiq::Frame2{S(x), S(y), C(0)},
                                                    {0, 0},
                                                    {phiq::Frame2{C(0), C(0), C(0)}, Curve::circle({0, 0}, 1.0)},
                                                    0.0,
                                                    C(0)}),
               phiq::Error);
  EXPECT_EQ(b.num_coordinates(), 3);
  const phiq::Model m = std::move(b).build();
  EXPECT_EQ(id, 0);
  // the parameter of the point of the unit circle nearest to (0.3, 2): its angle, as arc length
  EXPECT_NEAR(m.initial_positions()(2), std::atan2(2.0, 0.3), 1e-12);
  EXPECT_FALSE(m.grubler().has_value());  // a natural point: no joint count
  CheckModel(m, 2706);                    // the added coordinate's column in the model's CSC pattern and evaluations
}

TEST(CurveKinds, AFlatFollowerNeedsAConvexProfile) {
  phiq::ModelBuilder b;
  const Index y = b.add_coordinate("y", 3.0), th = b.add_coordinate("th", 0.0);
  auto notch = Curve::spline({{0, 0}, {2, 0}, {2, 2}, {1, 0.5}, {0, 2}}, true);
  try {
    b.add("cam", phiq::FlatFollowerSpec{
                     phiq::Frame2{C(0), S(y), C(0)}, {0, 0}, {1, 0}, {phiq::Frame2{C(0), C(0), S(th)}, notch}, C(0)});
    ADD_FAILURE() << "a notched profile accepted";
  } catch (const phiq::Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "constraint 'cam': flat_cam: the profile is not convex (it turns both ways): a flat face would touch "
              "it at more than one point");
  }
  EXPECT_EQ(b.num_coordinates(), 2);
}

}  // namespace
