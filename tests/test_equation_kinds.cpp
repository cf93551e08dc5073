// Derivative checks of the equation kind (EquationSpec: an expression of coordinates, time and constants, with or
// without a law), as test_constraint_kinds.cpp checks every kind: Φq, Φt and γ against differences of Φ, the
// derivatives along its data and along the parameters its text reads; and an angle equation swept through ±π.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "phiq/constraint_kinds.hpp"
#include "phiq/expression.hpp"
#include "phiq/motion_law.hpp"
#include "phiq/scene.hpp"
#include "phiq/sweep.hpp"
#include "phiq/types.hpp"
#include "constraint_check.hpp"

namespace {

// Coordinates theta2 = 0, xA = 1, yA = 2 (a 4th coordinate, 3, is left unused); constant L2 = 0.3; time t.
std::shared_ptr<const phiq::CompiledExpression> CompileCrank(const std::string& text) {
  return phiq::CompiledExpression::compile(text, [](const std::string& name) -> std::optional<phiq::NameBinding> {
    using K = phiq::NameBinding::Kind;
    if (name == "theta2") return phiq::NameBinding{K::kCoordinate, 0};
    if (name == "xA") return phiq::NameBinding{K::kCoordinate, 1};
    if (name == "yA") return phiq::NameBinding{K::kCoordinate, 2};
    if (name == "L2") return phiq::NameBinding{K::kConstant, -1, 0.3};
    if (name == "t") return phiq::NameBinding{K::kTime};
    return std::nullopt;
  });
}

// ---- EquationSpec ---------------------------------------------------------------------------------------------

TEST(ConstraintKinds, EquationInCoordinatesAndTime) {
  auto g = CompileCrank("xA - L2*cos(theta2) + 0.1*t^2*yA + atan2(yA, xA + 3)");
  ASSERT_EQ(g->coordinates(), (std::vector<Index>{0, 1, 2}));
  ASSERT_TRUE(g->depends_on_time());
  phiq::EquationSpec e{g, std::nullopt, phiq::Unit::kLength};
  CheckSpec(e, 4, Opts(1001, true));
}

TEST(ConstraintKinds, EquationWithoutTime) {
  phiq::EquationSpec e{CompileCrank("xA^2 + yA^2 - L2^2*theta2*sin(theta2)"), std::nullopt, phiq::Unit::kNone};
  CheckSpec(e, 4, Opts(1002, false));
}

TEST(ConstraintKinds, EquationWithLaw) {
  // g independent of t, driven by a law
  phiq::EquationSpec e{CompileCrank("xA*yA - sin(theta2)"), phiq::MotionLaw::harmonic(0.1, 0.6, 1.7, -0.3),
                       phiq::Unit::kNone};
  CheckSpec(e, 4, Opts(1003, true));
  // g depending on t and a law as well
  phiq::EquationSpec f{CompileCrank("xA - L2*cos(theta2) + 0.1*t^2*yA + atan2(yA, xA + 3)"),
                       phiq::MotionLaw::polynomial({0.2, -0.3, 0.15, 0.04}), phiq::Unit::kLength};
  CheckSpec(f, 4, Opts(1004, true));
}

TEST(ConstraintKinds, EquationAlongItsData) {
  // a driven equation whose text reads no parameter: its law moves, its expression has no rate
  const auto g = CompileCrank("xA*yA - sin(theta2)");
  const phiq::EquationSpec e{g, phiq::MotionLaw::harmonic(0.1, 0.6, 1.7, -0.3), phiq::Unit::kNone};
  const phiq::EquationSpec rate{nullptr, phiq::MotionLaw::polynomial({-0.4, 0.9, 0.25}), phiq::Unit::kNone};
  CheckDataDerivative(e, rate, 4, 1011);
  // without a law, nothing moves
  const phiq::EquationSpec still{g, std::nullopt, phiq::Unit::kNone};
  CheckDataDerivative(still, phiq::EquationSpec{nullptr, std::nullopt, phiq::Unit::kNone}, 4, 1012, 2);
}

TEST(ConstraintKinds, EquationAlongTheParametersItsTextReads) {
  // L2 = p and L3 = 1 + 2p², read by the text (a parameter defined from another moves with it), and a law in p:
  // the equation at p against its rate, which detail::datum_rate makes of four copies at a 10 % step (exact: L2
  // and L3 of degree ≤ 4 in p), its expression differentiated along its constants
  const std::string text = "xA - L2*cos(theta2) + 0.1*t^2*yA*L3 + atan2(yA, xA + L3) + L2^2*sqrt(L3 + yA^2)";
  auto at = [&](double p) {
    auto g = phiq::CompiledExpression::compile(text, [p](const std::string& name) -> std::optional<phiq::NameBinding> {
      using K = phiq::NameBinding::Kind;
      if (name == "theta2") return phiq::NameBinding{K::kCoordinate, 0};
      if (name == "xA") return phiq::NameBinding{K::kCoordinate, 1};
      if (name == "yA") return phiq::NameBinding{K::kCoordinate, 2};
      if (name == "L2") return phiq::NameBinding{K::kConstant, -1, p};
      if (name == "L3") return phiq::NameBinding{K::kConstant, -1, 1.0 + 2.0 * p * p};
      if (name == "t") return phiq::NameBinding{K::kTime};
      return std::nullopt;
    });
    return phiq::EquationSpec{g, phiq::MotionLaw::harmonic(0.1 * p, 0.6, 1.7, -0.3), phiq::Unit::kLength};
  };
  const double p = 0.3, h = 0.03;
  const phiq::EquationSpec e = at(p), m2 = at(p - 2 * h), m1 = at(p - h), p1 = at(p + h), p2 = at(p + 2 * h);
  EXPECT_EQ(e.g->constants(), (std::vector<double>{p, 1.0 + 2.0 * p * p}));
  ASSERT_TRUE(e.g->same_source(*m2.g));
  phiq::EquationSpec rate;
  ASSERT_TRUE(phiq::detail::spec_data_rate(e, {&m2, &m1, &p1, &p2}, h, rate));
  ASSERT_NE(rate.g, nullptr);
  EXPECT_EQ(rate.g->coordinates(), (std::vector<Index>{0, 1, 2}));
  CheckDataDerivativeOf(
      e, rate, [&](double x) { return at(p + x); }, 4, 1013);
  // constants that do not move give no rate; one that moves an exponent has none the kind can give (differenced)
  EXPECT_EQ(e.g->along_constants({0.0, 0.0}), nullptr);
  auto power = [](double p) {
    using K = phiq::NameBinding::Kind;
    return phiq::CompiledExpression::compile("xA^n - 1",
                                             [p](const std::string& name) -> std::optional<phiq::NameBinding> {
                                               if (name == "xA") return phiq::NameBinding{K::kCoordinate, 0};
                                               if (name == "n") return phiq::NameBinding{K::kConstant, -1, p};
                                               return std::nullopt;
                                             });
  };
  EXPECT_THROW(power(2.0)->along_constants({1.0}), phiq::Error);
  const phiq::EquationSpec pe{power(2.0), std::nullopt, phiq::Unit::kNone};
  const phiq::EquationSpec pm{power(1.9), std::nullopt, phiq::Unit::kNone};
  phiq::EquationSpec none;
  EXPECT_FALSE(phiq::detail::spec_data_rate(pe, {&pm, &pm, &pe, &pe}, 0.1, none));
  // another text is another function: no rate
  EXPECT_FALSE(e.g->same_source(*CompileCrank("xA - L2*cos(theta2)")));
}

// A driver written as an expression whose top-level form is an angle (atan2) passes ±π as a joint-angle driver
// does: its residual is the angle difference wrapped to (−π, π] (EquationSpec), not atan2 − f, which jumps by 2π
// there and stopped the sweep at t = π. Both forms: a driver with a law and an equation in t.
TEST(EquationKind, AtanDriverPassesPlusMinusPi) {
  using namespace phiq;
  for (const char* driver : {"drivers:\n  - {expr: \"atan2(yA - y0, xA - x0)\", unit: angle, law: {type: linear, "
                             "initial: 0, rate: 1}}\n",
                             "  - {type: equation, expr: \"atan2(yA - y0, xA - x0) - t\", unit: angle}\n"}) {
    const std::string text = std::string(
                                 "phiq: 1\nparameters: {x0: 0.5, y0: 0.25}\ncoordinates: {xA: 1.5, yA: 0.25}\n"
                                 "points: {O: [x0, y0], A: [xA, yA]}\n") +
                             "constraints:\n  - {name: crank, type: distance, points: [O, A], length: 1}\n" + driver +
                             "time: {start: 0, end: 7, steps: 70}\noutput: {velocities: true}\n";
    const Scene sc = parse_scene(text, "atan_driver.yaml");
    Workspace ws(*sc.model);
    SweepSummary sum;
    int rows = 0;
    const SolveStatus st = run_sweep(
        *sc.model, sc.sweep, ws,
        [&](const StepView& v) {
          EXPECT_NEAR(v.q(0), 0.5 + std::cos(v.t), 1e-9) << "t = " << v.t;
          EXPECT_NEAR(v.q(1), 0.25 + std::sin(v.t), 1e-9) << "t = " << v.t;
          EXPECT_NEAR((*v.qd)(0), -std::sin(v.t), 1e-8) << "t = " << v.t;
          ++rows;
          return true;
        },
        &sum);
    ASSERT_EQ(st, SolveStatus::kSuccess) << sum.message;
    EXPECT_EQ(rows, 71);
  }
}

}  // namespace
