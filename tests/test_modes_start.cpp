// The homotopy's start systems and end game (phiq/modes.hpp): multi-homogeneous Bézout numbers against counts by
// hand, a bilinear system in one path per solution, the total-degree and multi-homogeneous starts finding the same
// assembly modes, lowered degrees keeping the finite solutions (two circles lose their two circular points at
// infinity), the Stewart–Gough platform's 8192 total-degree paths lowered to 432 and a few of them tracked to its
// leg equations, and a triple root found by the end game; ends at infinity placed by the end game, and a path above
// the winding limit failed by name.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "modes/homotopy.hpp"
#include "modes_stewart.hpp"
#include "phiq/phiq.hpp"

namespace phiq {
namespace {

std::string modes_start_model(const std::string& rel) {
  std::string path = PHIQ_MODELS_DIR;
  path += '/';
  path += rel;
  return path;
}

Polynomial modes_start_poly(std::initializer_list<std::pair<double, std::vector<int>>> terms) {
  Polynomial p;
  for (const auto& [c, e] : terms) p.terms.push_back({c, e});
  return p;
}

// (x − 1)³ = 0, y − 2 = 0: a triple root, the end game's (from x³ = 1: x = 1 throughout, and a cycle of two paths)
PolynomialSystem modes_start_triple_root() {
  return {2,
          {},
          {modes_start_poly({{-1.0, {0, 0}}, {3.0, {1, 0}}, {-3.0, {2, 0}}, {1.0, {3, 0}}}),
           modes_start_poly({{1.0, {0, 1}}, {-2.0, {0, 0}}})}};
}

// (A − λ I) v = 0 with v1 + v2 + v3 = 1, A upper triangular with eigenvalues 1, 2, 3; variables λ, v1, v2, v3.
PolynomialSystem modes_start_eigenproblem() {
  const double a[3][3] = {{1, 1, 0}, {0, 2, 1}, {0, 0, 3}};
  PolynomialSystem s{4, {"lambda", "v1", "v2", "v3"}, {}};
  for (int k = 0; k < 3; ++k) {
    Polynomial row;
    for (int j = 0; j < 3; ++j)
      if (a[k][j] != 0.0) {
        std::vector<int> e(4, 0);
        e[static_cast<std::size_t>(j + 1)] = 1;
        row.terms.push_back({a[k][j], e});
      }
    std::vector<int> e(4, 0);
    e[0] = 1, e[static_cast<std::size_t>(k + 1)] = 1;
    row.terms.push_back({-1.0, e});
    s.equations.push_back(row);
  }
  s.equations.push_back(
      modes_start_poly({{1.0, {0, 1, 0, 0}}, {1.0, {0, 0, 1, 0}}, {1.0, {0, 0, 0, 1}}, {-1.0, {0, 0, 0, 0}}}));
  return s;
}

// Each angle's (cos, sin) one group, every other variable another: the grouping of a model's system by its names.
std::vector<int> modes_start_angles_apart(const PolynomialSystem& s) {
  std::vector<int> g;
  for (const std::string& name : s.names) g.push_back(name.rfind("cos(", 0) == 0 || name.rfind("sin(", 0) == 0);
  return g;
}

TEST(ModesStart, BezoutNumbersAsCountedByHand) {
  const PolynomialSystem eigen = modes_start_eigenproblem();
  EXPECT_EQ(eigen.total_degree(), 8);
  // {λ} {v}: three equations of degrees (1, 1), one (0, 1): the coefficient of α β³ in (α + β)³ β
  EXPECT_EQ(multihomogeneous_bezout_number(eigen, {0, 1, 1, 1}), 3);
  // every variable alone, all degrees 1: the perfect matchings of equations to variables they read (row 1 reads λ,
  // v1, v2; row 2 λ, v2, v3; row 3 λ, v3; the normalisation v1, v2, v3): 3 with the normalisation on v1, 2 on v2,
  // 1 on v3
  EXPECT_EQ(multihomogeneous_bezout_number(eigen, {0, 1, 2, 3}), 6);
  EXPECT_EQ(multihomogeneous_bezout_number(eigen, {0, 0, 0, 0}), 8);
  EXPECT_THROW(multihomogeneous_bezout_number(eigen, {0, 1}), Error);
  EXPECT_THROW(multihomogeneous_bezout_number(eigen, {0, 2, 2, 2}), Error);  // group 1 empty

  // The 3-RPR (6 linear pin rows: 2 in the platform's x, y alone, 4 with its cos, sin; 3 leg circles; the
  // platform's circle): {x, y, P_i} {c, s}: α⁸ β² in α² (α + β)⁴ (2α)³ (2β) = 16 · 4
  const Scene rpr3 = load_scene(modes_start_model("benchmarks/rpr3.yaml"));
  const ModelPolynomials p = find_polynomial_system(*rpr3.model, {});
  ASSERT_EQ(p.system.variables, 10);
  EXPECT_EQ(multihomogeneous_bezout_number(p.system, modes_start_angles_apart(p.system)), 64);
  EXPECT_EQ(p.system.total_degree(), 16);

  // The Stewart–Gough platform: the normalisation (0, 2) and six legs of degree 2 in (x, y, z) and 4 in e:
  // α³ β⁴ in (2α + 4β)⁶ 2β = 2 · C(6, 3) · 2³ · 4³, against the total degree 4⁶ · 2
  const Scene stewart = parse_scene(phiq::test::kModesStewartScene, "stewart.yaml");
  const ModelPolynomials sp = find_polynomial_system(*stewart.model, {});
  ASSERT_EQ(sp.system.variables, 7);
  EXPECT_EQ(sp.system.total_degree(), 8192);
  EXPECT_EQ(multihomogeneous_bezout_number(sp.system, {0, 0, 0, 1, 1, 1, 1}), 20480);
}

TEST(ModesStart, StewartGoughDegreesLoweredTo432Paths) {
  // Each leg's quartic part is |p|² (e·e)², the normalisation's e·e times a quadric: the leg less that multiple is
  // cubic; the six cubic parts 2 t·R(e) p_i span three dimensions, so three legs less combinations of the other three
  // are quadratic: 2 · 3³ · 2³ paths. Refused above one path, nothing tracked (the full solve is bench/'s).
  const Scene stewart = parse_scene(phiq::test::kModesStewartScene, "stewart.yaml");
  ModesOptions o;
  o.max_paths = 1;
  const AssemblyModes r = find_assembly_modes(*stewart.model, o);
  EXPECT_EQ(r.summary.status, ModesStatus::kTooManyPaths);
  EXPECT_EQ(r.summary.paths, 432);
  EXPECT_EQ(r.summary.total_degree, 8192);
  EXPECT_EQ(r.summary.start_system, "total degree, degrees lowered");
  EXPECT_NE(r.summary.message.find("(total degree, degrees lowered) has 432 paths"), std::string::npos)
      << r.summary.message;
  o.lower_degrees = false;
  EXPECT_EQ(find_assembly_modes(*stewart.model, o).summary.paths, 8192);
}

TEST(ModesStart, BilinearSystemTakesOnePathPerSolution) {
  const PolynomialSystem eigen = modes_start_eigenproblem();
  ModesOptions o;
  o.groupings = {{0, 1, 1, 1}};
  const ModesSummary r = solve_polynomial_system(eigen, o);
  ASSERT_EQ(r.status, ModesStatus::kSuccess);
  EXPECT_EQ(r.paths, 3);
  EXPECT_EQ(r.total_degree, 8);
  EXPECT_EQ(r.start_system, "multi-homogeneous {lambda} {v1 v2 v3}");
  ASSERT_EQ(r.real, 3);
  EXPECT_EQ(r.complex + r.singular + r.at_infinity + r.failed_paths + r.duplicate_paths, 0);
  // sorted by λ: (1; 1, 0, 0), (2; 1/2, 1/2, 0), (3; 1/5, 2/5, 2/5)
  const double expected[3][4] = {{1, 1, 0, 0}, {2, 0.5, 0.5, 0}, {3, 0.2, 0.4, 0.4}};
  for (int k = 0; k < 3; ++k)
    for (int v = 0; v < 4; ++v)
      EXPECT_NEAR(r.endpoints[static_cast<std::size_t>(k)].x(v).real(), expected[k][v], 1e-12);
  // without the grouping: every variable alone (6 paths) is still fewer than the total degree's 8
  const ModesSummary alone = solve_polynomial_system(eigen, {});
  EXPECT_EQ(alone.paths, 6);
  EXPECT_EQ(alone.start_system, "multi-homogeneous {lambda} {v1} {v2} {v3}");
  EXPECT_EQ(alone.real, 3);
  EXPECT_EQ(alone.failed_paths + alone.duplicate_paths, 0);
}

TEST(ModesStart, TotalDegreeAndMultiHomogeneousFindTheSameModes) {
  for (const char* rel : {"seed/fourbar_mixed.yaml", "seed/fourbar_natural.yaml", "seed/crank_slider_mixed.yaml",
                          "benchmarks/rpr3.yaml"}) {
    SCOPED_TRACE(rel);
    const Scene scene = load_scene(modes_start_model(rel));
    ModesOptions total;
    total.time = scene.sweep.t_begin, total.block_solve = false, total.lower_degrees = false;
    total.start_system = StartSystemChoice::kTotalDegree;
    const AssemblyModes a = find_assembly_modes(*scene.model, total);
    ModesOptions multi = total;
    multi.start_system = StartSystemChoice::kMultiHomogeneous;
    multi.groupings = {modes_start_angles_apart(a.polynomials.system)};
    const AssemblyModes b = find_assembly_modes(*scene.model, multi);
    ASSERT_EQ(a.summary.status, ModesStatus::kSuccess) << a.summary.message;
    ASSERT_EQ(b.summary.status, ModesStatus::kSuccess) << b.summary.message;
    EXPECT_EQ(a.summary.start_system, "total degree");
    // one unknown (the crank-slider's slider) has no grouping of two groups: the total degree again
    EXPECT_EQ(b.summary.start_system.rfind("multi-homogeneous", 0) == 0, a.polynomials.system.variables > 1)
        << b.summary.start_system;
    EXPECT_EQ(b.summary.failed_paths + b.summary.duplicate_paths, 0);
    EXPECT_EQ(a.summary.complex, b.summary.complex);
    ASSERT_EQ(a.modes.size(), b.modes.size());
    ASSERT_GE(a.modes.size(), 2u);
    // the same points, one to one (the order may differ where two modes share a coordinate to rounding)
    std::vector<bool> used(b.modes.size(), false);
    for (std::size_t k = 0; k < a.modes.size(); ++k) {
      double nearest = 1e300;
      std::size_t at = 0;
      for (std::size_t m = 0; m < b.modes.size(); ++m) {
        const double d = (a.modes[k].q - b.modes[m].q).cwiseAbs().maxCoeff();
        if (!used[m] && d < nearest) nearest = d, at = m;
      }
      EXPECT_LE(nearest, 1e-8) << "mode " << k;
      used[at] = true;
    }
  }
}

TEST(ModesStart, LoweredDegreesKeepTheFiniteSolutionsAndLoseTheCircularPoints) {
  // x² + y² = 1 and (x − 1)² + y² = 1 meet at (1/2, ±√3/2) and, projectively, at the circular points (1 : ±i : 0)
  // every two circles share: the total degree's other two paths end there. Less the first, the second is the line
  // 1 − 2x = 0: two paths, both finite.
  const PolynomialSystem s{2,
                           {},
                           {modes_start_poly({{1.0, {2, 0}}, {1.0, {0, 2}}, {-1.0, {0, 0}}}),
                            modes_start_poly({{1.0, {2, 0}}, {-2.0, {1, 0}}, {1.0, {0, 2}}})}};
  ModesOptions as_given;
  as_given.lower_degrees = false;
  as_given.start_system = StartSystemChoice::kTotalDegree;
  const ModesSummary a = solve_polynomial_system(s, as_given);
  const ModesSummary b = solve_polynomial_system(s, {});
  EXPECT_EQ(a.paths, 4);
  EXPECT_EQ(b.paths, 2);
  EXPECT_EQ(b.start_system, "total degree, degrees lowered");
  ASSERT_EQ(a.real, 2);
  ASSERT_EQ(b.real, 2);
  for (std::size_t k = 0; k < 2; ++k) {
    const double y = (k == 0 ? -1.0 : 1.0) * std::sqrt(3.0) / 2.0;
    EXPECT_NEAR(b.endpoints[k].x(0).real(), 0.5, 1e-14);
    EXPECT_NEAR(b.endpoints[k].x(1).real(), y, 1e-14);
    // the same point among the total degree's (in either order: their x agree to rounding)
    double nearest = 1e300;
    for (std::size_t m = 0; m < 2; ++m)
      nearest = std::min(nearest, (a.endpoints[m].x - b.endpoints[k].x).cwiseAbs().maxCoeff());
    EXPECT_LE(nearest, 1e-13);
  }
  EXPECT_EQ(b.at_infinity + b.failed_paths, 0);
  ASSERT_EQ(a.at_infinity, 2);  // (1, ±i) / √2 directions: |y| = |x|, y = ±i x
  for (const Endpoint& e : a.endpoints) {
    if (e.kind == EndpointKind::kAtInfinity) {
      EXPECT_NEAR(std::abs(e.x(1) * e.x(1) + e.x(0) * e.x(0)), 0.0, 1e-6) << e.x.transpose();
      EXPECT_LE(e.residual, 1e-12);  // regular solutions of the homogenised equations, tracked straight to t = 0
      EXPECT_LT(e.condition, 1e3);
      EXPECT_EQ(e.multiplicity, 1);
    }
  }
}

TEST(ModesStart, EndGameFindsATripleRoot) {
  // (x − 1)³ = 0, y − 2 = 0: the three paths of x³ = 1 all end at x = 1 (one of them x = 1 throughout, the other two
  // a Puiseux cycle of winding number 2), where Newton alone stalls; the end game's means put it to 1e-8
  const PolynomialSystem s = modes_start_triple_root();
  const ModesSummary r = solve_polynomial_system(s, {});
  ASSERT_EQ(r.status, ModesStatus::kSuccess);
  EXPECT_EQ(r.paths, 3);
  ASSERT_EQ(r.singular, 1);
  EXPECT_EQ(r.real + r.complex + r.at_infinity + r.failed_paths, 0);
  EXPECT_EQ(r.endpoints[0].multiplicity, 3);
  EXPECT_EQ(r.end_game_paths, 3);
  EXPECT_NEAR(std::abs(r.endpoints[0].x(0) - 1.0), 0.0, 1e-8);
  EXPECT_NEAR(std::abs(r.endpoints[0].x(1) - 2.0), 0.0, 1e-12);
}

TEST(ModesStart, EndGamePlacesTheEndsAtInfinityOfACollapsingStep) {
  // xy − 1 = 0, xy + x − 2 = 0: one finite solution, (1, 1); the other three of the total degree's four paths
  // diverge. Homogenised, xy − z² = xy + xz − 2z² = 0 meet at infinity at (1 : 0 : 0), simply (y = z², z = z²), and
  // at (0 : 1 : 0) twice (x = z², z²(z − 1) = 0), where the Jacobian is singular: those two paths' steps collapse, and
  // the end game, not where they collapsed, says where they end. (Degrees lowered, the second is x − 1.)
  const PolynomialSystem s{2,
                           {},
                           {modes_start_poly({{1.0, {1, 1}}, {-1.0, {0, 0}}}),
                            modes_start_poly({{1.0, {1, 1}}, {1.0, {1, 0}}, {-2.0, {0, 0}}})}};
  ModesOptions o;
  o.lower_degrees = false, o.start_system = StartSystemChoice::kTotalDegree;  // ({x} {y}: 2 paths)
  const ModesSummary r = solve_polynomial_system(s, o);
  ASSERT_EQ(r.status, ModesStatus::kSuccess);
  EXPECT_EQ(r.paths, 4);
  ASSERT_EQ(r.real, 1);
  EXPECT_EQ(r.complex + r.singular + r.failed_paths, 0);
  EXPECT_TRUE(r.failures.empty());
  EXPECT_EQ(r.end_game_paths, 2);
  ASSERT_EQ(r.at_infinity, 2);
  EXPECT_NEAR(std::abs(r.endpoints[0].x(0) - 1.0) + std::abs(r.endpoints[0].x(1) - 1.0), 0.0, 1e-12);
  int simple = 0, twice = 0;
  for (const Endpoint& e : r.endpoints) {
    if (e.kind != EndpointKind::kAtInfinity) continue;
    const bool along_x = std::abs(e.x(0)) > std::abs(e.x(1));  // the direction, its largest coordinate 1
    EXPECT_NEAR(std::abs(e.x(along_x ? 1 : 0)), 0.0, 1e-6) << e.x.transpose();
    EXPECT_NEAR(std::abs(e.x(along_x ? 0 : 1)), 1.0, 1e-12) << e.x.transpose();
    EXPECT_LE(e.residual, 1e-8);  // of the homogenised equations there
    EXPECT_EQ(e.multiplicity, along_x ? 1 : 2);
    if (along_x)
      EXPECT_LT(e.condition, 10.0);  // regular at infinity
    else
      EXPECT_GT(e.condition, 1e6);  // the double point
    (along_x ? simple : twice) += 1;
  }
  EXPECT_EQ(simple, 1);
  EXPECT_EQ(twice, 1);
}

TEST(ModesStart, APathAboveTheWindingLimitFailsNamed) {
  // (x − 1)³ = 0, y = 2 from x³ = 1: the start root x = 1 is the target's, and the homotopy is
  // (x − 1) ((x − 1)² + γt (x² + x + 1) / (1 − t)): one path stays at x = 1 (winding number 1, its step collapsing
  // all the same: the Jacobian is singular there), the other two are a cycle of winding number 2. With one turn
  // allowed those two fail, each named with why, neither classified from where its step collapsed.
  const PolynomialSystem s = modes_start_triple_root();
  ModesOptions o;
  o.max_winding = 1;
  const ModesSummary r = solve_polynomial_system(s, o);
  ASSERT_EQ(r.status, ModesStatus::kSuccess);
  EXPECT_EQ(r.failed_paths, 2);
  EXPECT_EQ(r.end_game_paths, 1);
  ASSERT_EQ(r.real + r.complex + r.singular + r.at_infinity, 1);
  ASSERT_EQ(r.failures.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(r.failures[k].first, static_cast<std::int64_t>(k + 1));  // path 0 is x = 1's
    EXPECT_NE(r.failures[k].second.find("did not close within 1 turn of"), std::string::npos) << r.failures[k].second;
  }
  o.max_winding = 2;  // enough: the triple root, its three paths
  const ModesSummary two = solve_polynomial_system(s, o);
  ASSERT_EQ(two.singular, 1);
  EXPECT_EQ(two.endpoints[0].multiplicity, 3);
  EXPECT_EQ(two.end_game_paths, 3);
  EXPECT_TRUE(two.failures.empty());
}

TEST(ModesStart, MultiHomogeneousAndEndGameSameBitsOnOneAndTwoThreads) {
  // the four-bar from a linear product over every variable alone (16 paths, most ending at infinity in some group)
  const Scene scene = load_scene(modes_start_model("seed/fourbar_mixed.yaml"));
  ModesOptions o;
  o.block_solve = false, o.start_system = StartSystemChoice::kMultiHomogeneous, o.threads = 1;
  const AssemblyModes one = find_assembly_modes(*scene.model, o);
  o.threads = 2;
  const AssemblyModes two = find_assembly_modes(*scene.model, o);
  ASSERT_EQ(one.summary.status, ModesStatus::kSuccess);
  EXPECT_EQ(one.summary.paths, 16);
  ASSERT_EQ(one.summary.endpoints.size(), two.summary.endpoints.size());
  for (std::size_t k = 0; k < one.summary.endpoints.size(); ++k) {
    EXPECT_EQ(one.summary.endpoints[k].kind, two.summary.endpoints[k].kind);
    EXPECT_TRUE(one.summary.endpoints[k].x == two.summary.endpoints[k].x) << "endpoint " << k;
  }
  // the end game's ends: (x − 1)³ = 0, y = 2 (three paths: x = 1 throughout and a cycle of two)
  const PolynomialSystem triple = modes_start_triple_root();
  ModesOptions t;
  t.threads = 1;
  const ModesSummary a = solve_polynomial_system(triple, t);
  t.threads = 2;
  const ModesSummary b = solve_polynomial_system(triple, t);
  EXPECT_EQ(a.end_game_paths, 3);
  EXPECT_EQ(b.end_game_paths, 3);
  ASSERT_EQ(a.endpoints.size(), 1u);
  ASSERT_EQ(b.endpoints.size(), 1u);
  EXPECT_TRUE(a.endpoints[0].x == b.endpoints[0].x);
}

// A few of the Stewart–Gough platform's 432 lowered paths tracked as solve_polynomial_system() tracks them (the whole
// solve is bench/'s): each ends at a finite point or diverges; a finite end is a solution, every equation (six legs
// and the normalisation, as fitted from the model) zero there to 1e-9 of its largest coefficient before any
// refinement, and Newton on the original equations keeps it where it is.
TEST(ModesStart, StewartGoughPathsEndOnTheLegEquations) {
  const Scene stewart = parse_scene(phiq::test::kModesStewartScene, "stewart.yaml");
  const ModelPolynomials p = find_polynomial_system(*stewart.model, {});
  ASSERT_EQ(p.system.variables, 7);
  ASSERT_EQ(p.system.equations.size(), 7u);
  const PolynomialSystem lowered = modes_detail::lowered_degrees(p.system);
  const modes_detail::Grouping one = modes_detail::single_group(7);
  modes_detail::Random random(20261203);
  modes_detail::StartSystem start;
  ASSERT_TRUE(modes_detail::make_start_system(modes_detail::group_degrees(lowered, one), one, random, start));
  ASSERT_EQ(start.paths, 432);
  const modes_detail::CompiledSystem target(lowered, one), original(p.system);
  modes_detail::Homotopy h{&target, &start, random.unit_complex(), Eigen::VectorXcd(8)};
  for (int v = 0; v < 8; ++v) h.patch(v) = random.unit_complex();
  int finite = 0;
  for (std::int64_t path = 0; path < 432; path += 54) {  // 8 paths spread over the start points
    SCOPED_TRACE(path);
    const modes_detail::PathEnd end = modes_detail::track_path(h, path, 32);
    ASSERT_TRUE(end.reached) << end.failure;
    EXPECT_EQ(end.t, 0.0);
    // a finite end is tracked to t = 0 itself, its homogenising coordinate of the patch's order; the others diverge
    // (432 paths, 80 finite solutions: 40 at ±e) to a solution set at infinity, their step collapsing near t = 0:
    // the end game places their end on the patch, its homogenising coordinate zero to the end's accuracy
    const double finiteness = h.finiteness(end.X);
    if (!(finiteness > 1e-2)) {
      EXPECT_GT(end.winding, 0);
      EXPECT_LE(end.accuracy, 1e-8);
      EXPECT_LE(finiteness, std::max(1e-8, 10.0 * end.accuracy)) << "accuracy " << end.accuracy;
      continue;
    }
    ++finite;
    const Eigen::VectorXcd x = h.affine(end.X);
    std::vector<std::complex<double>> f(7);
    p.system.evaluate(x.data(), f.data());
    for (std::size_t i = 0; i < 7; ++i) {
      double largest = 0.0;
      for (const PolynomialTerm& t : p.system.equations[i].terms) largest = std::max(largest, std::abs(t.coefficient));
      EXPECT_LE(std::abs(f[i]) / largest, 1e-9) << "equation " << i << " at " << x.transpose();
    }
    Eigen::VectorXcd refined = x;
    double condition = 0.0;
    EXPECT_LE(modes_detail::refine_endpoint(original, refined, &condition), 1e-12);
    EXPECT_LE((refined - x).cwiseAbs().maxCoeff(), 1e-8 * (1.0 + x.cwiseAbs().maxCoeff()));
  }
  EXPECT_GE(finite, 2);
}

}  // namespace
}  // namespace phiq
