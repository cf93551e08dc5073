// The block-by-block solve of phiq modes against the whole-system solve, the closed form and PHCpack. The IFToMM N
// four-bar (phiq generate nfourbar) has unit cranks, couplers and ground links: from a crank tip P_i the next loop
// closes at the parallelogram (P_i + (1, 0)) or folds onto the pivot before it (P_{i+1} = (i, 0)); after a fold the
// next loop's two circles touch (centres 2 apart, radii 1): a double root, so every later crank folds too. Its real
// assemblies at crank angle θ: P_0 = σ(cos θ, sin θ), σ = 1 (σ = −1 also in natural coordinates, where the
// segment angle holds the line, not the direction), the parallelogram up to the loop k that folds (none, or 1 … N),
// singular when k < N (a later loop touches): N + 1 modes, two regular (in natural coordinates twice that). A
// block solve that substitutes a fold's tip, known only to √ε, into the next loop splits its double root into two
// real or two complex ones; it must find the whole system's modes, or solve the whole system and say why.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "generate.hpp"
#include "modes/model_rows.hpp"
#include "modes_phc.hpp"
#include "phiq/phiq.hpp"

namespace phiq {
namespace {

Scene modes_blocks_nfourbar(int n, const std::string& coords) {
  tools::GenerateOptions o;
  o.kind = "nfourbar", o.n = n, o.coords = coords, o.steps = 1;
  return parse_scene(tools::generate_scene(o), "nfourbar.yaml");
}

// Crank i's tip in mode q: natural (x_i, y_i); reference-point twice the crank's centre less its pivot (i, 0).
Eigen::Vector2d modes_blocks_tip(const Model& model, const Eigen::VectorXd& q, int i, bool natural) {
  const std::string k = std::to_string(i);
  if (natural) return {q(model.coordinate_index("x" + k)), q(model.coordinate_index("y" + k))};
  return {2.0 * q(model.coordinate_index("xc" + k)) - i, 2.0 * q(model.coordinate_index("yc" + k))};
}

// The modes of the closed form (file comment) each found exactly once, singular exactly when a later loop touches.
void modes_blocks_expect_closed_form(const Model& model, const AssemblyModes& r, int n, bool natural) {
  const double theta = std::numbers::pi / 4.0;
  int expected = 0, hits = 0, wrong_kind = 0;
  for (const double sigma : natural ? std::vector<double>{1.0, -1.0} : std::vector<double>{1.0})
    for (int fold = 1; fold <= n + 1; ++fold) {  // n + 1: no loop folds
      ++expected;
      const bool singular = fold < n;
      for (const AssemblyMode& m : r.modes) {
        double d = 0.0;
        for (int i = 0; i <= n; ++i) {
          const Eigen::Vector2d tip = i < fold ? Eigen::Vector2d(i + sigma * std::cos(theta), sigma * std::sin(theta))
                                               : Eigen::Vector2d(i - 1.0, 0.0);
          d = std::max(d, (modes_blocks_tip(model, m.q, i, natural) - tip).cwiseAbs().maxCoeff());
        }
        if (d > 1e-6) continue;
        ++hits;
        wrong_kind += m.singular != singular;
      }
    }
  EXPECT_EQ(static_cast<int>(r.modes.size()), expected);
  EXPECT_EQ(hits, expected);
  EXPECT_EQ(wrong_kind, 0);
}

int modes_blocks_singular(const AssemblyModes& r) {
  int singular = 0;
  for (const AssemblyMode& m : r.modes) singular += m.singular;
  return singular;
}

// Both solves of one scene: the same modes (to 1e-6, the accuracy of a singular one), the same singular ones.
void modes_blocks_expect_same(const Model& model, const AssemblyModes& blocks, const AssemblyModes& whole) {
  ASSERT_EQ(blocks.summary.status, ModesStatus::kSuccess) << blocks.summary.message;
  ASSERT_EQ(whole.summary.status, ModesStatus::kSuccess) << whole.summary.message;
  EXPECT_EQ(whole.summary.method, ModesMethod::kWholeSystem);
  ASSERT_EQ(blocks.modes.size(), whole.modes.size());
  EXPECT_EQ(modes_blocks_singular(blocks), modes_blocks_singular(whole));
  for (const AssemblyMode& m : blocks.modes) {
    int same = 0;
    for (const AssemblyMode& w : whole.modes)
      same += mode_distance(model, m.q, w.q) <= 1e-6 && m.singular == w.singular;
    EXPECT_EQ(same, 1) << "a mode of the block solve that the whole system has " << same << " times";
  }
}

AssemblyModes modes_blocks_solve(const Model& model, bool blocks) {
  ModesOptions o;
  o.block_solve = blocks;
  return find_assembly_modes(model, o);
}

// Block by block and whole: the same modes, the closed form's. After a fold the block solve meets a singular
// solution and solves that block with all after it, for that fold: at N = 3, 2 + 2 · 4 paths for P_0 and P_1, then
// 4 · 4 for P_2, the two folds at loop 1 with loops 2 and 3 together (2 · 16) and the two parallelograms' last loop
// (4 · 4): 74 paths, not the whole system's 2⁷ = 128.
TEST(ModesBlocks, NfourbarNaturalAsTheWholeSystemAndTheClosedForm) {
  for (int n = 1; n <= 3; ++n) {
    SCOPED_TRACE("nfourbar " + std::to_string(n) + " natural");
    const Scene scene = modes_blocks_nfourbar(n, "natural");
    const AssemblyModes blocks = modes_blocks_solve(*scene.model, true);
    const AssemblyModes whole = modes_blocks_solve(*scene.model, false);
    modes_blocks_expect_same(*scene.model, blocks, whole);
    modes_blocks_expect_closed_form(*scene.model, blocks, n, true);
    EXPECT_EQ(whole.summary.paths, std::int64_t{1} << (2 * n + 1));
    EXPECT_EQ(blocks.summary.method, ModesMethod::kBlocks);
    EXPECT_EQ(blocks.summary.blocks, n + 1);
    EXPECT_TRUE(blocks.summary.method_note.empty()) << blocks.summary.method_note;
  }
  // (the blocks' total degrees; lowered, a loop's two circles about one point are a circle and a line: 38 paths)
  const Scene three = modes_blocks_nfourbar(3, "natural");
  const AssemblyModes blocks3 = modes_blocks_solve(*three.model, true);
  EXPECT_EQ(blocks3.summary.total_degree, 2 + 2 * 4 + 4 * 4 + 2 * 16 + 4 * 4);
  EXPECT_EQ(blocks3.summary.paths, 38);
}

// Reference-point coordinates: one loop is one block of 8 unknowns (both bodies' positions and (c, s)); N = 1 is
// one block, solved whole.
TEST(ModesBlocks, NfourbarReferencePointAsTheWholeSystemAndTheClosedForm) {
  for (int n = 1; n <= 2; ++n) {
    SCOPED_TRACE("nfourbar " + std::to_string(n) + " reference-point");
    const Scene scene = modes_blocks_nfourbar(n, "reference-point");
    const AssemblyModes blocks = modes_blocks_solve(*scene.model, true);
    const AssemblyModes whole = modes_blocks_solve(*scene.model, false);
    modes_blocks_expect_same(*scene.model, blocks, whole);
    modes_blocks_expect_closed_form(*scene.model, blocks, n, false);
    EXPECT_EQ(blocks.summary.method == ModesMethod::kBlocks, n > 1) << blocks.summary.method_note;
    EXPECT_EQ(whole.summary.paths, std::int64_t{1} << (2 * n));
  }
  // N = 3 (the whole system's 64 paths in 24 unknowns take a second): the closed form's four, by 36 paths
  const Scene three = modes_blocks_nfourbar(3, "reference-point");
  const AssemblyModes r = modes_blocks_solve(*three.model, true);
  EXPECT_EQ(r.summary.method, ModesMethod::kBlocks);
  EXPECT_EQ(r.summary.paths, 36);
  modes_blocks_expect_closed_form(*three.model, r, 3, false);
}

// N = 4, natural: the scene whose block solve, substituting singular solutions, found 5 regular and 2 singular
// modes of the 10, and whose whole-system count by the condition number alone was 8 regular and 1 singular (a
// k-fold tangency is placed to about √ε, its condition 1e7 … 1e9; and the fold of all four loops at θ + π was called
// complex). PHCpack (phc -b) finds 4 regular and 6 singular real solutions of the same system in 512 paths.
TEST(ModesBlocks, NfourbarFourNaturalHasFourRegularAndSixSingularModes) {
  const Scene scene = modes_blocks_nfourbar(4, "natural");
  const AssemblyModes r = modes_blocks_solve(*scene.model, true);
  ASSERT_EQ(r.summary.status, ModesStatus::kSuccess) << r.summary.message;
  EXPECT_EQ(r.summary.method, ModesMethod::kBlocks);
  EXPECT_EQ(r.summary.total_degree, 218);  // the whole system: 512
  EXPECT_EQ(r.summary.paths, 110);         // the blocks' degrees lowered
  EXPECT_EQ(modes_blocks_singular(r), 6);
  modes_blocks_expect_closed_form(*scene.model, r, 4, true);
}

// PHCpack on the same systems (N = 2, a singular mode among them): its real regular solutions and its distinct
// real singular ones are phiq's block solve's.
TEST(ModesBlocks, NfourbarAsPhcCountsIt) {
  if (!modes_phc::phc_installed()) GTEST_SKIP() << "phc (Debian package phcpack) is not installed";
  for (const char* coords : {"natural", "reference-point"}) {
    SCOPED_TRACE(std::string("nfourbar 2 ") + coords);
    const Scene scene = modes_blocks_nfourbar(2, coords);
    const AssemblyModes r = modes_blocks_solve(*scene.model, true);
    ASSERT_EQ(r.summary.status, ModesStatus::kSuccess) << r.summary.message;
    EXPECT_EQ(r.summary.method, ModesMethod::kBlocks);
    const modes_phc::PhcRealCounts phc = modes_phc::phc_real_counts(r.polynomials.system);
    int real_singular = 0;
    for (const Endpoint& e : r.summary.endpoints)
      real_singular += e.kind == EndpointKind::kSingular && e.x.imag().cwiseAbs().maxCoeff() <= 1e-5;
    EXPECT_EQ(r.summary.real, phc.regular);
    EXPECT_EQ(real_singular, phc.singular);
    EXPECT_EQ(phc.singular, 1 + (coords[0] == 'n'));
    EXPECT_EQ(static_cast<int>(r.modes.size()) + r.rejected + r.merged, phc.regular + phc.singular);
  }
}

// Every scene of models/ of at most 20 coordinates (fitting a bigger one's rows alone takes a quarter second and
// more) whose whole system takes at most 64 paths: the block solve finds its modes (those it solves block by block
// among them: the natural four-bars, fourbar_m and fourbar_mm, a driven-torque four-bar).
TEST(ModesBlocks, ModelScenesAsTheWholeSystem) {
  std::vector<std::string> compared, in_blocks;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(PHIQ_MODELS_DIR)) {
    if (entry.path().extension() != ".yaml") continue;
    std::optional<Scene> scene;
    try {
      scene = load_scene(entry.path().string());
    } catch (const std::exception&) {
      continue;  // not a scene (an include, a bad-input example)
    }
    if (scene->model->num_coordinates() > 20) continue;
    ModesOptions o;
    o.time = scene->sweep.t_begin, o.max_paths = 64, o.block_solve = false;
    AssemblyModes whole;
    try {
      whole = find_assembly_modes(*scene->model, o);
    } catch (const std::exception&) {
      continue;
    }
    if (whole.summary.status != ModesStatus::kSuccess) continue;
    const std::string name = std::filesystem::relative(entry.path(), PHIQ_MODELS_DIR).string();
    SCOPED_TRACE(name);
    o.block_solve = true, o.max_paths = 100000;
    const AssemblyModes blocks = find_assembly_modes(*scene->model, o);
    modes_blocks_expect_same(*scene->model, blocks, whole);
    compared.push_back(name);
    if (blocks.summary.method == ModesMethod::kBlocks) in_blocks.push_back(name);
  }
  EXPECT_GE(compared.size(), 20u);
  for (const char* name : {"seed/fourbar_natural.yaml", "hard/fourbar_m.yaml", "hard/fourbar_mm.yaml"})
    EXPECT_NE(std::find(in_blocks.begin(), in_blocks.end(), name), in_blocks.end()) << name;
}

// The path limit of the block solve counts each block's paths as its solve takes them (degrees lowered), not its
// total degree. x² = 1, then for each x two circles (y − x)² + z² = 2 and y² + z² = 1 (total degree 4; their
// difference is linear, so lowered 2 paths): (x, y, z) = (±1, 0, ±1), in 2 + 2 · 2 = 6 paths (by total degrees 10).
TEST(ModesBlocks, PathLimitCountsEachBlocksLoweredPaths) {
  auto term = [](double c, std::vector<int> e) { return PolynomialTerm{c, std::move(e)}; };
  PolynomialSystem s{3, {"x", "y", "z"}, {}};
  s.equations.push_back({{term(1, {2, 0, 0}), term(-1, {0, 0, 0})}});
  s.equations.push_back(
      {{term(1, {0, 2, 0}), term(-2, {1, 1, 0}), term(1, {2, 0, 0}), term(1, {0, 0, 2}), term(-2, {0, 0, 0})}});
  s.equations.push_back({{term(1, {0, 2, 0}), term(1, {0, 0, 2}), term(-1, {0, 0, 0})}});
  ModesOptions o;
  o.max_paths = 6;
  ModesSummary out;
  std::string unsafe;
  ASSERT_TRUE(modes_detail::solve_in_blocks(s, {}, Eigen::VectorXd::Zero(3), o, out, unsafe)) << unsafe;
  EXPECT_EQ(out.paths, 6);
  EXPECT_EQ(out.total_degree, 10);
  EXPECT_EQ(out.start_system, "total degree, degrees lowered");
  ASSERT_EQ(out.real, 4);
  EXPECT_EQ(out.complex + out.singular + out.failed_paths, 0);
  for (const Endpoint& e : out.endpoints) {
    EXPECT_NEAR(std::abs(e.x(0).real()), 1.0, 1e-12);
    EXPECT_NEAR(e.x(1).real(), 0.0, 1e-12);
    EXPECT_NEAR(std::abs(e.x(2).real()), 1.0, 1e-12);
  }
  o.max_paths = 5;  // the second x's block would pass it
  EXPECT_FALSE(modes_detail::solve_in_blocks(s, {}, Eigen::VectorXd::Zero(3), o, out, unsafe));
  EXPECT_EQ(unsafe, "block 2 of 2 (2 unknowns): the blocks' paths pass the limit of 5");
}

}  // namespace
}  // namespace phiq
