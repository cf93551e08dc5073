// phiq's assembly modes side by side with PHCpack (`phc -b`, Debian's phcpack) on the same polynomial systems
// (phc_input_text()): the same number of finite regular solutions, of real ones, and the same real solutions.
// Skipped, with the reason, when phc is not installed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "modes_phc.hpp"
#include "phiq/phiq.hpp"

namespace phiq {
namespace {

using modes_phc::modes_expect_same_as_phc;
using modes_phc::phc_installed;

std::string modes_phc_models(const std::string& rel) {
  std::string path = PHIQ_MODELS_DIR;
  path += '/';
  path += rel;
  return path;
}

TEST(ModesPhc, IntegerSystemAsPhcSolvesIt) {
  if (!phc_installed()) GTEST_SKIP() << "phc (Debian package phcpack) is not installed";
  Polynomial a, b;
  a.terms = {{2.0, {0, 0}}, {-3.0, {1, 0}}, {1.0, {2, 0}}};
  b.terms = {{-3.0, {0, 0}}, {-2.0, {0, 1}}, {1.0, {0, 2}}};
  const PolynomialSystem s{2, {}, {a, b}};
  const ModesSummary ours = solve_polynomial_system(s, {});
  ASSERT_EQ(ours.real, 4);
  modes_expect_same_as_phc(s, ours);
}

TEST(ModesPhc, FourBarAndCrankSliderAsPhcSolvesThem) {
  if (!phc_installed()) GTEST_SKIP() << "phc (Debian package phcpack) is not installed";
  for (const char* rel : {"seed/fourbar_mixed.yaml", "seed/crank_slider_mixed.yaml", "seed/fourbar_natural.yaml"}) {
    SCOPED_TRACE(rel);
    const Scene scene = load_scene(modes_phc_models(rel));
    ModesOptions o;
    o.time = 0.9;
    const AssemblyModes r = find_assembly_modes(*scene.model, o);
    ASSERT_EQ(r.summary.status, ModesStatus::kSuccess) << r.summary.message;
    modes_expect_same_as_phc(r.polynomials.system, r.summary);
  }
}

TEST(ModesPhc, ThreeRprAsPhcSolvesIt) {
  if (!phc_installed()) GTEST_SKIP() << "phc (Debian package phcpack) is not installed";
  const Scene scene = load_scene(modes_phc_models("benchmarks/rpr3.yaml"));
  const AssemblyModes r = find_assembly_modes(*scene.model, {});
  ASSERT_EQ(r.summary.status, ModesStatus::kSuccess) << r.summary.message;
  modes_expect_same_as_phc(r.polynomials.system, r.summary);
}

}  // namespace
}  // namespace phiq
