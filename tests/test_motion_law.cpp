// Motion laws: values and exact derivatives; periodic tables across their seam.
#include <gtest/gtest.h>

#include <cmath>

#include "phiq/expression.hpp"
#include "phiq/model.hpp"
#include "phiq/motion_law.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

template <class Family>
void check_rate(const Family& law, double p, double h, double tol);

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

TEST(MotionLaw, APeriodicTableRepeatsAndIsC2AcrossItsSeam) {
  // sin over one period at uneven times: the cyclic spline interpolates its points, repeats with the period at
  // every t (before t_0 too), and its f, f′, f″ meet across the seam t_0 ≡ t_n
  std::vector<double> t, v;
  for (int k = 0; k <= 24; ++k) {
    const double x = 2 * M_PI * (k + 0.3 * std::sin(k)) / 24;
    t.push_back(x), v.push_back(std::sin(x));
  }
  t.front() = 0.0, t.back() = 2 * M_PI, v.front() = v.back() = 0.0;
  const MotionLaw tab = MotionLaw::table(t, v, true);
  EXPECT_EQ(tab.domain_begin(), -INFINITY);
  EXPECT_EQ(tab.domain_end(), INFINITY);
  for (std::size_t k = 0; k < t.size(); ++k) EXPECT_NEAR(tab.evaluate(t[k]).f, v[k], 1e-14) << k;
  for (double x : {0.4, 1.3, 3.9, 5.5}) {
    const LawValue a = tab.evaluate(x);
    EXPECT_NEAR(a.f, std::sin(x), 2e-4) << x;
    EXPECT_NEAR(a.df, std::cos(x), 5e-3) << x;
    for (double shift : {-2.0, 3.0}) {
      const LawValue b = tab.evaluate(x + shift * 2 * M_PI);
      EXPECT_NEAR(b.f, a.f, 1e-12);
      EXPECT_NEAR(b.df, a.df, 1e-11);
      EXPECT_NEAR(b.ddf, a.ddf, 1e-10);
    }
    check_derivatives(tab, x, 1e-6);
  }
  const double e = 1e-9;
  const LawValue before = tab.evaluate(2 * M_PI - e), after = tab.evaluate(2 * M_PI + e);
  EXPECT_NEAR(before.f, after.f, 1e-8);
  EXPECT_NEAR(before.df, after.df, 1e-7);
  EXPECT_NEAR(before.ddf, after.ddf, 1e-6);
  EXPECT_GT(std::fabs(tab.evaluate(1.0).ddf), 0.5);  // (the second derivative is not trivially 0)
  // the rate along values that move with p: the periodic table of their rates
  check_rate(
      [](double p) {
        return MotionLaw::table({0.0, 0.7, 1.5, 2.2, 3.0}, {p, 0.2 * p * p, -0.3, 1.0 - p, p}, true);
      },
      0.7, 0.07, 1e-9);
  EXPECT_THROW(MotionLaw::table({0.0, 1.0}, {0.0, 0.0}, true), Error);            // 2 points
  EXPECT_THROW(MotionLaw::table({0.0, 1.0, 2.0}, {0.0, 1.0, 0.5}, true), Error);  // does not close
}

TEST(MotionLaw, APeriodicTableDrivesASweepPastItsPeriod) {
  // the seed crank-slider's crank swung by a periodic table over 1 s, swept over 3 s: no time limit, and the
  // motion repeats each period
  std::string text = test::model_file_text("seed/crank_slider_mixed.yaml", "time:");
  const std::string law = "law: {type: linear, initial: 0, rate: 2}";
  ASSERT_NE(text.find(law), std::string::npos);
  text.replace(text.find(law), law.size(),
               "law: {type: table, t: [0, 0.3, 0.5, 0.8, 1], values: [0, 0.8, 2.0, 0.9, 0], periodic: true}");
  Scene s = parse_scene(text + "time: {start: 0, end: 3, steps: 60}\n", "crank_slider_periodic.yaml");
  s.sweep.velocities = true;
  EXPECT_GT(s.model->time_domain_end(), 1e300);  // (no driver limits it)
  test::Trace tr;
  ASSERT_EQ(test::sweep(*s.model, s.sweep, &tr), SolveStatus::kSuccess);
  ASSERT_EQ(tr.t.size(), 61u);
  ASSERT_EQ(tr.qd.size(), 61u);
  const Index theta = s.model->find_coordinate("theta2");
  const MotionLaw swing = MotionLaw::table({0, 0.3, 0.5, 0.8, 1}, {0, 0.8, 2.0, 0.9, 0}, true);
  for (std::size_t k = 0; k + 20 < tr.t.size(); ++k) {
    EXPECT_NEAR(tr.q[k](theta), swing.evaluate(tr.t[k]).f, 1e-12) << tr.t[k];
    EXPECT_LT((tr.q[k + 20] - tr.q[k]).cwiseAbs().maxCoeff(), 1e-9) << tr.t[k];
    EXPECT_LT((tr.qd[k + 20] - tr.qd[k]).cwiseAbs().maxCoeff(), 1e-8) << tr.t[k];
  }
  std::string open = text;
  open.replace(open.find("0.9, 0]"), 7, "0.9, 0.1]");
  EXPECT_NE(test::scene_error(open + "time: {start: 0, end: 3, steps: 60}\n")
                .find("law.values: a periodic table ends where it starts: its last value is not its first"),
            std::string::npos);
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
  auto law = [&](const std::string& text) {
    return MotionLaw::expression(CompiledExpression::compile(text, time_only));
  };
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
  EXPECT_EQ(refusal([](ModelBuilder& b) { b.add_driver("motor", 0, MotionLaw{}); }), "constraint 'motor" + refused);
  EXPECT_EQ(refusal([](ModelBuilder& b) { b.add_driver("motor", 0, MotionLaw::linear(0.0, 1.0)); }), "accepted");
  const Frame3 body{Slot::coordinate(0), Slot::coordinate(1), Slot::coordinate(2), Slot::coordinate(3),
                    Slot::coordinate(4), Slot::coordinate(5), Slot::coordinate(6)};
  EXPECT_EQ(refusal([&](ModelBuilder& b) {
              b.add("turn", JointAngleDriverSpec{JointSide3::body(Frame3::ground(), {}), JointSide3::body(body, {}),
                                                 MotionLaw{}});
            }),
            "constraint 'turn" + refused);
  EXPECT_EQ(refusal([&](ModelBuilder& b) {
              b.add("lift", JointDistanceDriverSpec{JointSide3::body(Frame3::ground(), {}), JointSide3::body(body, {}),
                                                    MotionLaw{}});
            }),
            "constraint 'lift" + refused);
  const auto g = CompiledExpression::compile("x", [](const std::string& name) -> std::optional<NameBinding> {
    if (name == "x") return NameBinding{NameBinding::Kind::kCoordinate, 0};
    return std::nullopt;
  });
  EXPECT_EQ(refusal([&](ModelBuilder& b) { b.add("eq", EquationSpec{g, MotionLaw{}}); }), "constraint 'eq" + refused);
  EXPECT_EQ(refusal([&](ModelBuilder& b) { b.add("eq", EquationSpec{g, std::nullopt}); }), "accepted");
}

// ---- a law's rate along a design parameter ------------------------------------------------------------------------

// A family of laws law(p) and the rate MotionLaw::rate_along gives at p, against the sixth-order central difference
// of f, f′, f″ over p with steps other than the rate's own (independent of its formulas), at times across [0, 3].
template <class Family>
void check_rate(const Family& law, double p, double h, double tol) {
  const MotionLaw at = law(p), m2 = law(p - 2 * h), m1 = law(p - h), p1 = law(p + h), p2 = law(p + 2 * h);
  const MotionLaw rate = MotionLaw::rate_along(at, {&m2, &m1, &p1, &p2}, h);
  ASSERT_TRUE(rate.has_value());
  const double e = 2e-3;
  for (double t = 0.0; t <= 3.0; t += 0.25) {
    LawValue d[6];
    const double off[6] = {-3, -2, -1, 1, 2, 3};
    for (int k = 0; k < 6; ++k) d[k] = law(p + off[k] * e).evaluate(t);
    auto fd = [&](double LawValue::*m) {
      return (-(d[0].*m) + 9 * (d[1].*m) - 45 * (d[2].*m) + 45 * (d[3].*m) - 9 * (d[4].*m) + (d[5].*m)) / (60 * e);
    };
    const LawValue r = rate.evaluate(t);
    EXPECT_NEAR(r.f, fd(&LawValue::f), tol) << at.description() << ", t = " << t;
    EXPECT_NEAR(r.df, fd(&LawValue::df), tol) << at.description() << ", t = " << t;
    EXPECT_NEAR(r.ddf, fd(&LawValue::ddf), tol) << at.description() << ", t = " << t;
  }
  check_derivatives(rate, 1.3, 1e-6);  // the rate law's own f′, f″ are its derivatives in t
}

TEST(MotionLaw, RateAlongItsDataIsExact) {
  // data of degree ≤ 4 in p: their differences are exact, and f is differentiated along them exactly; a large
  // step (10 % of p) shows that nothing of f itself is differenced
  check_rate([](double p) { return MotionLaw::linear(0.3 * p * p, 2.0 - p); }, 0.7, 0.07, 1e-9);
  check_rate([](double p) { return MotionLaw::polynomial({p, -p * p, 0.5, 0.2 * p * p * p}); }, 0.7, 0.07, 1e-9);
  check_rate([](double p) { return MotionLaw::harmonic(0.1 + p * p, 0.5 + 0.3 * p, 2.0 + p - 0.2 * p * p, 0.2 * p); },
             0.7, 0.07, 1e-8);
  // an expression: differentiated along the parameters its text reads (CompiledExpression::along_constants())
  check_rate(
      [](double p) {
        return MotionLaw::expression(
            CompiledExpression::compile("a*sin(a*t) + b*t^2", [p](const std::string& n) -> std::optional<NameBinding> {
              if (n == "t") return NameBinding{NameBinding::Kind::kTime};
              if (n == "a") return NameBinding{NameBinding::Kind::kConstant, -1, p};
              if (n == "b") return NameBinding{NameBinding::Kind::kConstant, -1, 0.5 - p * p};
              return std::nullopt;
            }));
      },
      1.2, 0.12, 1e-8);
  // a table's values that move (its times fixed): the spline is linear in the values
  check_rate(
      [](double p) {
        return MotionLaw::table({-0.5, 0.4, 1.1, 2.0, 3.5}, {p, 0.2 * p * p, -0.3, 1.0 - p, 0.5 * p});
      },
      0.7, 0.07, 1e-9);
}

TEST(MotionLaw, RateOfLawsWhoseDataDoNotMatchIsTheirDifference) {
  // an expression whose exponent moves (its power of a constant exponent has no rate along it): the four laws
  // are differenced, fourth order in h
  auto expression = [](double p) {
    return MotionLaw::expression(
        CompiledExpression::compile("a*sin(t) + (1 + t)^a", [p](const std::string& n) -> std::optional<NameBinding> {
          if (n == "t") return NameBinding{NameBinding::Kind::kTime};
          if (n == "a") return NameBinding{NameBinding::Kind::kConstant, -1, p};
          return std::nullopt;
        }));
  };
  check_rate(expression, 1.2, 1e-3, 1e-8);
  // a table whose times move has other knots: differenced too, defined where all four are
  auto moving = [](double p) { return MotionLaw::table({0.0, 1.0 + 0.1 * p, 3.0}, {0.0, 1.0, p}); };
  check_rate(moving, 0.5, 1e-3, 1e-7);
  const MotionLaw at = moving(0.5), m2 = moving(0.3), m1 = moving(0.4), p1 = moving(0.6), p2 = moving(0.7);
  const MotionLaw rate = MotionLaw::rate_along(at, {&m2, &m1, &p1, &p2}, 0.1);
  EXPECT_EQ(rate.domain_begin(), 0.0);
  EXPECT_EQ(rate.domain_end(), 3.0);
  // laws of another kind along the parameter
  const MotionLaw lin = MotionLaw::linear(0.0, 1.0), harm = MotionLaw::harmonic(0.0, 1.0, 1.0, 0.0);
  const MotionLaw mixed = MotionLaw::rate_along(lin, {&lin, &lin, &harm, &harm}, 0.5);
  const double t = 0.8;
  EXPECT_NEAR(mixed.evaluate(t).f, (1.0 / 12 - 8.0 / 12) * t / 0.5 + (8.0 / 12 - 1.0 / 12) * std::sin(t) / 0.5, 1e-15);
}

TEST(MotionLaw, SumOfLaws) {
  const MotionLaw a = MotionLaw::linear(1.0, 2.0), b = MotionLaw::table({0.0, 1.0, 2.0}, {0.0, 1.0, 0.0});
  const MotionLaw s = MotionLaw::sum({{0.5, a}, {-2.0, b}});
  for (double t : {0.0, 0.3, 1.7}) {
    const LawValue x = a.evaluate(t), y = b.evaluate(t), v = s.evaluate(t);
    EXPECT_DOUBLE_EQ(v.f, 0.5 * x.f - 2.0 * y.f);
    EXPECT_DOUBLE_EQ(v.df, 0.5 * x.df - 2.0 * y.df);
    EXPECT_DOUBLE_EQ(v.ddf, 0.5 * x.ddf - 2.0 * y.ddf);
  }
  EXPECT_EQ(s.domain_begin(), 0.0);
  EXPECT_EQ(s.domain_end(), 2.0);
  EXPECT_TRUE(std::isnan(s.evaluate(2.5).f));
  EXPECT_TRUE(s == MotionLaw::sum({{0.5, a}, {-2.0, b}}));
  EXPECT_FALSE(s == MotionLaw::sum({{0.5, a}, {-2.5, b}}));
  EXPECT_THROW(MotionLaw::sum({}), Error);
  EXPECT_THROW(MotionLaw::sum({{std::nan(""), a}}), Error);
  EXPECT_THROW(MotionLaw::sum({{1.0, MotionLaw{}}}), Error);
}

}  // namespace
}  // namespace phiq
