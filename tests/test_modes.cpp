// Every assembly mode (phiq/modes.hpp): polynomial systems with known solutions, the four-bar against
// Freudenstein's closed form and its Grashof limit, the mode a placement is in (locate_mode()) and the distance to
// the other against the closed form, the crank-slider's two modes, the 3-RPR parallel robot's six
// complex assemblies, a cam refused with its constraint named, a runaway law named with its time, and the same bits
// on 1 and 2 threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "phiq/phiq.hpp"

namespace phiq {
namespace {

std::string modes_model_path(const std::string& rel) {
  std::string path = PHIQ_MODELS_DIR;
  path += '/';
  path += rel;
  return path;
}

std::string modes_read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A polynomial from (coefficient, exponents) pairs.
Polynomial modes_poly(std::initializer_list<std::pair<double, std::vector<int>>> terms) {
  Polynomial p;
  for (const auto& [c, e] : terms) p.terms.push_back({c, e});
  return p;
}

std::vector<Endpoint> modes_of_kind(const ModesSummary& s, EndpointKind kind) {
  std::vector<Endpoint> out;
  for (const Endpoint& e : s.endpoints)
    if (e.kind == kind) out.push_back(e);
  return out;
}

TEST(ModesPolynomial, KnownIntegerSolutionsAreEveryEndpoint) {
  // (x − 1)(x − 2) = 0, (y − 3)(y + 1) = 0: exactly the four integer points, all real and regular
  PolynomialSystem s{2,
                     {},
                     {modes_poly({{2.0, {0, 0}}, {-3.0, {1, 0}}, {1.0, {2, 0}}}),
                      modes_poly({{-3.0, {0, 0}}, {-2.0, {0, 1}}, {1.0, {0, 2}}})}};
  const ModesSummary r = solve_polynomial_system(s, {});
  ASSERT_EQ(r.status, ModesStatus::kSuccess);
  EXPECT_EQ(r.paths, 4);
  EXPECT_EQ(r.real, 4);
  EXPECT_EQ(r.complex + r.singular + r.at_infinity + r.failed_paths, 0);
  std::vector<std::pair<double, double>> expected{{1, -1}, {1, 3}, {2, -1}, {2, 3}};  // the sorted order
  ASSERT_EQ(r.endpoints.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(r.endpoints[k].x(0).real(), expected[k].first, 1e-13);
    EXPECT_NEAR(r.endpoints[k].x(1).real(), expected[k].second, 1e-13);
    EXPECT_EQ(r.endpoints[k].x(0).imag(), 0.0);
    EXPECT_LT(r.endpoints[k].residual, 1e-14);
  }
}

TEST(ModesPolynomial, ComplexInfiniteAndDoubleRootsAreClassified) {
  // x² + 1 = 0, y − 2x = 0: two complex solutions (±i, ±2i), no real one
  PolynomialSystem c{2, {}, {modes_poly({{1.0, {0, 0}}, {1.0, {2, 0}}}), modes_poly({{1.0, {0, 1}}, {-2.0, {1, 0}}})}};
  const ModesSummary rc = solve_polynomial_system(c, {});
  EXPECT_EQ(rc.real, 0);
  ASSERT_EQ(rc.complex, 2);
  for (const Endpoint& e : rc.endpoints) {
    EXPECT_NEAR(std::abs(e.x(0).imag()), 1.0, 1e-13);
    EXPECT_NEAR(std::abs(e.x(1) - 2.0 * e.x(0)), 0.0, 1e-13);
  }
  // x² − 4 = 0, x y − x = 0: (±2, 1); the other two paths of the total degree 4 diverge (to the point at infinity
  // in the y direction). (By default {x} {y} apart: 2 · 1 paths, both finite.)
  PolynomialSystem i{2, {}, {modes_poly({{-4.0, {0, 0}}, {1.0, {2, 0}}}), modes_poly({{1.0, {1, 1}}, {-1.0, {1, 0}}})}};
  EXPECT_EQ(solve_polynomial_system(i, {}).paths, 2);
  ModesOptions total_degree;
  total_degree.start_system = StartSystemChoice::kTotalDegree;
  const ModesSummary ri = solve_polynomial_system(i, total_degree);
  EXPECT_EQ(ri.paths, 4);
  ASSERT_EQ(ri.real, 2);
  EXPECT_NEAR(ri.endpoints[0].x(0).real(), -2.0, 1e-12);
  EXPECT_NEAR(ri.endpoints[1].x(0).real(), 2.0, 1e-12);
  EXPECT_NEAR(ri.endpoints[0].x(1).real(), 1.0, 1e-12);
  ASSERT_GE(ri.at_infinity, 1);
  const Endpoint far = modes_of_kind(ri, EndpointKind::kAtInfinity).front();
  EXPECT_LT(std::abs(far.x(0)), 1e-4);  // the direction (0, 1)
  EXPECT_NEAR(std::abs(far.x(1)), 1.0, 1e-12);
  // (x − 1)² = 0, y − 2 = 0: one double root, reached by both paths, singular
  PolynomialSystem d{
      2, {}, {modes_poly({{1.0, {0, 0}}, {-2.0, {1, 0}}, {1.0, {2, 0}}}), modes_poly({{1.0, {0, 1}}, {-2.0, {0, 0}}})}};
  const ModesSummary rd = solve_polynomial_system(d, {});
  EXPECT_EQ(rd.real + rd.complex, 0);
  ASSERT_EQ(rd.singular, 1);
  EXPECT_EQ(rd.endpoints[0].multiplicity, 2);
  EXPECT_NEAR(rd.endpoints[0].x(0).real(), 1.0, 1e-6);
  EXPECT_NEAR(rd.endpoints[0].x(1).real(), 2.0, 1e-10);
}

TEST(ModesPolynomial, TooManyPathsAndTooFewEquationsAreRefused) {
  PolynomialSystem s{2,
                     {},
                     {modes_poly({{2.0, {0, 0}}, {-3.0, {1, 0}}, {1.0, {2, 0}}}),
                      modes_poly({{-3.0, {0, 0}}, {-2.0, {0, 1}}, {1.0, {0, 2}}})}};
  ModesOptions o;
  o.max_paths = 3;
  const ModesSummary r = solve_polynomial_system(s, o);
  EXPECT_EQ(r.status, ModesStatus::kTooManyPaths);
  EXPECT_NE(r.message.find("4 paths"), std::string::npos) << r.message;
  EXPECT_TRUE(r.endpoints.empty());
  s.equations.pop_back();
  EXPECT_EQ(solve_polynomial_system(s, {}).status, ModesStatus::kNotSquare);
}

// Freudenstein's closed form of the four-bar (ground d from O to C on the x axis, crank a at angle θ2 from O,
// coupler b, rocker c from C): the rocker's two angles θ4, from A cos… with t = tan(θ4/2); none where the loop
// cannot close.
std::vector<double> modes_freudenstein(double a, double b, double c, double d, double theta2) {
  const double k1 = d / a, k2 = d / c, k3 = (a * a - b * b + c * c + d * d) / (2.0 * a * c);
  const double A = std::cos(theta2) - k1 - k2 * std::cos(theta2) + k3, B = -2.0 * std::sin(theta2),
               C = k1 - (k2 + 1.0) * std::cos(theta2) + k3;
  const double disc = B * B - 4.0 * A * C;
  if (disc < 0.0) return {};
  return {2.0 * std::atan2(-B + std::sqrt(disc), 2.0 * A), 2.0 * std::atan2(-B - std::sqrt(disc), 2.0 * A)};
}

Scene modes_fourbar_scene(double crank) {
  std::string text = modes_read_text(modes_model_path("seed/fourbar_mixed.yaml"));
  const std::string from = "L2: 0.4";
  text.replace(text.find(from), from.size(), "L2: " + std::to_string(crank));
  return parse_scene(text, "fourbar_mixed.yaml");
}

TEST(ModesFourBar, TwoRealModesAreFreudensteinsOpenAndCrossed) {
  const Scene scene = load_scene(modes_model_path("seed/fourbar_mixed.yaml"));
  const Model& model = *scene.model;
  const Index xb = model.coordinate_index("xB"), yb = model.coordinate_index("yB");
  for (double T : {0.0, 0.7, 2.0, 4.5}) {
    ModesOptions o;
    o.time = T;
    const AssemblyModes r = find_assembly_modes(model, o);
    ASSERT_EQ(r.summary.status, ModesStatus::kSuccess) << r.summary.message;
    EXPECT_EQ(r.summary.paths, 4);  // after θ2 and A are eliminated: two linear pin rows each, two circles
    ASSERT_EQ(r.modes.size(), 2u) << "T = " << T;
    const std::vector<double> theta4 = modes_freudenstein(0.4, 1.2, 1.0, 1.0, T);
    ASSERT_EQ(theta4.size(), 2u);
    std::vector<bool> matched(2, false);
    for (const AssemblyMode& m : r.modes) {
      EXPECT_LT(m.residual, 1e-12);
      EXPECT_FALSE(m.singular);
      for (std::size_t k = 0; k < 2; ++k)
        if (std::hypot(m.q(xb) - (1.0 + std::cos(theta4[k])), m.q(yb) - std::sin(theta4[k])) < 1e-10) matched[k] = true;
    }
    EXPECT_TRUE(matched[0] && matched[1]) << "T = " << T;
  }
}

// The four-bar's position in mixed coordinates (fourbar_mixed.yaml: θ2, A, the coupler's centre and angle, B) at
// crank angle θ2 and rocker angle θ4, from the closed form: A = a(cos θ2, sin θ2), B = C + c(cos θ4, sin θ4), the
// coupler's centre the middle of AB and its angle that of AB.
Eigen::VectorXd modes_fourbar_position(double theta2, double theta4) {
  const double xa = 0.4 * std::cos(theta2), ya = 0.4 * std::sin(theta2);
  const double xb = 1.0 + std::cos(theta4), yb = std::sin(theta4);
  Eigen::VectorXd q(8);
  q << theta2, xa, ya, (xa + xb) / 2, (ya + yb) / 2, std::atan2(yb - ya, xb - xa), xb, yb;
  return q;
}

TEST(ModesFourBar, ThePlacementIsFreudensteinsUpperModeAndTheOtherIsTheClosedFormDistanceAway) {
  // fourbar_mixed.yaml's rough placement has B above the ground, (1.1, 1.0): it assembles into the closed form's
  // solution with the larger θ4 in (−π, π] (sin θ4 > 0), at the start and at any crank angle of this crank-rocker
  const Scene scene = load_scene(modes_model_path("seed/fourbar_mixed.yaml"));
  const Model& model = *scene.model;
  ASSERT_EQ(model.coordinate_names(), std::vector<std::string>({"theta2", "xA", "yA", "x3", "y3", "psi3", "xB", "yB"}));
  for (double T : {0.0, 0.7, 2.0}) {
    SCOPED_TRACE(T);
    ModesOptions o;
    o.time = T;
    const AssemblyModes r = find_assembly_modes(model, o);
    ASSERT_EQ(r.modes.size(), 2u);
    Eigen::VectorXd q = model.initial_positions();
    ASSERT_EQ(assemble(model, T, AssemblyOptions{}, q), SolveStatus::kSuccess);
    const ModeLocation where = locate_mode(model, q, r.modes);
    ASSERT_GE(where.mode, 0);
    ASSERT_EQ(where.next, 1 - where.mode);
    std::vector<double> theta4 = modes_freudenstein(0.4, 1.2, 1.0, 1.0, T);
    ASSERT_EQ(theta4.size(), 2u);
    for (double& a : theta4) a = std::remainder(a, 2.0 * std::numbers::pi);
    std::sort(theta4.begin(), theta4.end());
    ASSERT_GT(std::sin(theta4[1]), 0.0);
    const Eigen::VectorXd upper = modes_fourbar_position(T, theta4[1]), lower = modes_fourbar_position(T, theta4[0]);
    EXPECT_LT(mode_distance(model, r.modes[static_cast<std::size_t>(where.mode)].q, upper), 1e-10);
    EXPECT_LT(mode_distance(model, r.modes[static_cast<std::size_t>(where.next)].q, lower), 1e-10);
    EXPECT_LT(where.distance, 1e-9);  // the assembled position is the mode itself, to the assembly's tolerance
    // the distance to the other mode is the closed form's, in mode_distance()'s norm written out here: the largest
    // of |Δ length| / length scale and |Δ angle| modulo 2π over the coordinates
    double expected = 0.0;
    for (Index j = 0; j < 8; ++j) {
      const bool angle = j == 0 || j == 5;
      const double d = upper(j) - lower(j);
      expected = std::max(
          expected, angle ? std::abs(std::remainder(d, 2.0 * std::numbers::pi)) : std::abs(d) / model.length_scale());
    }
    EXPECT_GT(expected, 0.1);
    EXPECT_NEAR(where.next_distance, expected, 1e-9);
  }
  // no modes: nothing located; one mode: no next
  EXPECT_EQ(locate_mode(model, model.initial_positions(), {}).mode, -1);
  const AssemblyModes r = find_assembly_modes(model, {});
  const ModeLocation one = locate_mode(model, model.initial_positions(), {r.modes[1]});
  EXPECT_EQ(one.mode, 0);
  EXPECT_EQ(one.next, -1);
}

TEST(ModesFourBar, NoRealModeBeyondTheGrashofLimit) {
  // crank a = 1.5: A = 1.5 (cos θ2, sin θ2) reaches C = (1, 0) from as far as 2.5 > b + c = 2.2. The loop closes
  // while |AC| ≤ 2.2: cos θ2 ≥ (1 + 2.25 − 2.2²) / 3 = −0.53; the limit angle
  const double limit = std::acos((1.0 + 2.25 - 2.2 * 2.2) / 3.0);
  const Scene scene = modes_fourbar_scene(1.5);
  for (double T : {limit - 0.05, limit + 0.05, std::numbers::pi}) {
    ModesOptions o;
    o.time = T;
    const AssemblyModes r = find_assembly_modes(*scene.model, o);
    ASSERT_EQ(r.summary.status, ModesStatus::kSuccess) << r.summary.message;
    const std::size_t closed_form = modes_freudenstein(1.5, 1.2, 1.0, 1.0, T).size();
    EXPECT_EQ(r.modes.size(), closed_form) << "T = " << T;
    EXPECT_EQ(r.modes.size(), T < limit ? 2u : 0u) << "T = " << T;
    if (T > limit) {
      EXPECT_EQ(r.summary.complex, 2);  // the two assemblies became a complex pair
    }
  }
}

TEST(ModesCrankSlider, TwoModesOneEachSideOfTheCrank) {
  const Scene scene = load_scene(modes_model_path("seed/crank_slider_mixed.yaml"));
  const Model& model = *scene.model;
  ModesOptions o;
  o.time = 0.4;  // θ2 = 0.8
  const AssemblyModes r = find_assembly_modes(model, o);
  ASSERT_EQ(r.summary.status, ModesStatus::kSuccess) << r.summary.message;
  ASSERT_EQ(r.modes.size(), 2u);
  const double xa = 0.3 * std::cos(0.8), ya = 0.3 * std::sin(0.8), reach = std::sqrt(1.0 - ya * ya);
  const Index xb = model.coordinate_index("xB");
  std::vector<double> found{r.modes[0].q(xb), r.modes[1].q(xb)};
  std::sort(found.begin(), found.end());
  EXPECT_NEAR(found[0], xa - reach, 1e-12);
  EXPECT_NEAR(found[1], xa + reach, 1e-12);
}

// The 3-RPR planar parallel robot at fixed leg lengths (models/benchmarks/rpr3.yaml says whose dimensions).
Scene modes_rpr_scene() { return load_scene(modes_model_path("benchmarks/rpr3.yaml")); }

TEST(ModesParallelRobot, ThreeRprHasSixAssembliesAllReal) {
  const Scene scene = modes_rpr_scene();
  const AssemblyModes r = find_assembly_modes(*scene.model, {});
  ASSERT_EQ(r.summary.status, ModesStatus::kSuccess) << r.summary.message;
  EXPECT_EQ(r.summary.paths, 16);  // 6 linear pin rows, 3 legs and the platform's circle: 2⁴
  EXPECT_EQ(r.summary.real + r.summary.complex, 6);
  EXPECT_EQ(r.summary.singular, 0);
  EXPECT_EQ(r.summary.real, 6);
  EXPECT_EQ(r.modes.size(), 6u);
  for (const AssemblyMode& m : r.modes) EXPECT_LT(m.residual, 1e-10);
}

TEST(ModesScene, ACamIsRefusedWithItsConstraintNamed) {
  const Scene scene = load_scene(modes_model_path("cams/eccentric_knife.yaml"));
  const AssemblyModes r = find_assembly_modes(*scene.model, {});
  EXPECT_EQ(r.summary.status, ModesStatus::kNotPolynomial);
  EXPECT_NE(r.summary.message.find("constraint 'cam' is not polynomial"), std::string::npos) << r.summary.message;
  EXPECT_TRUE(r.modes.empty());
}

// A driver's law taken beyond what doubles resolve of its coordinate (θ2 = t: its row is −t at the placement) is the
// time's fault, said with the constraint and the time, not "not polynomial" nor eight failed paths; just inside the
// limit (1e11 row scales) the four-bar keeps its two modes. A time outside a table's range is refused by name.
TEST(ModesScene, ARunawayLawIsNamedWithItsTime) {
  const Scene scene = load_scene(modes_model_path("seed/fourbar_mixed.yaml"));
  for (const auto& [t, said] : {std::pair{1e308, std::string("constraint 'motor' is -1e+308 at t = 1e+308")},
                                std::pair{1e20, std::string("constraint 'motor' is -1e+20 at t = 1e+20")}}) {
    ModesOptions o;
    o.time = t;
    try {
      (void)find_assembly_modes(*scene.model, o);
      ADD_FAILURE() << "no error at t = " << t;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(said), std::string::npos) << e.what();
    }
  }
  ModesOptions inside;
  inside.time = 9e10;
  EXPECT_EQ(find_assembly_modes(*scene.model, inside).summary.real, 2);
  std::string text = modes_read_text(modes_model_path("seed/fourbar_mixed.yaml"));
  const std::string law = "law: {type: linear, initial: 0, rate: 1}";
  ASSERT_NE(text.find(law), std::string::npos);
  text.replace(text.find(law), law.size(), "law: {type: table, t: [0, 1, 2], values: [0, 0.5, 0.6]}");
  const Scene tabled = parse_scene(text, "fourbar_table.yaml");
  ModesOptions late;
  late.time = 3;
  EXPECT_THROW(
      {
        try {
          (void)find_assembly_modes(*tabled.model, late);
        } catch (const Error& e) {
          EXPECT_STREQ(e.what(), "ModesOptions: driver 'motor' is not defined at t = 3");
          throw;
        }
      },
      Error);
}

TEST(ModesDeterminism, OneAndTwoThreadsGiveTheSameBits) {
  const Scene scene = modes_rpr_scene();
  ModesOptions one, two;
  one.threads = 1, two.threads = 2;
  const AssemblyModes a = find_assembly_modes(*scene.model, one), b = find_assembly_modes(*scene.model, two);
  ASSERT_EQ(a.summary.endpoints.size(), b.summary.endpoints.size());
  for (std::size_t k = 0; k < a.summary.endpoints.size(); ++k) {
    const Endpoint &x = a.summary.endpoints[k], &y = b.summary.endpoints[k];
    EXPECT_EQ(x.kind, y.kind);
    EXPECT_EQ(x.multiplicity, y.multiplicity);
    ASSERT_EQ(x.x.size(), y.x.size());
    for (Eigen::Index v = 0; v < x.x.size(); ++v) {
      EXPECT_EQ(x.x(v).real(), y.x(v).real());
      EXPECT_EQ(x.x(v).imag(), y.x(v).imag());
    }
  }
}

// A row of degree 4 in twelve coordinates, each of degree 1 in it: its 1 820 monomials of degree ≤ 4 are past what a
// fit takes (1 500), the 794 multilinear ones are not. The fit finds each coordinate's own degree first and fits
// those: x1 = … = x12 = x with 3 x⁴ = 3, two real modes at ±1 and two complex (±i) of four paths.
TEST(ModesScene, AMultilinearRowOfTwelveCoordinatesIsFitted) {
  std::string text = "phiq: 1\nname: multilinear\ncoordinates: {";
  for (int i = 1; i <= 12; ++i) text += (i > 1 ? ", x" : "x") + std::to_string(i) + ": 0.9";
  text +=
      "}\nconstraints:\n  - {name: product, type: equation, "
      "expr: \"x1*x2*x3*x4 + x5*x6*x7*x8 + x9*x10*x11*x12 - 3\"}\n";
  for (int i = 2; i <= 12; ++i)
    text += "  - {name: same" + std::to_string(i) + ", type: equation, expr: \"x" + std::to_string(i) + " - x" +
            std::to_string(i - 1) + "\", unit: length}\n";
  text += "time: {start: 0, end: 1, steps: 1}\n";
  const Scene scene = parse_scene(text, "multilinear.yaml");
  const AssemblyModes r = find_assembly_modes(*scene.model, {});
  ASSERT_EQ(r.summary.status, ModesStatus::kSuccess) << r.summary.message;
  EXPECT_EQ(r.summary.paths, 4);
  EXPECT_EQ(r.summary.real, 2);
  EXPECT_EQ(r.summary.complex, 2);
  ASSERT_EQ(r.modes.size(), 2u);
  std::vector<double> signs;
  for (const AssemblyMode& m : r.modes) {
    ASSERT_EQ(m.q.size(), 12);
    for (Index j = 0; j < 12; ++j) EXPECT_NEAR(m.q(j), m.q(0), 1e-12);
    EXPECT_NEAR(std::abs(m.q(0)), 1.0, 1e-12);
    signs.push_back(m.q(0));
  }
  EXPECT_LT(signs[0] * signs[1], 0.0);
}

}  // namespace
}  // namespace phiq
