// Motion laws: values and exact derivatives.
#include <gtest/gtest.h>

#include <cmath>

#include "phiq/expression.hpp"
#include "phiq/model.hpp"
#include "phiq/motion_law.hpp"

namespace phiq {
namespace {

void check_derivatives(const MotionLaw& law, double t, double tol) {
  const double h = 1e-5;
  LawValue v = law.evaluate(t), p = law.evaluate(t + h), m = law.evaluate(t - h);
  EXPECT_NEAR(v.df, (p.f - m.f) / (2 * h), tol) << law.description() << " at " << t;
  EXPECT_NEAR(v.ddf, (p.df - m.df) / (2 * h), tol) << law.description() << " at " << t;
}

TEST(MotionLaw, LinearPolynomialHarmonic) {
  MotionLaw lin = MotionLaw::linear(0.5, 2.0);
  EXPECT_DOUBLE_EQ(lin.evaluate(3.0).f, 6.5);
  EXPECT_DOUBLE_EQ(lin.evaluate(3.0).df, 2.0);
  EXPECT_DOUBLE_EQ(lin.evaluate(3.0).ddf, 0.0);
  MotionLaw poly = MotionLaw::polynomial({1.0, -2.0, 0.5, 0.25});
  LawValue v = poly.evaluate(2.0);
  EXPECT_DOUBLE_EQ(v.f, 1 - 4 + 2 + 2);
  EXPECT_DOUBLE_EQ(v.df, -2 + 2 + 3);
  EXPECT_DOUBLE_EQ(v.ddf, 1 + 3);
  MotionLaw harm = MotionLaw::harmonic(0.1, 0.5, 3.0, 0.2);
  EXPECT_NEAR(harm.evaluate(0.7).f, 0.1 + 0.5 * std::sin(2.3), 1e-15);
  EXPECT_NEAR(harm.evaluate(0.7).ddf, -4.5 * std::sin(2.3), 1e-14);
  for (double t : {0.0, 0.3, 1.7}) {
    check_derivatives(poly, t, 1e-7);
    check_derivatives(harm, t, 1e-7);
  }
}

TEST(MotionLaw, TableInterpolatesItsPointsAndIsExactForCubics) {
  std::vector<double> t = {0.0, 0.5, 1.2, 2.0, 2.5, 3.0}, v;
  for (double x : t) v.push_back(1.0 - x + 0.5 * x * x - 0.1 * x * x * x);
  MotionLaw tab = MotionLaw::table(t, v);
  for (std::size_t k = 0; k < t.size(); ++k) EXPECT_NEAR(tab.evaluate(t[k]).f, v[k], 1e-12);
  // a cubic is reproduced with its derivatives (not-a-knot-like B-spline interpolation)
  for (double x : {0.1, 0.9, 1.9, 2.8}) {
    LawValue l = tab.evaluate(x);
    EXPECT_NEAR(l.f, 1.0 - x + 0.5 * x * x - 0.1 * x * x * x, 1e-12);
    EXPECT_NEAR(l.df, -1.0 + x - 0.3 * x * x, 1e-11);
    EXPECT_NEAR(l.ddf, 1.0 - 0.6 * x, 1e-10);
  }
  EXPECT_DOUBLE_EQ(tab.domain_begin(), 0.0);
  EXPECT_DOUBLE_EQ(tab.domain_end(), 3.0);
  EXPECT_TRUE(std::isnan(tab.evaluate(3.5).f));
}

TEST(MotionLaw, TableOfNonPolynomialDataHasConsistentDerivatives) {
  std::vector<double> t, v;
  for (int k = 0; k <= 12; ++k) t.push_back(0.25 * k), v.push_back(std::sin(t.back()));
  MotionLaw tab = MotionLaw::table(t, v);
  for (double x : {0.4, 1.3, 2.2}) {
    check_derivatives(tab, x, 1e-6);
    EXPECT_NEAR(tab.evaluate(x).f, std::sin(x), 1e-3);
  }
}

TEST(MotionLaw, ExpressionLaw) {
  auto f = CompiledExpression::compile("0.1*t^3 + cos(2*t)", [](const std::string& n) -> std::optional<NameBinding> {
    if (n == "t") return NameBinding{NameBinding::Kind::kTime};
    return std::nullopt;
  });
  MotionLaw law = MotionLaw::expression(f);
  LawValue v = law.evaluate(0.6);
  EXPECT_NEAR(v.f, 0.1 * 0.216 + std::cos(1.2), 1e-15);
  EXPECT_NEAR(v.df, 0.3 * 0.36 - 2 * std::sin(1.2), 1e-14);
  EXPECT_NEAR(v.ddf, 0.6 * 0.6 - 4 * std::cos(1.2), 1e-14);
}

TEST(MotionLaw, ExpressionLawPowersThroughZero) {
  // f = 0.1 + (2t)² failed at t = 0 ("velocity is not finite"): GiNaC's derivative of (2t)^k was
  // (2t)^k·k·t^(-1), 0·∞ there. f' and f'' are the closed forms wherever the base is 0.
  auto time_only = [](const std::string& n) -> std::optional<NameBinding> {
    if (n == "t") return NameBinding{NameBinding::Kind::kTime};
    return std::nullopt;
  };
  auto law = [&](const std::string& text) { return MotionLaw::expression(CompiledExpression::compile(text, time_only)); };
  for (int round = 0; round < 4; ++round) {  // GiNaC's term order changes between compilations: each must hold
    LawValue a = law("0.1 + (2*t)^2").evaluate(0.0);
    EXPECT_EQ(a.f, 0.1);
    EXPECT_EQ(a.df, 0.0);
    EXPECT_DOUBLE_EQ(a.ddf, 8.0);
    LawValue b = law("0.1 + (t - 0.5)^2").evaluate(0.5);
    EXPECT_EQ(b.f, 0.1);
    EXPECT_EQ(b.df, 0.0);
    EXPECT_DOUBLE_EQ(b.ddf, 2.0);
    LawValue c = law("(0.5 - t)^3 + (3*t - 1.5)^4").evaluate(0.5);
    EXPECT_EQ(c.f, 0.0);
    EXPECT_EQ(c.df, 0.0);
    EXPECT_EQ(c.ddf, 0.0);
    LawValue d = law("(3*t)^(-2)").evaluate(1.0);  // t^-2 / 9 away from 0
    EXPECT_DOUBLE_EQ(d.f, 1.0 / 9);
    EXPECT_DOUBLE_EQ(d.df, -2.0 / 9);
    EXPECT_DOUBLE_EQ(d.ddf, 6.0 / 9);
  }
}

TEST(MotionLaw, InvalidData) {
  EXPECT_THROW(MotionLaw::table({0.0, 1.0, 1.0}, {0, 1, 2}), Error);
  EXPECT_THROW(MotionLaw::table({0.0}, {0}), Error);
  EXPECT_THROW(MotionLaw::table({0.0, 1.0}, {0}), Error);
  EXPECT_THROW(MotionLaw::linear(NAN, 1.0), Error);
  EXPECT_THROW(MotionLaw::polynomial({}), Error);
}

// A default-constructed law has no function, and every kind that holds a law refuses it where the constraint is
// added, naming it: it used to be accepted, made the model's time domain [0, 0] (limited by that driver) and threw
// only from inside Φ at the first solve.
TEST(MotionLaw, ADefaultConstructedLawHasNoFunctionAndNoDriverTakesIt) {
  EXPECT_FALSE(MotionLaw{}.has_value());
  EXPECT_TRUE(MotionLaw::linear(0.0, 1.0).has_value());
  EXPECT_THROW(MotionLaw{}.evaluate(0.0), Error);
  auto refusal = [](auto&& add) -> std::string {
    ModelBuilder b;
    for (const char* c : {"x", "y", "z", "e0", "e1", "e2", "e3"}) b.add_coordinate(c, c[0] == 'e' ? 0.5 : 0.0);
    try {
      add(b);
    } catch (const Error& e) {
      return e.what();
    }
    return "accepted";
  };
  const std::string refused = "': its motion law has no function (a default-constructed MotionLaw)";
  EXPECT_EQ(refusal([](ModelBuilder& b) { b.add_driver("motor", 0, MotionLaw{}); }),
            "constraint 'motor" + refused);
  EXPECT_EQ(refusal([](ModelBuilder& b) { b.add_driver("motor", 0, MotionLaw::linear(0.0, 1.0)); }), "accepted");
  const Frame3 body{Slot::coordinate(0), Slot::coordinate(1), Slot::coordinate(2), Slot::coordinate(3),
                    Slot::coordinate(4), Slot::coordinate(5), Slot::coordinate(6)};
  EXPECT_EQ(refusal([&](ModelBuilder& b) {
              b.add("turn", JointAngleDriverSpec{JointSide3::body(Frame3::ground(), {}), JointSide3::body(body, {}),
                                                 MotionLaw{}});
            }),
            "constraint 'turn" + refused);
  EXPECT_EQ(refusal([&](ModelBuilder& b) {
              b.add("lift", JointDistanceDriverSpec{JointSide3::body(Frame3::ground(), {}),
                                                    JointSide3::body(body, {}), MotionLaw{}});
            }),
            "constraint 'lift" + refused);
  const auto g = CompiledExpression::compile("x", [](const std::string& name) -> std::optional<NameBinding> {
    if (name == "x") return NameBinding{NameBinding::Kind::kCoordinate, 0};
    return std::nullopt;
  });
  EXPECT_EQ(refusal([&](ModelBuilder& b) { b.add("eq", EquationSpec{g, MotionLaw{}}); }), "constraint 'eq" + refused);
  EXPECT_EQ(refusal([&](ModelBuilder& b) { b.add("eq", EquationSpec{g, std::nullopt}); }), "accepted");
}

}  // namespace
}  // namespace phiq
