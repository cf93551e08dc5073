// Equation constraints from text: parsing, exact derivatives, the compiled tape, errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <fstream>

#include "phiq/expression.hpp"
#include "test_support.hpp"
#include "scratch_path.hpp"

namespace phiq {
namespace {

// q = [theta2, xA, yA]; L2 = 0.3.
std::optional<NameBinding> resolve(const std::string& n) {
  if (n == "theta2") return NameBinding{NameBinding::Kind::kCoordinate, 0};
  if (n == "xA") return NameBinding{NameBinding::Kind::kCoordinate, 1};
  if (n == "yA") return NameBinding{NameBinding::Kind::kCoordinate, 2};
  if (n == "unused") return NameBinding{NameBinding::Kind::kCoordinate, 7};
  if (n == "L2") return NameBinding{NameBinding::Kind::kConstant, -1, 0.3};
  if (n == "t") return NameBinding{NameBinding::Kind::kTime};
  return std::nullopt;
}

TEST(Expression, ValueGradientAndGammaOfTheNotesCrankRow) {
  auto e = CompiledExpression::compile("xA - L2*cos(theta2)", resolve);
  EXPECT_EQ(e->coordinates(), (std::vector<Index>{0, 1}));
  EXPECT_FALSE(e->depends_on_time());
  const double q[3] = {0.7, 0.2, -0.1}, qd[3] = {2.0, 0.5, 0.0};
  EXPECT_DOUBLE_EQ(e->value(q, 0.0), 0.2 - 0.3 * std::cos(0.7));
  double g[2];
  e->gradient(q, 0.0, g);
  EXPECT_DOUBLE_EQ(g[0], 0.3 * std::sin(0.7));  // the notes' Φq row: [L2 sin θ2, 1, 0, 0]
  EXPECT_DOUBLE_EQ(g[1], 1.0);
  // γ = −θ̇² L2 cos θ2 (notes, worked example)
  EXPECT_NEAR(e->gamma(q, qd, 0.0), -4.0 * 0.3 * std::cos(0.7), 1e-15);
}

TEST(Expression, TimeDerivativesAreExact) {
  auto e = CompiledExpression::compile("xA*t^2 + sin(3*t)*yA", resolve);
  EXPECT_TRUE(e->depends_on_time());
  EXPECT_EQ(e->coordinates(), (std::vector<Index>{1, 2}));
  const double q[3] = {0, 1.5, -2.0}, qd[3] = {0, 0.4, 0.7}, t = 0.8;
  // Φt = 2 xA t + 3 cos(3t) yA
  EXPECT_NEAR(e->partial_t(q, t), 2 * 1.5 * t + 3 * std::cos(3 * t) * -2.0, 1e-14);
  // γ = −(2 Φ_{q t} q̇ + Φtt) = −(2 (2t ẋA + 3 cos 3t ẏA) + 2 xA − 9 sin 3t yA)
  const double expect = -(2 * (2 * t * 0.4 + 3 * std::cos(3 * t) * 0.7) + 2 * 1.5 - 9 * std::sin(3 * t) * -2.0);
  EXPECT_NEAR(e->gamma(q, qd, t), expect, 1e-13);
}

TEST(Expression, SecondDerivativesAgainstFiniteDifferences) {
  auto e =
      CompiledExpression::compile("atan2(yA, xA) * sqrt(xA^2 + yA^2) + exp(-theta2) / (1 + xA^2) + abs(yA)^3", resolve);
  const double q[3] = {0.3, 0.8, -0.6}, qd[3] = {-1.1, 0.7, 0.4};
  // −γ = d²/ds² g(q + s q̇) at s = 0 (no t); Richardson on central differences
  auto g_at = [&](double s) {
    double x[3] = {q[0] + s * qd[0], q[1] + s * qd[1], q[2] + s * qd[2]};
    return e->value(x, 0.0);
  };
  auto d2 = [&](double h) { return (g_at(h) - 2 * g_at(0) + g_at(-h)) / (h * h); };
  const double rich = (4 * d2(1e-3) - d2(2e-3)) / 3;
  EXPECT_NEAR(-e->gamma(q, qd, 0.0), rich, 1e-8);
  double grad[3];
  e->gradient(q, 0.0, grad);
  for (int j = 0; j < 3; ++j) {
    double a[3] = {q[0], q[1], q[2]}, b[3] = {q[0], q[1], q[2]};
    a[j] += 1e-6, b[j] -= 1e-6;
    EXPECT_NEAR(grad[j], (e->value(a, 0) - e->value(b, 0)) / 2e-6, 1e-8) << j;
  }
}

TEST(Expression, CommonSubexpressionsAreSharedOnTheTape) {
  // cos(theta2) appears four times in the text; the value tape computes it once.
  auto a = CompiledExpression::compile("cos(theta2) + cos(theta2)*xA + cos(theta2)*yA + cos(theta2)^2", resolve);
  auto b = CompiledExpression::compile("cos(theta2)", resolve);
  const double q[3] = {0.4, 2.0, 3.0};
  const double c = std::cos(0.4);
  EXPECT_DOUBLE_EQ(a->value(q, 0), c + c * 2 + c * 3 + c * c);
  EXPECT_EQ(b->value(q, 0), c);
}

TEST(Expression, UnusedNamesDoNotBecomeColumns) {
  auto e = CompiledExpression::compile("xA + 0*unused", resolve);
  EXPECT_EQ(e->coordinates(), (std::vector<Index>{1}));
}

TEST(Expression, ErrorsNameTheTextAndTheProblem) {
  auto message = [](const std::string& text, bool allow_time = true) {
    try {
      CompiledExpression::compile(text, resolve, allow_time);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message("xA - L3"), "expression \"xA - L3\": unknown name 'L3'");
  EXPECT_NE(message("xA - (yA").find("expression \"xA - (yA\""), std::string::npos);
  EXPECT_NE(message("xA - frob(yA)").find("frob"), std::string::npos);
  EXPECT_EQ(message("xA*t", false), "expression \"xA*t\": time 't' is not allowed here");
  EXPECT_EQ(message("   "), "expression is empty");
  // 1e-3 is a number, not the name 'e'
  EXPECT_NO_THROW(CompiledExpression::compile("1e-3*xA + 2.5E+2*yA", resolve));
}

std::string compile_message(const std::string& text) {
  try {
    CompiledExpression::compile(text, resolve);
  } catch (const Error& e) {
    return std::string(e.what());
  }
  return std::string("no error");
}

TEST(Expression, ComplexOrHugeConstantsAreRefusedNotHandedToGiNaC) {
  // Found by the fuzzer (CI): GiNaC recursed without bound differentiating atan2 times a complex constant, and
  // exact big powers never finished. Constant parts are folded in double precision before GiNaC sees them.
  EXPECT_HAS(compile_message("sin(atan2(-1, t)*2*(-1)^(1/2)) + xA"), "not a finite real number");
  EXPECT_HAS(compile_message("tan(atan2(-3/4, t)*(-2.0)^0.5) + xA"), "not a finite real number");
  EXPECT_HAS(compile_message("xA - 9^(9^(9^9))"), "not a finite real number");
  EXPECT_HAS(compile_message("xA - sqrt(-1e-300)"), "not a finite real number");
  // exact zeros made by the text itself: cos(0) is 1 and log(-1) is not real, whatever GiNaC would make of it
  EXPECT_HAS(compile_message("atan2(log(-cos(0)), 0)*xA"), "not a finite real number (NaN)");
  EXPECT_HAS(compile_message("xA/(1 - 1)"), "division by zero");
  EXPECT_HAS(compile_message("xA/0"), "division by zero");
  EXPECT_HAS(compile_message("xA/(xA - xA)"), "division by zero");            // GiNaC's own refusal, one line
  EXPECT_HAS(compile_message("xA/((t - (3 + t)) + 3)"), "division by zero");  // two 3s, two symbols to GiNaC
  EXPECT_HAS(compile_message("xA - 1e400"), "number '1e400' is out of the range of a double");
}

TEST(Expression, MalformedTextIsRefusedInOneLineNamingTheColumn) {
  // "sin()" crashed GiNaC's own parser (fuzzer, CI); phiq parses the text itself.
  auto what = [](const std::string& text) {  // the message after the quoted expression
    const std::string m = compile_message(text);
    const std::string head = "expression \"" + text + "\": ";
    return m.rfind(head, 0) == 0 ? m.substr(head.size()) : "[" + m + "]";
  };
  EXPECT_EQ(what("sin() - theta2"), "'sin' takes 1 argument, not 0 (column 1)");
  EXPECT_EQ(what("xA + atan2(yA)"), "'atan2' takes 2 arguments, not 1 (column 6)");
  EXPECT_HAS(what("zeta(xA)"), "unknown function 'zeta' (supported: abs acos asin atan atan2 cos cosh exp log");
  EXPECT_EQ(what("xA^2^3"), "x^a^b is ambiguous: write (x^a)^b or x^(a^b) (column 5)");
  EXPECT_EQ(what("2xA + 1"), "'2xA' is not a number");
  EXPECT_EQ(what("xA - (yA"), "missing ')' at the end");
  EXPECT_EQ(what("xA) + 1"), "')' without a matching '(' (column 3)");
  EXPECT_EQ(what("xA yA"), "expected an operator before 'yA' (column 4)");
  EXPECT_EQ(what("xA + * yA"), "expected a number, a name or '(' before '*' (column 6)");
  EXPECT_EQ(what("xA +"), "an operand is missing at the end");
  EXPECT_EQ(what("xA + {1}"), "expected a number, a name or '(' before '{' (column 6)");
  EXPECT_HAS(compile_message(std::string(65, '(') + "xA" + std::string(65, ')')),
             "nested more than 64 parentheses deep");
}

TEST(Expression, PowersParseAsWrittenAndStayCheap) {
  // A signed exponent applies to the exponent only: theta2^-1 + xA is theta2^(-1) + xA; -xA^2 is -(xA^2).
  auto e = CompiledExpression::compile("theta2^-1 + xA - yA^2*-1 + -xA^2", resolve);
  const double q[3] = {0.5, 3.0, 2.0};
  EXPECT_DOUBLE_EQ(e->value(q, 0.0), 2.0 + 3.0 + 4.0 - 9.0);
  double g[3];
  e->gradient(q, 0.0, g);
  EXPECT_DOUBLE_EQ(g[0], -4.0);
  EXPECT_DOUBLE_EQ(g[1], 1.0 - 6.0);
  EXPECT_DOUBLE_EQ(g[2], 4.0);
  // Exact power towers made GiNaC compute 2^(2^40): numbers no longer reach it, so this compiles at once, and its
  // value is the double-precision one, (2 xA)^(1024^3) = +inf for xA = 1 and 0 for xA = 0.25.
  auto tower = CompiledExpression::compile("(((2*xA)^1024)^1024)^1024 + (((cos(0)+cos(0))^8)^8)^8*xA", resolve);
  const double q1[3] = {0, 0.25, 0};
  EXPECT_DOUBLE_EQ(tower->value(q1, 0.0), std::ldexp(0.25, 512));
}

TEST(Expression, LiteralsFoldToTheValuesTheTextMeans) {
  // Powers written with integer exponents stay exact: the derivative of xA^2 at 0 is 0 (not 0·2/0), and of
  // yA^(3) and theta2^(-1) the closed forms. Constant parts fold to their double values.
  auto e = CompiledExpression::compile("xA^2 + yA^(3) + 2.5e-1*theta2^(-1) + 0*unused + (1/4)^(1/2)*L2 + pi", resolve);
  EXPECT_EQ(e->coordinates(), (std::vector<Index>{0, 1, 2}));
  const double q0[3] = {0.5, 0.0, 0.0};
  double g[3];
  e->gradient(q0, 0.0, g);
  EXPECT_EQ(g[1], 0.0);
  EXPECT_EQ(g[2], 0.0);
  EXPECT_DOUBLE_EQ(g[0], -0.25 / (0.5 * 0.5));
  const double q[3] = {0.5, -1.5, 2.0};
  EXPECT_DOUBLE_EQ(e->value(q, 0.0), 2.25 + 8.0 + 0.5 + 0.5 * 0.3 + M_PI);
  e->gradient(q, 0.0, g);
  EXPECT_DOUBLE_EQ(g[1], -3.0);
  EXPECT_DOUBLE_EQ(g[2], 12.0);
  // a half-integer exponent through sqrt: d/dx x^1.5 = 1.5 sqrt(x)
  auto h = CompiledExpression::compile("xA^1.5", resolve);
  const double q1[3] = {0, 4.0, 0};
  double gh[1];
  h->gradient(q1, 0.0, gh);
  EXPECT_DOUBLE_EQ(gh[0], 3.0);
}

// The value, gradient, ∂/∂t and γ of e at (q, t) along (q̇, 1) against central differences (Richardson for γ):
// the check of every order the tapes provide. `scale` is the size of the derivatives checked (tolerances relative
// to it). All of them must be finite.
void expect_derivatives_match_differences(const CompiledExpression& e, const double q[3], const double qd[3], double t,
                                          double scale) {
  const std::vector<Index>& cols = e.coordinates();
  std::vector<double> grad(cols.size());
  e.gradient(q, t, grad.data());
  auto at = [&](double s, double dt) {
    double x[3] = {q[0] + s * qd[0], q[1] + s * qd[1], q[2] + s * qd[2]};
    return e.value(x, t + dt);
  };
  const double h = 1e-5;
  for (std::size_t k = 0; k < cols.size(); ++k) {
    double a[3] = {q[0], q[1], q[2]}, b[3] = {q[0], q[1], q[2]};
    a[cols[k]] += h, b[cols[k]] -= h;
    ASSERT_TRUE(std::isfinite(grad[k])) << e.text() << " column " << cols[k];
    EXPECT_NEAR(grad[k], (e.value(a, t) - e.value(b, t)) / (2 * h), 1e-7 * scale) << e.text() << " column " << cols[k];
  }
  const double pt = e.partial_t(q, t);
  ASSERT_TRUE(std::isfinite(pt)) << e.text();
  EXPECT_NEAR(pt, (e.value(q, t + h) - e.value(q, t - h)) / (2 * h), 1e-7 * scale) << e.text();
  // −γ = d²/ds² g(q + s q̇, t + s) at s = 0
  auto d2 = [&](double step) { return (at(step, step) - 2 * at(0, 0) + at(-step, -step)) / (step * step); };
  const double g = e.gamma(q, qd, t);
  ASSERT_TRUE(std::isfinite(g)) << e.text();
  EXPECT_NEAR(-g, (4 * d2(1e-3) - d2(2e-3)) / 3, 1e-6 * scale) << e.text();
}

TEST(Expression, IntegerPowersHaveExactDerivativesAtAZeroBase) {
  // GiNaC differentiated u^k (k a constant of the text) as u^k·k·u'·u^(-1): 0·∞ where u = 0, unless the tape
  // builder could merge u^k·u^(-1) — which failed whenever GiNaC rewrote u^(-1): (2x)^(-1) as ½·x^(-1) always,
  // (x − y)^(-1) as −(y − x)^(-1) in about half of all processes. Compiled several times (GiNaC's term order
  // changes with its symbols' serial numbers), so that an order-dependent failure shows here too.
  const double q[3] = {0.0, 0.0, 0.0}, qd[3] = {0.7, -1.3, 0.4};
  for (int round = 0; round < 6; ++round) {
    // (2 xA)^2 at xA = 0: g = 0, ∂g/∂xA = 8 xA = 0, −γ = 8 ẋA²
    auto sq = CompiledExpression::compile("(2*xA)^2", resolve);
    double g1[1];
    sq->gradient(q, 0.0, g1);
    EXPECT_EQ(g1[0], 0.0);
    EXPECT_DOUBLE_EQ(-sq->gamma(q, qd, 0.0), 8 * qd[1] * qd[1]);
    // (xA − yA)^2 with xA = yA ≠ 0: 2 (xA − yA) (1, −1) = 0; −γ = 2 (ẋA − ẏA)²
    auto diff = CompiledExpression::compile("(xA - yA)^2 + (yA - xA)^3", resolve);
    const double qe[3] = {0.0, 0.35, 0.35};
    double g2[2];
    diff->gradient(qe, 0.0, g2);
    EXPECT_EQ(g2[0], 0.0);
    EXPECT_EQ(g2[1], 0.0);
    EXPECT_DOUBLE_EQ(-diff->gamma(qe, qd, 0.0), 2 * (qd[1] - qd[2]) * (qd[1] - qd[2]));
    // a cube and a time-dependent base: (t − 0.5)^3 xA + (2 t − 1)^2 at t = 0.5: ∂/∂t = 0 and −γ = 8 (no xA
    // term survives: 3 (t − ½)² ẋA and 6 (t − ½) xA vanish)
    auto tm = CompiledExpression::compile("(t - 0.5)^3*xA + (2*t - 1)^2", resolve);
    const double qx[3] = {0.0, 1.7, 0.0};
    EXPECT_EQ(tm->partial_t(qx, 0.5), 0.0);
    EXPECT_DOUBLE_EQ(-tm->gamma(qx, qd, 0.5), 8.0);
    for (const char* text : {"(2*xA)^2", "(xA - yA)^2 + (yA - xA)^3", "(2*xA - 3*yA)^3 - (xA*yA)^2",
                             "(sin(theta2) - xA)^4 + (t - 0.5)^2*yA", "L2*(theta2 - 2*t)^3 + (xA + yA - t)^2"}) {
      auto e = CompiledExpression::compile(text, resolve);
      // every base above is 0 here: theta2 = sin(theta2) = xA = yA = 0, t = 0; and at θ2 = 1, t = ½
      expect_derivatives_match_differences(*e, q, qd, 0.0, 1.0);
      const double q1[3] = {1.0, std::sin(1.0), 0.0};
      expect_derivatives_match_differences(*e, q1, qd, 0.5, 10.0);
    }
  }
  // negative integer powers away from 0 keep their closed forms
  for (const char* text : {"(2*xA - yA)^(-2)", "(xA - yA)^-3 + xA/(t - yA)^2", "1/(2*xA)^2"}) {
    auto e = CompiledExpression::compile(text, resolve);
    const double q2[3] = {0.0, 0.8, -0.3};
    expect_derivatives_match_differences(*e, q2, qd, 0.25, 100.0);
  }
}

TEST(Expression, AbsHasTheDerivativeSignAtAZeroArgument) {
  // GiNaC's abs differentiates to u u'/|u|, 0/0 where u = 0; phiq's has sign(u) u' (0 there, a subgradient), and
  // its own value's elsewhere
  auto e = CompiledExpression::compile("yA*abs(xA - 1.3) + abs(theta2)*theta2", resolve);
  const double at[3] = {0.0, 1.3, 2.0}, away[3] = {-0.4, 1.45, 2.0}, qd[3] = {0.5, -0.7, 0.2};
  double g[3];
  e->gradient(at, 0.0, g);
  EXPECT_EQ(g[0], 0.0);  // 2 |θ| at θ = 0
  EXPECT_EQ(g[1], 0.0);  // yA sign(0)
  EXPECT_EQ(g[2], 0.0);  // |0|
  e->gradient(away, 0.0, g);
  EXPECT_DOUBLE_EQ(g[0], 2 * 0.4);
  EXPECT_DOUBLE_EQ(g[1], 2.0);
  EXPECT_NEAR(g[2], 0.15, 1e-15);
  expect_derivatives_match_differences(*e, away, qd, 0.0, 10.0);
}

TEST(Expression, SignIsMinusOneZeroOrOneWithNoSlope) {
  auto e = CompiledExpression::compile("xA*sign(yA - 1) + sign(-2)", resolve);
  for (const double y : {2.5, 1.0, -0.5}) {
    const double q[3] = {0.0, 3.0, y}, s = (y > 1) - (y < 1);
    EXPECT_EQ(e->value(q, 0.0), 3.0 * s - 1.0) << y;
    double g[2];
    e->gradient(q, 0.0, g);
    EXPECT_EQ(g[0], s) << y;
    EXPECT_EQ(g[1], 0.0) << y;
  }
}

TEST(Expression, RealPowersAtAZeroBaseAreFiniteWhereTheirDerivativesAre) {
  // u^p at u = 0: ∂ = p u^(p−1) and the second derivative p (p − 1) u^(p−2) are 0 for p > 2, the second is
  // infinite for 1 < p < 2, both are for p < 1. Finite ones must come out exactly 0, not NaN.
  const double q[3] = {0.0, 0.0, 0.0}, qd[3] = {0.0, 0.9, 0.0};
  for (const char* text : {"xA^2.5", "(2*xA)^2.5", "xA^2.7", "(3*xA)^3.5", "xA^7.25"}) {
    auto e = CompiledExpression::compile(text, resolve);
    double g[1];
    e->gradient(q, 0.0, g);
    EXPECT_EQ(g[0], 0.0) << text;
    EXPECT_EQ(e->gamma(q, qd, 0.0), 0.0) << text;
  }
  for (const char* text : {"xA^1.5", "(2*xA)^1.7"}) {  // ∂ = 0, second derivative infinite
    auto e = CompiledExpression::compile(text, resolve);
    double g[1];
    e->gradient(q, 0.0, g);
    EXPECT_EQ(g[0], 0.0) << text;
    EXPECT_FALSE(std::isfinite(e->gamma(q, qd, 0.0))) << text;
  }
  for (const char* text : {"sqrt(xA)", "xA^0.5", "(2*xA)^0.3"}) {  // ∂ itself infinite: not finite, never 0
    auto e = CompiledExpression::compile(text, resolve);
    double g[1];
    e->gradient(q, 0.0, g);
    EXPECT_FALSE(std::isfinite(g[0])) << text;
  }
  // and away from 0, against differences
  const double q1[3] = {0.3, 0.6, 0.2};
  for (const char* text : {"xA^2.5 + (xA - yA)^1.5", "(2*xA)^2.7*yA", "(xA + yA)^(-0.5)"})
    expect_derivatives_match_differences(*CompiledExpression::compile(text, resolve), q1, qd, 0.0, 10.0);
}

// Texts whose terms GiNaC orders by hash values: numbers, differences, products of differences, powers, functions.
const char* const kOrderSensitiveTexts[] = {
    "(xA - xA*yA)^2 + (yA - theta2)^2 - L2^2",
    "xA - L2*cos(theta2) + 0.1*sin(t)*yA - (yA - 2*xA)^3",
    "atan2(yA - xA, xA + 2*yA) * abs(xA - yA) + sqrt(1 + (xA - t)^2)*exp(-theta2)",
    "(xA*yA - theta2)/(1 + xA^2 + yA^2) - tanh(yA - xA)^2 + L2*t^2*(xA - yA)",
    // constants of one value are different symbols to GiNaC: sums that are 0 only on the tape, with either sign
    "(0.5*xA - 0.5*xA + yA)*(0.5 - (0.5 - yA))^3 + (xA - 2*t)*(2*t - xA + 3 - 3)*(3 + xA)/(xA + 3)",
};

std::string listings() {
  std::string all;
  for (const char* text : kOrderSensitiveTexts) all += CompiledExpression::compile(text, resolve)->listing();
  return all;
}

TEST(Expression, CompilesToTheSameTapeWhateverWasCompiledBefore) {
  // GiNaC orders a sum's terms by hash values, which come from its symbols' serial numbers (and from addresses,
  // below): the same text compiled after others used to give another order of operations, other roundings.
  const std::string first = listings();
  for (int k = 1; k <= 5; ++k) {
    for (int j = 0; j < k; ++j) CompiledExpression::compile("xA*yA + theta2", resolve);  // new symbols in between
    EXPECT_EQ(listings(), first) << "after " << k << " more compilations";
  }
}

TEST(Expression, CompilesToTheSameTapeInEveryProcess) {
  // GiNaC's hash values start from the address of its classes' type names, which address-space randomisation
  // moves from process to process: the same scene's CSV differed in its last bits from run to run. The test
  // binary runs this test again in child processes (PHIQ_TAPE_LISTING names the file a child writes its listings
  // to) and compares.
  if (const char* out = std::getenv("PHIQ_TAPE_LISTING")) {
    std::ofstream(out) << listings();
    return;
  }
  const std::string mine = listings();
  const std::filesystem::path dir = phiq::test::scratch_path("phiq_tape_listing");
  std::filesystem::create_directories(dir);
  for (int child = 0; child < 4; ++child) {
    const std::filesystem::path file = dir / ("child" + std::to_string(child) + ".txt");
    std::filesystem::remove(file);
    // (not sharded as this process may be: GoogleTest would give the child's one test to one shard only)
    const std::string cmd = "env -u GTEST_TOTAL_SHARDS -u GTEST_SHARD_INDEX PHIQ_TAPE_LISTING=" + file.string() + " " +
                            std::filesystem::read_symlink("/proc/self/exe").string() +
                            " --gtest_filter=Expression.CompilesToTheSameTapeInEveryProcess >/dev/null 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    EXPECT_EQ(test::file_text(file.string()), mine) << "child process " << child;
  }
  std::filesystem::remove_all(dir);
}

// An angle by its top-level form: a sum of ±atan2 terms and other terms without atan2 (EquationSpec wraps its
// residual); anything else is not, whatever atan2 it holds deeper.
TEST(Expression, AngleDifferenceIsRecognisedFromTheTopLevelForm) {
  auto angle = [](const std::string& text) { return CompiledExpression::compile(text, resolve)->angle_difference(); };
  EXPECT_TRUE(angle("atan2(yA, xA)"));
  EXPECT_TRUE(angle("atan2(yA - 0.25, xA - 0.5) - t"));
  EXPECT_TRUE(angle("-atan2(yA, xA) + theta2"));
  EXPECT_TRUE(angle("atan2(yA, xA) - atan2(xA, yA) - 0.3*t^2"));
  EXPECT_FALSE(angle("2*atan2(yA, xA) - t"));     // jumps by 4π
  EXPECT_FALSE(angle("sin(atan2(yA, xA)) - t"));  // no jump at all
  EXPECT_FALSE(angle("atan2(yA, xA)*xA - t"));
  EXPECT_FALSE(angle("theta2 - t"));
  EXPECT_FALSE(angle("atan(yA/xA) - t"));
  // kept when a family instantiates the expression for its members
  auto e = CompiledExpression::compile("atan2(yA, xA) - theta2", resolve);
  EXPECT_TRUE(e->rebind({5, 6, 7}, {0.0, 0.0, 0.0}, "atan2(y1, x1) - a1")->angle_difference());
}

// h = Σ rate_j ∂g/∂c_j (along_constants()) of a family member: a parameter L and a placeholder that the member binds
// to a constant c, against central differences of the member compiled and rebound at L + e·rL, c + e·rc: its value,
// gradient, ∂/∂t and γ (each a derivative of g's along the constants).
TEST(Expression, RateAlongItsConstantsOfARebindingMatchesTheirDifferences) {
  const std::string text = "x0*cos(x1*L + t) + L^2*x2^3 - x1*sqrt(L + x2^2)";
  auto base = [&](double L) {
    return CompiledExpression::compile(text, [L](const std::string& n) -> std::optional<NameBinding> {
      for (int k = 0; k < 3; ++k)
        if (n == "x" + std::to_string(k)) return NameBinding{NameBinding::Kind::kCoordinate, k};
      if (n == "L") return NameBinding{NameBinding::Kind::kConstant, -1, L};
      if (n == "t") return NameBinding{NameBinding::Kind::kTime};
      return std::nullopt;
    });
  };
  const double L = 0.8, c = 0.7, rL = 0.5, rc = -2.0;
  // compiled index 1 is the member's constant c; 0 and 2 its coordinates 4 and 6
  auto member = [&](double e) { return base(L + e * rL)->rebind({4, -1, 6}, {0.0, c + e * rc, 0.0}, text); };
  const auto g = member(0.0);
  EXPECT_EQ(g->constants(), (std::vector<double>{L, c}));
  EXPECT_TRUE(g->same_source(*member(0.1)));
  EXPECT_FALSE(g->same_source(*base(L)->rebind({4, 5, 6}, {0.0, 0.0, 0.0}, text)));  // c a coordinate there
  const auto h = g->along_constants({rL, rc});
  ASSERT_NE(h, nullptr);
  EXPECT_EQ(h->coordinates(), (std::vector<Index>{4, 6}));
  EXPECT_EQ(h->constants(), std::vector<double>{});
  const double q[7] = {0, 0, 0, 0, 0.9, 0, -0.4}, qd[7] = {0, 0, 0, 0, 1.3, 0, 0.6};
  const double t = 0.35, e = 1e-3;
  const auto m2 = member(-2 * e), m1 = member(-e), p1 = member(e), p2 = member(2 * e);
  auto fd = [&](const std::function<double(const CompiledExpression&)>& f) {
    return ((f(*m2) - f(*p2)) + 8.0 * (f(*p1) - f(*m1))) / (12.0 * e);
  };
  EXPECT_NEAR(h->value(q, t), fd([&](const CompiledExpression& x) { return x.value(q, t); }), 1e-10);
  EXPECT_NEAR(h->partial_t(q, t), fd([&](const CompiledExpression& x) { return x.partial_t(q, t); }), 1e-10);
  EXPECT_NEAR(h->gamma(q, qd, t), fd([&](const CompiledExpression& x) { return x.gamma(q, qd, t); }), 1e-9);
  double dh[2];
  h->gradient(q, t, dh);
  for (int k = 0; k < 2; ++k)
    EXPECT_NEAR(dh[k], fd([&](const CompiledExpression& x) {
                  double dg[2];
                  x.gradient(q, t, dg);
                  return dg[k];
                }),
                1e-10)
        << "column " << k;
  // another member, its constant moving alike: the same derivative on its own coordinates
  EXPECT_EQ(base(L)->rebind({1, -1, 3}, {0.0, c, 0.0}, text)->along_constants({rL, rc})->coordinates(),
            (std::vector<Index>{1, 3}));
  EXPECT_EQ(g->along_constants({0.0, 0.0}), nullptr);
  EXPECT_THROW(g->along_constants({1.0}), Error);
}

TEST(Expression, ConstantExpressions) {
  auto c = [](const std::string& n) -> std::optional<double> {
    if (n == "L") return 2.0;
    return std::nullopt;
  };
  EXPECT_DOUBLE_EQ(evaluate_constant_expression("2*pi", c), 2 * M_PI);
  EXPECT_DOUBLE_EQ(evaluate_constant_expression("-L/2 + sqrt(9)", c), 2.0);
  EXPECT_THROW(evaluate_constant_expression("t + 1", c), Error);
  EXPECT_THROW(evaluate_constant_expression("M", c), Error);
}

}  // namespace
}  // namespace phiq
