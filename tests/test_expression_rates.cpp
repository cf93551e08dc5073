// Rates in expressions (phiq/expression.hpp, `der(u)`, read by loads' forces and torques): der(u) as the exact
// rate Σ ∂u/∂q_j q̇_j + ∂u/∂t against its closed form; the value's gradients in q and in q̇ against central
// differences; der of a constant; refusals where rates may not be read, of a rate of a rate and of a wrong arity;
// a family's rebinding of the coordinates whose rates it reads, and the rate along a constant of an expression
// that reads rates.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "phiq/expression.hpp"

namespace phiq {
namespace {

// q = [theta, x, y]; c = 2.5.
std::optional<NameBinding> rates_resolve(const std::string& n) {
  if (n == "theta") return NameBinding{NameBinding::Kind::kCoordinate, 0};
  if (n == "x") return NameBinding{NameBinding::Kind::kCoordinate, 1};
  if (n == "y") return NameBinding{NameBinding::Kind::kCoordinate, 2};
  if (n == "c") return NameBinding{NameBinding::Kind::kConstant, -1, 2.5};
  if (n == "t") return NameBinding{NameBinding::Kind::kTime};
  return std::nullopt;
}

std::shared_ptr<const CompiledExpression> with_rates(const std::string& text) {
  return CompiledExpression::compile(text, rates_resolve, true, true);
}

std::string rates_error(const std::string& text, bool allow_rates) {
  try {
    CompiledExpression::compile(text, rates_resolve, true, allow_rates);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ExpressionRates, DerIsTheExactRateAlongTheMotion) {
  // x θ̇ + der(sin(x) t) = x θ̇ + cos(x) ẋ t + sin(x); der(y²) = 2 y ẏ
  const auto e = with_rates("x*der(theta) + der(sin(x)*t) - c*der(y^2)");
  EXPECT_EQ(e->coordinates(), (std::vector<Index>{1, 2}));  // θ only through its rate
  EXPECT_EQ(e->rate_coordinates(), (std::vector<Index>{0, 1, 2}));
  EXPECT_TRUE(e->depends_on_time());
  const double q[3] = {0.4, 0.9, -0.3}, qd[3] = {1.7, -0.6, 0.8}, t = 0.45;
  const double exact = q[1] * qd[0] + std::cos(q[1]) * qd[1] * t + std::sin(q[1]) - 2.5 * 2.0 * q[2] * qd[2];
  EXPECT_NEAR(e->value(q, qd, t), exact, 1e-15);
  // without q̇, at rest: every rate 0
  EXPECT_NEAR(e->value(q, t), std::sin(q[1]), 1e-16);
  EXPECT_NEAR(e->value(q, nullptr, t), std::sin(q[1]), 1e-16);
}

TEST(ExpressionRates, GradientsInQAndInQdotMatchCentralDifferences) {
  const auto e = with_rates("-3*der(x)*abs(der(x)) + sqrt(1 + x^2)*der(atan2(y, x)) + tanh(der(theta)/0.1)*y");
  const double q0[3] = {0.4, 0.9, -0.3}, qd0[3] = {0.05, -0.6, 0.8}, t = 0.2, h = 1e-6;
  double g[3], gd[3];
  ASSERT_EQ(e->coordinates().size(), 2u);  // x, y
  ASSERT_EQ(e->rate_coordinates().size(), 3u);
  e->gradient(q0, qd0, t, g);
  e->rate_gradient(q0, qd0, t, gd);
  for (std::size_t k = 0; k < 2; ++k) {
    const Index j = e->coordinates()[k];
    double qp[3] = {q0[0], q0[1], q0[2]}, qm[3] = {q0[0], q0[1], q0[2]};
    qp[j] += h, qm[j] -= h;
    const double fd = (e->value(qp, qd0, t) - e->value(qm, qd0, t)) / (2 * h);
    EXPECT_NEAR(g[k], fd, 1e-8 * (1 + std::fabs(fd))) << "∂/∂q" << j;
  }
  for (std::size_t k = 0; k < 3; ++k) {
    const Index j = e->rate_coordinates()[k];
    double vp[3] = {qd0[0], qd0[1], qd0[2]}, vm[3] = {qd0[0], qd0[1], qd0[2]};
    vp[j] += h, vm[j] -= h;
    const double fd = (e->value(q0, vp, t) - e->value(q0, vm, t)) / (2 * h);
    EXPECT_NEAR(gd[k], fd, 1e-8 * (1 + std::fabs(fd))) << "∂/∂q̇" << j;
    EXPECT_GT(std::fabs(gd[k]), 0.1) << j;  // each rate counts: the check is not of zeros
  }
}

TEST(ExpressionRates, DerOfAConstantIsZeroAndReadsNoRate) {
  const auto e = with_rates("x + der(c*pi) + der(2)");
  EXPECT_TRUE(e->rate_coordinates().empty());
  const double q[3] = {0.0, 1.25, 0.0};
  const double qd[3] = {0.3, -0.2, 0.1};
  EXPECT_EQ(e->value(q, qd, 0.0), 1.25);
}

TEST(ExpressionRates, RatesAreRefusedWhereAnExpressionIsOfQAndTAlone) {
  EXPECT_NE(rates_error("x - c*der(y)", false).find("der() reads velocities: only the forces and torques of `loads`"),
            std::string::npos);
  EXPECT_NE(rates_error("der(der(x))", true).find("der() of a rate: an acceleration"), std::string::npos);
  EXPECT_NE(rates_error("der(x, y)", true).find("'der' takes 1 argument, not 2 or more (column 1)"), std::string::npos);
  EXPECT_NE(rates_error("der()", true).find("'der' takes 1 argument, not 0"), std::string::npos);
  EXPECT_NE(rates_error("dur(x)", true).find("(supported: abs"), std::string::npos);
  EXPECT_NE(rates_error("dur(x)", true).find(" der)"), std::string::npos);
  EXPECT_EQ(rates_error("dur(x)", false).find(" der)"), std::string::npos);
}

TEST(ExpressionRates, ARebindingReadsTheMembersRatesAndAConstantsRateIsZero) {
  // a family's text with placeholders 0, 1 (e.g. x{i}, x{i+1}) bound to coordinates 5 and 2, or 1 to a constant
  const std::string text = "-c*der(p0 - p1)*abs(der(p0))";
  const auto base = CompiledExpression::compile(
      text,
      [](const std::string& n) -> std::optional<NameBinding> {
        if (n == "p0") return NameBinding{NameBinding::Kind::kCoordinate, 0};
        if (n == "p1") return NameBinding{NameBinding::Kind::kCoordinate, 1};
        if (n == "c") return NameBinding{NameBinding::Kind::kConstant, -1, 2.5};
        return std::nullopt;
      },
      true, true);
  const auto member = base->rebind({5, 2}, {0.0, 0.0}, text);
  EXPECT_EQ(member->rate_coordinates(), (std::vector<Index>{2, 5}));
  double q[6] = {}, qd[6] = {0, 0, -0.4, 0, 0, 1.5};
  EXPECT_NEAR(member->value(q, qd, 0.0), -2.5 * (1.5 + 0.4) * 1.5, 1e-15);
  double gd[2];
  member->rate_gradient(q, qd, 0.0, gd);
  EXPECT_NEAR(gd[0], 2.5 * 1.5, 1e-15);                        // ∂/∂q̇2
  EXPECT_NEAR(gd[1], -2.5 * (1.5 + 1.9), 1e-15);               // ∂/∂q̇5: −c (|v5| + (v5 − v2) sign v5)
  const auto fixed = base->rebind({5, -1}, {0.0, 7.0}, text);  // p1 a constant: its rate is 0
  EXPECT_EQ(fixed->rate_coordinates(), (std::vector<Index>{5}));
  EXPECT_NEAR(fixed->value(q, qd, 0.0), -2.5 * 1.5 * 1.5, 1e-15);
}

TEST(ExpressionRates, TheRateAlongAConstantReadsTheRatesToo) {
  // d/dc of c der(x)² is der(x)²
  const auto e = with_rates("c*der(x)^2 + y");
  const auto h = e->along_constants({1.0});
  ASSERT_NE(h, nullptr);
  EXPECT_EQ(h->rate_coordinates(), (std::vector<Index>{1}));
  const double q[3] = {0.0, 0.3, 0.7}, qd[3] = {0.0, -1.2, 0.0};
  EXPECT_NEAR(h->value(q, qd, 0.0), 1.44, 1e-15);
}

}  // namespace
}  // namespace phiq
