// `phiq tolerance`: the first-order spread of the crank-slider's slider against its closed form (normal, ± limit and
// correlated parameters), the Monte Carlo spread within its standard error of it, reproducible samples, a four-bar
// whose tolerance makes cases fail to assemble (counted, named, disagreeing), a parameter nothing reads (reported),
// and bad input refused.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>

#include "phiq/csv_compare.hpp"
#include "tolerance_input.hpp"

#include "cli_test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::one_phiq_line;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

const std::string kCrankSlider = std::string(PHIQ_MODELS_DIR) + "/seed/crank_slider_mixed.yaml";
const std::string kFourbar = std::string(PHIQ_MODELS_DIR) + "/seed/fourbar_natural.yaml";

// ∂xB/∂L2 and ∂xB/∂L3 of xB = L2 cos θ + √(L3² − L2² sin²θ), θ = 2t (L2 = 0.3, L3 = 1).
struct Gradient {
  double l2, l3;
};
Gradient slider_gradient(double t) {
  const double L2 = 0.3, L3 = 1.0, s = std::sin(2 * t), w = std::sqrt(L3 * L3 - L2 * L2 * s * s);
  return {std::cos(2 * t) - L2 * s * s / w, L3 / w};
}

double column(const phiq::CsvTable& table, std::size_t row, const std::string& name) {
  const auto it = std::find(table.columns.begin(), table.columns.end(), name);
  EXPECT_NE(it, table.columns.end()) << name;
  return it == table.columns.end() ? NAN : table.rows[row][static_cast<std::size_t>(it - table.columns.begin())];
}

// The Monte Carlo spread of `y` within `k` standard errors (σ_lin / √(2(N − 1))) of the linear one at every row.
void expect_agreement(const phiq::CsvTable& table, const std::string& y, long samples, double k) {
  const double root = std::sqrt(2.0 * static_cast<double>(samples - 1));
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    const double lin = column(table, r, y + ".sd_linear"), mc = column(table, r, y + ".sd_mc");
    if (lin <= 1e-9 && mc <= 1e-9) continue;  // no spread (the slider's velocity at a dead point): nothing to compare
    ASSERT_LE(std::fabs(mc - lin), k * lin / root) << y << " row " << r;
  }
}

// The slider's first-order spread is the closed form's, and the samples' spread agrees with it everywhere.
TEST_F(Cli, ToleranceLinearSpreadIsTheClosedFormAndMonteCarloAgrees) {
  const fs::path out = dir_ / "tol.csv", summary = dir_ / "tol.json", svg = dir_ / "tol.svg";
  const Result r = run("tolerance " + kCrankSlider + " --sd L2=0.001 --sd L3=0.002 --columns xB,xB.v -o " +
                       out.string() + " --summary " + summary.string() + " --plot " + svg.string() + " -q");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");  // nothing fails, nothing disagrees
  const phiq::CsvTable table = phiq::read_csv_table(out.string());
  EXPECT_EQ(table.columns, (std::vector<std::string>{"t", "xB", "xB.sd_linear", "xB.sd_mc", "xB.mean_mc", "xB.v",
                                                     "xB.v.sd_linear", "xB.v.sd_mc", "xB.v.mean_mc"}));
  ASSERT_EQ(table.rows.size(), 181u);
  for (std::size_t row = 0; row < table.rows.size(); ++row) {
    const double t = table.rows[row][0];
    const Gradient g = slider_gradient(t);
    const double closed = std::hypot(g.l2 * 0.001, g.l3 * 0.002);
    EXPECT_NEAR(column(table, row, "xB.sd_linear"), closed, 1e-9 * closed) << "t = " << t;
    const double L2 = 0.3, s = std::sin(2 * t);
    EXPECT_NEAR(column(table, row, "xB"), L2 * std::cos(2 * t) + std::sqrt(1 - L2 * L2 * s * s), 1e-9);
  }
  expect_agreement(table, "xB", 1000, 4.0);
  expect_agreement(table, "xB.v", 1000, 4.0);
  const auto j = nlohmann::json::parse(slurp(summary));
  EXPECT_EQ(j["format"], 1);
  EXPECT_EQ(j["samples"], 1000);
  EXPECT_EQ(j["succeeded"], 1000);
  EXPECT_EQ(j["failed"].size(), 0u);
  EXPECT_EQ(j["disagreeing"], 0);
  EXPECT_EQ(j["sensitivity_form"], "adjoint");  // two parameters with q̇, one output: the adjoint costs less
  EXPECT_EQ(j["parameters"][0]["name"], "L2");
  EXPECT_DOUBLE_EQ(j["parameters"][0]["nominal"].get<double>(), 0.3);
  EXPECT_DOUBLE_EQ(j["covariance"][1][1].get<double>(), 4e-6);
  for (const auto& o : j["outputs"]) EXPECT_LE(o["worst_standard_errors"].get<double>(), 4.0);
  EXPECT_EQ(j["outputs"][0]["rows_compared"], 181);  // xB spreads everywhere (xB.v not at the dead points)
  const std::string picture = slurp(svg);
  EXPECT_EQ(phiq::test::count(picture, "class=\"band-linear\""), 1u);
  EXPECT_EQ(phiq::test::count(picture, "class=\"band-mc\""), 2u);
  EXPECT_EQ(phiq::test::count(picture, "data-column=\"xB\""), 1u);
}

// --set moves the nominal point: with L3 = 1.1 the nominal slider and its first-order spread to L2 are the closed
// form's at those lengths, and the samples (L2 drawn, L3 kept at 1.1) agree with it; --set of the toleranced L2
// is its nominal value, about which it is sampled.
TEST_F(Cli, ToleranceSetMovesTheNominalPoint) {
  const fs::path out = dir_ / "tol.csv", summary = dir_ / "tol.json";
  const Result r = run("tolerance " + kCrankSlider + " --sd L2=0.001 --set L3=1.1 --set L2=0.25 --columns xB -o " +
                       out.string() + " --summary " + summary.string() + " --samples 400 -q");
  ASSERT_EQ(r.code, 0) << r.err;
  const phiq::CsvTable table = phiq::read_csv_table(out.string());
  ASSERT_EQ(table.rows.size(), 181u);
  const double L2 = 0.25, L3 = 1.1;
  for (std::size_t row = 0; row < table.rows.size(); ++row) {
    const double t = table.rows[row][0], s = std::sin(2 * t), w = std::sqrt(L3 * L3 - L2 * L2 * s * s);
    EXPECT_NEAR(column(table, row, "xB"), L2 * std::cos(2 * t) + w, 1e-9) << "t = " << t;
    const double dl2 = std::fabs(std::cos(2 * t) - L2 * s * s / w) * 0.001;
    EXPECT_NEAR(column(table, row, "xB.sd_linear"), dl2, 1e-12) << "t = " << t;  // 1e-9 of 0.001 × O(1)
  }
  expect_agreement(table, "xB", 400, 4.0);
  const auto j = nlohmann::json::parse(slurp(summary));
  EXPECT_DOUBLE_EQ(j["parameters"][0]["nominal"].get<double>(), 0.25);
}

// A ± limit is uniform on [p − l, p + l]: its standard deviation l/√3 is what the linear spread uses.
TEST_F(Cli, ToleranceLimitIsUniformWithSdLimitOverRootThree) {
  const fs::path out = dir_ / "tol.csv";
  const Result r = run("tolerance " + kCrankSlider +
                       " --limit L2=0.003 --columns xB --samples 2000 --names "
                       "identifiers -q -o " +
                       out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const phiq::CsvTable table = phiq::read_csv_table(out.string());
  EXPECT_EQ(table.columns, (std::vector<std::string>{"t", "xB", "xB__sd_linear", "xB__sd_mc", "xB__mean_mc"}));
  for (std::size_t row = 0; row < table.rows.size(); ++row) {
    const double closed = std::fabs(slider_gradient(table.rows[row][0]).l2) * 0.003 / std::sqrt(3.0);
    EXPECT_NEAR(column(table, row, "xB__sd_linear"), closed, 1e-9 * closed + 1e-15);
  }
  // (rows where ∂xB/∂L2 vanishes have no spread to compare: the check skips them through σ_lin ≈ 0)
  const double root = std::sqrt(2.0 * 1999);
  for (std::size_t row = 0; row < table.rows.size(); ++row) {
    const double lin = column(table, row, "xB__sd_linear"), mc = column(table, row, "xB__sd_mc");
    if (lin > 1e-9) {
      EXPECT_LE(std::fabs(mc - lin), 4 * lin / root) << "row " << row;
    }
  }
}

// Correlated parameters: σ_lin = sqrt(gᵀ Σ g) with Σ from the file, checked by hand at one row; the samples'
// spread agrees with it, so they are correlated as Σ says (ρ = 0.6 changes σ by far more than the error).
TEST_F(Cli, ToleranceCovarianceGivesSqrtGSigmaG) {
  const double s2 = 0.001, s3 = 0.002, rho = 0.6;
  const fs::path cov = write("cov.csv", "L2,L3\n1e-06,1.2e-06\n1.2e-06,4e-06\n");
  const fs::path out = dir_ / "tol.csv";
  const Result r =
      run("tolerance " + kCrankSlider + " --covariance " + cov.string() + " --columns xB -q -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const phiq::CsvTable table = phiq::read_csv_table(out.string());
  const std::size_t row = 30;  // t = π/6: θ = π/3
  const Gradient g = slider_gradient(table.rows[row][0]);
  const double by_hand = std::sqrt(g.l2 * g.l2 * s2 * s2 + 2 * rho * g.l2 * g.l3 * s2 * s3 + g.l3 * g.l3 * s3 * s3);
  EXPECT_NEAR(column(table, row, "xB.sd_linear"), by_hand, 1e-9 * by_hand);
  // uncorrelated would be visibly different here
  EXPECT_GT(std::fabs(by_hand - std::hypot(g.l2 * s2, g.l3 * s3)), 0.05 * by_hand);
  expect_agreement(table, "xB", 1000, 4.0);
}

// The same seed gives the same bytes (on any number of threads), another seed other bytes.
TEST_F(Cli, ToleranceSamplesAreReproducible) {
  auto once = [&](const std::string& name, const std::string& extra) {
    const fs::path out = dir_ / name;
    const Result r = run("tolerance " + kCrankSlider + " --sd L2=0.001 --limit L3=0.002 --samples 60 -q -o " +
                         out.string() + " " + extra);
    EXPECT_EQ(r.code, 0) << r.err;
    return slurp(out);
  };
  const std::string a = once("a.csv", "--seed 7 --threads 1"), b = once("b.csv", "--seed 7 --threads 2");
  const std::string c = once("c.csv", "--seed 8");
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  // the library's samples: the same for the same seed, the uniform parameter within its limit, the normal one
  // beyond 1.96 σ in 5 % of the cases (Box–Muller's tails: 50 of 1000 expected, binomial sd 7; within 4 of them)
  phiq::tolerance::Tolerance l2, l3;
  l2.name = "L2", l2.spread = 0.001;
  l3.name = "L3", l3.spread = 0.002, l3.distribution = phiq::tolerance::Distribution::kUniform;
  const auto spread = phiq::tolerance::parameter_spread({l2, l3}, nullptr);
  const Eigen::MatrixXd d = phiq::tolerance::sample_offsets(spread, 1000, 7);
  EXPECT_EQ(d, phiq::tolerance::sample_offsets(spread, 1000, 7));
  EXPECT_NE(d, phiq::tolerance::sample_offsets(spread, 1000, 8));
  EXPECT_LE(d.col(1).cwiseAbs().maxCoeff(), 0.002);
  const long tails = (d.col(0).array().abs() > 1.96 * 0.001).count();
  EXPECT_GE(tails, 50 - 4 * 7);
  EXPECT_LE(tails, 50 + 4 * 7);
}

// A four-bar whose ground length L1 below 0.6 lets the crank (0.4) not turn: those sampled cases fail to assemble
// or to pass the dead point, counted and named with their values; near the dead points the first-order model fails
// and the spreads disagree.
TEST_F(Cli, ToleranceNamesFailedCasesAndReportsDisagreementNearSingularPositions) {
  const fs::path out = dir_ / "tol.csv", summary = dir_ / "tol.json";
  const long samples = 300;
  const Result r = run("tolerance " + kFourbar + " --sd L1=0.25 --samples " + std::to_string(samples) +
                       " --columns xB,yB -o " + out.string() + " --summary " + summary.string());
  ASSERT_EQ(r.code, 0) << r.err;  // a report, not an error
  const auto j = nlohmann::json::parse(slurp(summary));
  // the cases that fail are those with L1 < 0.6 (crank 0.4 + 0.2 ≥ L1: not a crank-rocker), up to the ones so near
  // that the sweep passes the dead point within its tolerance
  phiq::tolerance::Tolerance l1;
  l1.name = "L1", l1.spread = 0.25;
  const Eigen::MatrixXd d =
      phiq::tolerance::sample_offsets(phiq::tolerance::parameter_spread({l1}, nullptr), samples, 1);
  std::set<long> failed, expected;
  for (const auto& f : j["failed"]) {
    failed.insert(f["case"].get<long>());
    const double value = f["parameters"]["L1"].get<double>();
    EXPECT_DOUBLE_EQ(value, 1.0 + d(f["case"].get<long>(), 0));
    EXPECT_LT(value, 0.6 + 1e-3) << f["message"];
    EXPECT_NE(r.err.find("case " + std::to_string(f["case"].get<long>()) + " (L1 = "), std::string::npos) << r.err;
  }
  for (long k = 0; k < samples; ++k)
    if (1.0 + d(k, 0) < 0.6 - 1e-3) expected.insert(k);
  EXPECT_FALSE(expected.empty());
  for (long k : expected) EXPECT_TRUE(failed.count(k)) << "case " << k << " with L1 = " << 1.0 + d(k, 0);
  EXPECT_EQ(j["succeeded"].get<long>(), samples - static_cast<long>(failed.size()));
  EXPECT_NE(r.err.find(std::to_string(failed.size()) + " of " + std::to_string(samples) + " sampled cases failed"),
            std::string::npos)
      << r.err;
  EXPECT_GE(j["disagreeing"].get<int>(), 1);
  EXPECT_NE(r.err.find("disagree"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("singular position"), std::string::npos) << r.err;
}

// A parameter nothing reads: its sensitivities are zero at every row, which is reported (stderr, summary), not an
// error; the spread is the other parameter's alone.
TEST_F(Cli, ToleranceReportsAParameterNoOutputDependsOn) {
  std::string text = slurp(kCrankSlider);
  const std::string l3 = "  L3: 1.0     # m\n";
  ASSERT_NE(text.find(l3), std::string::npos);
  text.replace(text.find(l3), l3.size(), l3 + "  spare: 2.0\n");
  const fs::path scene = write("spare.yaml", text), out = dir_ / "tol.csv", summary = dir_ / "tol.json";
  const Result r = run("tolerance " + scene.string() + " --sd spare=0.1 --sd L3=0.002 --columns xB --samples 100 -o " +
                       out.string() + " --summary " + summary.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("note: no output depends on spare (its sensitivities are zero at every row)"), std::string::npos)
      << r.err;
  const auto j = nlohmann::json::parse(slurp(summary));
  EXPECT_EQ(j["parameters"][0]["name"], "spare");
  EXPECT_EQ(j["parameters"][0]["independent"], true);
  EXPECT_EQ(j["parameters"][1]["independent"], false);
  const phiq::CsvTable table = phiq::read_csv_table(out.string());
  for (std::size_t row = 0; row < table.rows.size(); ++row) {
    const double closed = std::fabs(slider_gradient(table.rows[row][0]).l3) * 0.002;
    EXPECT_NEAR(column(table, row, "xB.sd_linear"), closed, 1e-9 * closed);
  }
}

// Positions only, two parameters and one output (`--columns xB`, whatever the scene writes): the nominal sweep
// solves the sensitivities in the adjoint form (one solve a row), and the linear spread is the closed form's.
TEST_F(Cli, ToleranceTakesTheAdjointFormForFewOutputs) {
  std::string text = slurp(kCrankSlider);
  const std::string outputs = "output: {velocities: true, accelerations: true}";
  ASSERT_NE(text.find(outputs), std::string::npos);
  text.replace(text.find(outputs), outputs.size(), "output: {velocities: false, accelerations: false}");
  const fs::path scene = write("positions.yaml", text), out = dir_ / "tol.csv", summary = dir_ / "tol.json";
  const Result r = run("tolerance " + scene.string() + " --sd L2=0.001 --sd L3=0.002 --columns xB --samples 50 -q -o " +
                       out.string() + " --summary " + summary.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(summary))["sensitivity_form"], "adjoint");
  const phiq::CsvTable table = phiq::read_csv_table(out.string());
  ASSERT_EQ(table.rows.size(), 181u);
  for (std::size_t row = 0; row < table.rows.size(); ++row) {
    const Gradient g = slider_gradient(table.rows[row][0]);
    const double closed = std::hypot(g.l2 * 0.001, g.l3 * 0.002);
    EXPECT_NEAR(column(table, row, "xB.sd_linear"), closed, 1e-9 * closed) << "t = " << table.rows[row][0];
  }
}

// Bad input: one line, exit 2, no output file.
TEST_F(Cli, ToleranceRefusesBadInput) {
  const fs::path cov = write("cov.csv", "L2,L3\n1e-06,3e-06\n3e-06,4e-06\n");  // ρ = 1.5
  const fs::path asym = write("asym.csv", "L2,L3\n1e-06,1e-07\n2e-07,4e-06\n");
  const std::string out = " -o " + (dir_ / "out.csv").string();
  struct Case {
    std::string args, says;
  };
  const std::vector<Case> cases{
      {"--sd foo=0.1", "'foo' is not a parameter of"},
      {"--sd L2=-0.001", "the standard deviation must be positive"},
      {"--limit L2=0", "the limit must be positive"},
      {"--sd L2", "expected NAME=VALUE"},
      {"--covariance " + cov.string(), "not positive definite"},
      {"--covariance " + asym.string(), "not symmetric"},
      {"--sd L2=0.001 --columns nope", "'nope' is not an output of"},
      {"--sd L2=0.001 --sd L2=0.002", "L2 is given more than once"},
      {"", "no toleranced parameter"},
  };
  for (const Case& c : cases) {
    const Result r = run("tolerance " + kCrankSlider + " " + c.args + out);
    EXPECT_EQ(r.code, 2) << c.args << ": " << r.err;
    EXPECT_TRUE(one_phiq_line(r.err)) << c.args;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << ": " << r.err;
    if (c.args.find("--covariance") != std::string::npos) {
      EXPECT_NE(r.err.find(c.args.substr(13)), std::string::npos) << "names the file: " << r.err;
    }
    EXPECT_FALSE(fs::exists(dir_ / "out.csv")) << c.args;
  }
  EXPECT_EQ(files(), (std::vector<std::string>{"asym.csv", "cov.csv", "stderr.txt", "stdout.txt"}));
}

}  // namespace
