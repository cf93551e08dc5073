// A phiq result against an `.asmt` file's TimeSeries (asmt_comparison(), `phiq compare RESULT FILE.asmt`):
// OndselSolver's samples (PHIQ_ASMT_SAMPLES, outside the repository; skipped, saying so, when absent) swept in
// process and compared quantity by quantity with what the file stores, and a bad comparison refused in one line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "cli_test_support.hpp"
#include "phiq/csv_compare.hpp"
#include "phiq/import_asmt.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

std::string AsmtCompareSample(const std::string& name) { return std::string(PHIQ_ASMT_SAMPLES) + "/" + name; }
#define PHIQ_NEED_ASMT_COMPARE_SAMPLES()                                               \
  if (!std::filesystem::exists(AsmtCompareSample("Gears.asmt")))                       \
  GTEST_SKIP() << "OndselSolver's sample .asmt files are not at " << PHIQ_ASMT_SAMPLES \
               << " (../shared/asmt beside the clone; cmake -DPHIQ_ASMT_SAMPLES=DIR)"

// The sample swept as `phiq run` sweeps it (prepared, tolerance 1e-13), as the table of a result with dotted
// names: t, every coordinate, and with `rates` their .v and .a columns.
CsvTable AsmtCompareResult(const std::string& path, bool rates) {
  Scene scene = load_scene(path);
  scene.sweep.velocities = scene.sweep.accelerations = rates;
  scene.sweep.newton.tolerance = scene.sweep.assembly.tolerance = 1e-13;
  SquareScene square;
  EXPECT_EQ(prepare_scene(*scene.model, scene.sweep.t_begin, scene.sweep.assembly, &square), SolveStatus::kSuccess);
  const Model& m = square.model(*scene.model);
  Workspace ws(m);
  ws.q = square.start;
  test::Trace trace;
  EXPECT_EQ(test::sweep(m, scene.sweep, &trace, nullptr, &ws), SolveStatus::kSuccess);
  CsvTable t;
  t.path = "result.csv";
  t.columns = {"t"};
  const std::vector<std::string>& names = scene.model->coordinate_names();
  for (const char* rate : {"", ".v", ".a"}) {
    if (*rate && !rates) break;
    for (const std::string& n : names) t.columns.push_back(n + rate);
  }
  for (std::size_t k = 0; k < trace.t.size(); ++k) {
    std::vector<double> row = {trace.t[k]};
    for (const auto* v : {&trace.q, &trace.qd, &trace.qdd}) {
      if (v != &trace.q && !rates) break;
      row.insert(row.end(), (*v)[k].data(), (*v)[k].data() + (*v)[k].size());
    }
    t.rows.push_back(std::move(row));
  }
  return t;
}

// The columns of a comparison beyond `options`, by name, with their mismatches.
std::map<std::string, std::size_t> AsmtCompareFailing(const AsmtComparison& c, const CompareOptions& options) {
  const CompareResult r = compare_csv(c.result, c.series, options);
  std::map<std::string, std::size_t> failing;
  for (const ColumnComparison& col : r.per_column)
    if (col.mismatches) failing[col.column] = col.mismatches;
  EXPECT_TRUE(r.only_in_a.empty() && r.only_in_b.empty());
  EXPECT_EQ(r.rows_a, r.rows_b);
  return failing;
}

// Gears.asmt: positions within the stored 14 digits, Bryant angles and velocities within 1e-9; the one column that
// differs is Part2's Bryantz, by π at each of the 101 times (phiq keeps the file's placement of gear 2, turned by π,
// which OndselSolver's first output drops: test_import_asmt.cpp, GearsFollowTheirTimeSeries).
TEST(AsmtCompare, GearsAgreeWithTheirTimeSeriesButForGearTwosHalfTurn) {
  PHIQ_NEED_ASMT_COMPARE_SAMPLES();
  const std::string path = AsmtCompareSample("Gears.asmt");
  const AsmtComparison c = asmt_comparison(AsmtCompareResult(path, true), path);
  EXPECT_TRUE(c.left_out.empty());
  ASSERT_EQ(c.series.columns.size(), 1u + 2 * 18);  // t, and 18 quantities of each of the 2 parts
  EXPECT_EQ(c.series.columns[1], "Part1.X");
  EXPECT_EQ(c.series.columns[36], "Part2.AlphaZ");
  ASSERT_EQ(c.series.rows.size(), 101u);
  const std::map<std::string, std::size_t> failing = AsmtCompareFailing(c, {0.0, 1e-9, {}});
  ASSERT_EQ(failing.size(), 1u);
  EXPECT_EQ(failing.begin()->first, "Part2.Bryantz");
  EXPECT_EQ(failing.begin()->second, 101u);
  const std::size_t z = 1 + 18 + 5;
  ASSERT_EQ(c.result.columns[z], "Part2.Bryantz");
  for (std::size_t k = 0; k < 101; ++k) {
    const double d = std::remainder(c.result.rows[k][z] - c.series.rows[k][z], 2 * std::numbers::pi);
    EXPECT_NEAR(std::abs(d), std::numbers::pi, 1e-11) << "t = " << c.series.rows[k][0];
  }
  // positions alone within the stored digits
  CompareOptions positions{1e-11, 1e-11, {}};
  for (const char* q : {"X", "Y", "Z"})
    for (const char* part : {"Part1.", "Part2."}) positions.columns.push_back(std::string(part) + q);
  EXPECT_TRUE(compare_csv(c.result, c.series, positions).equal);
}

// parm.asmt: positions and Bryant angles within the stored digits; its stored velocities are 0 (README of the
// samples), so each part's turning ones differ; a result without rates leaves them out, saying so.
TEST(AsmtCompare, ParallelogramPositionsAgreeItsZeroVelocitiesDoNot) {
  PHIQ_NEED_ASMT_COMPARE_SAMPLES();
  const std::string path = AsmtCompareSample("parm.asmt");
  const AsmtComparison positions = asmt_comparison(AsmtCompareResult(path, false), path);
  ASSERT_EQ(positions.left_out.size(), 2u);
  EXPECT_EQ(positions.left_out[0],
            "velocities (VX ... OmegaZ): result.csv has none (a scene whose output has `velocities: true`)");
  EXPECT_EQ(positions.series.columns.size(), 1u + 4 * 6);
  EXPECT_TRUE(AsmtCompareFailing(positions, {1e-11, 1e-11, {}}).empty());
  const AsmtComparison rates = asmt_comparison(AsmtCompareResult(path, true), path);
  EXPECT_TRUE(rates.left_out.empty());
  const std::map<std::string, std::size_t> failing = AsmtCompareFailing(rates, {1e-9, 1e-9, {}});
  EXPECT_EQ(failing.count("Part1.OmegaZ"), 0u);  // the fixed ground link: 0 as stored
  EXPECT_EQ(failing.count("Part2.X"), 0u);
  EXPECT_GT(failing.count("Part2.OmegaZ"), 0u);
  for (const auto& [column, mismatches] : failing)
    EXPECT_TRUE(column.find(".V") != std::string::npos || column.find(".Omega") != std::string::npos ||
                column.find(".A") != std::string::npos)
        << column << ": " << mismatches;
}

TEST(AsmtCompare, RefusesAResultOfAnotherModelAndAFileWithoutTimeSeries) {
  PHIQ_NEED_ASMT_COMPARE_SAMPLES();
  CsvTable other{"other.csv", {"t", "Part1_x"}, {{0.0, 1.0}}};
  try {
    asmt_comparison(other, AsmtCompareSample("Gears.asmt"));
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "other.csv: no column 'Part1_y' for part 'Part1' of " +
                                         AsmtCompareSample("Gears.asmt") +
                                         " (compare a result of `phiq run` of that file)");
  }
  const std::string plain = AsmtCompareSample("rackPinion.asmt");
  try {
    asmt_comparison(other, plain);
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()),
              plain + ": no TimeSeries of parts to compare with (OndselSolver stores one after a run)");
  }
}

}  // namespace

namespace test {

// The command: a run of the file against it, exit 1 naming the differing column; the reports' counts.
TEST_F(Cli, CompareAResultWithAnAsmtTimeSeries) {
  PHIQ_NEED_ASMT_COMPARE_SAMPLES();
  const std::string gears = AsmtCompareSample("Gears.asmt"), csv = (dir_ / "g.csv").string();
  ASSERT_EQ(run("run -q " + gears + " -o " + csv).code, 0);
  const Result r = run("compare " + csv + " " + gears + " --rtol 0 --atol 1e-9 --json=" + (dir_ / "c.json").string());
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("phiq: compare: not compared: velocities (VX ... OmegaZ): " + csv + " has none"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("differ: 101 cells beyond tolerance; worst Part2.Bryantz"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Part2.Bryantz"), std::string::npos) << r.err;
  const Result both = run("compare " + gears + " " + gears);
  EXPECT_EQ(both.code, 2);
  EXPECT_EQ(both.err, "phiq: compare: " + gears + ", " + gears + ": two .asmt files; one must be a result\n");
}

}  // namespace test
}  // namespace phiq
