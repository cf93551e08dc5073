// A phiq result against an `.asmt` file's TimeSeries (asmt_comparison(), `phiq compare RESULT FILE.asmt`):
// OndselSolver's samples (PHIQ_ASMT_SAMPLES, outside the repository; skipped, saying so, when absent) swept in
// process and compared quantity by quantity with what the file stores, and a bad comparison refused in one line.
// Joint and motion forces: a massive pendulum under gravity (tests/data/asmt/pendulum.asmt given a centre of mass,
// gravity and a varying speed) with a TimeSeries written here from its closed form in OndselSolver's conventions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <sstream>
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

// Sweeps `scene` as `phiq run` does (prepared, tolerance 1e-13): `sweep_it(model, workspace)` on its square model,
// the workspace at its start.
template <class Sweep>
void AsmtCompareSweep(Scene& scene, Sweep sweep_it) {
  scene.sweep.newton.tolerance = scene.sweep.assembly.tolerance = 1e-13;
  SquareScene square;
  EXPECT_EQ(prepare_scene(*scene.model, scene.sweep.t_begin, scene.sweep.assembly, &square), SolveStatus::kSuccess);
  const Model& m = square.model(*scene.model);
  Workspace ws(m);
  ws.q = square.start;
  sweep_it(m, ws);
}

// The sample swept as `phiq run` sweeps it, as the table of a result with dotted names: t, every coordinate, and
// with `rates` their .v and .a columns.
CsvTable AsmtCompareResult(const std::string& path, bool rates) {
  Scene scene = load_scene(path);
  scene.sweep.velocities = scene.sweep.accelerations = rates;
  test::Trace trace;
  AsmtCompareSweep(scene, [&](const Model& m, Workspace& ws) {
    EXPECT_EQ(test::sweep(m, scene.sweep, &trace, nullptr, &ws), SolveStatus::kSuccess);
  });
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

// The scene of an .asmt text with `--rates --forces` swept as `phiq run` sweeps it, as the table its CSV holds.
CsvTable AsmtCompareForcesResult(const std::string& text, const std::string& path) {
  ImportOptions options;
  options.rates = options.forces = true;
  Scene scene = parse_scene(import_asmt(text, path, options).yaml, path);
  std::string csv;
  AsmtCompareSweep(scene, [&](const Model& m, Workspace& ws) {
    const CsvFormat format(m, scene.sweep);
    csv = format.header();
    EXPECT_EQ(run_sweep(
                  m, scene.sweep, ws, [&](const StepView& v) { return format.append_row(v, csv), true; }, nullptr),
              SolveStatus::kSuccess);
  });
  return parse_csv_table(csv, "result.csv");
}

// tests/data/asmt/pendulum.asmt made massive: the arm (mass 1, Izz 2 about its centre) has its centre at (1, 0, 0),
// gravity is (0, -9.81, 0) and the motor turns J about I's z by φ(t) = 0.5 t + 0.3 sin 2t; `swapped` exchanges the
// hinge's markers (I on the arm, the arm's angle −φ). Its TimeSeries holds the closed form, 14 digits as OndselSolver
// writes: the arm's place and rates, then per joint and motion the force on marker I's part and the moment about
// marker I's origin, world axes (OndselSolver's ASMTConstraintSet::updateFromMbD: aFImO, aTImO). With the arm's
// angle θ, its centre c = (cos θ, sin θ, 0): the hinge pushes the arm with m c̈ − m g, the motor turns it with
// I_O θ̈ − (c × m g)_z = 3 θ̈ + 9.81 cos θ; on the ground the opposite.
std::string AsmtCompareMassivePendulum(bool swapped) {
  std::string text = test::file_text(std::string(PHIQ_SOURCE_DIR) + "/tests/data/asmt/pendulum.asmt");
  const auto replace = [&](const std::string& from, const std::string& to) {
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
  };
  replace("\t\t\t\tPosition3D\n\t\t\t\t\t0.0\t0.0\t0.0\t", "\t\t\t\tPosition3D\n\t\t\t\t\t1.0\t0.0\t0.0\t");
  replace("ConstantGravity\n\t\t0.0\t0.0\t0.0", "ConstantGravity\n\t\t0.0\t-9.81\t0.0");
  replace("0.5*time", "0.5*time + 0.3*sin(2*time)");
  if (swapped) {
    replace("/Pendulum/Pivot\n", "/Pendulum/ArmPivotTmp\n");
    replace("/Pendulum/Arm/Pivot\n", "/Pendulum/Pivot\n");
    replace("/Pendulum/ArmPivotTmp\n", "/Pendulum/Arm/Pivot\n");
  }
  const int n = 17;  // t 0..4 step 0.25
  std::ostringstream ts;
  const auto row = [&](const std::string& label, const std::function<double(double)>& f) {
    ts << label << "\t0";
    for (int k = 0; k < n; ++k) {
      char v[32];
      std::snprintf(v, sizeof v, "%.14g", f(0.25 * k));
      ts << "\t" << v;
    }
    ts << "\n";
  };
  const double sign = swapped ? -1.0 : 1.0;  // the arm's angle is sign·φ
  const auto th = [&](double t) { return sign * (0.5 * t + 0.3 * std::sin(2 * t)); };
  const auto w = [&](double t) { return sign * (0.5 + 0.6 * std::cos(2 * t)); };
  const auto al = [&](double t) { return sign * (-1.2 * std::sin(2 * t)); };
  const auto zero = [](double) { return 0.0; };
  const std::function<double(double)> hinge[3] = {
      // on the arm
      [&](double t) { return -std::sin(th(t)) * al(t) - std::cos(th(t)) * w(t) * w(t); },
      [&](double t) { return std::cos(th(t)) * al(t) - std::sin(th(t)) * w(t) * w(t) + 9.81; }, zero};
  const auto motor = [&](double t) { return 3 * al(t) + 9.81 * std::cos(th(t)); };  // on the arm
  const double on_i = swapped ? 1.0 : -1.0;  // marker I: on the arm, or on the ground
  ts << "TimeSeries\nNumber\tInput";
  for (int k = 1; k <= n; ++k) ts << "\t" << k;
  row("\nTime", [](double t) { return t; });
  ts << "PartSeries /Pendulum/Arm\n";
  for (const char* q : {"X", "Y", "Z", "Bryantx", "Bryanty"}) row(q, zero);
  row("Bryantz", th);
  for (const char* q : {"VX", "VY", "VZ", "OmegaX", "OmegaY"}) row(q, zero);
  row("OmegaZ", w);
  for (const char* q : {"AX", "AY", "AZ", "AlphaX", "AlphaY"}) row(q, zero);
  row("AlphaZ", al);
  ts << "RevoluteJointSeries\t/Pendulum/Hinge\n";
  for (int i = 0; i < 3; ++i) row(std::string("F") + "XYZ"[i] + "onI", [&](double t) { return on_i * hinge[i](t); });
  for (const char* q : {"TXonI", "TYonI", "TZonI"}) row(q, zero);
  ts << "RotationalMotionSeries\t/Pendulum/Motor\n";
  for (const char* q : {"FXonI", "FYonI", "FZonI", "TXonI", "TYonI"}) row(q, zero);
  row("TZonI", [&](double t) { return on_i * motor(t); });
  return text + ts.str();
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
  ASSERT_EQ(c.left_out.size(), 1u);  // its joints' and motion's stored forces: no part has mass
  EXPECT_EQ(c.left_out[0], "forces (FXonI ... TZonI): no part of " + path + " has mass: phiq computes no force for it");
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
  ASSERT_EQ(positions.left_out.size(), 3u);  // velocities, accelerations, forces (no part has mass)
  EXPECT_EQ(positions.left_out[0],
            "velocities (VX ... OmegaZ): result.csv has none (a scene whose output has `velocities: true`)");
  EXPECT_EQ(positions.series.columns.size(), 1u + 4 * 6);
  EXPECT_TRUE(AsmtCompareFailing(positions, {1e-11, 1e-11, {}}).empty());
  const AsmtComparison rates = asmt_comparison(AsmtCompareResult(path, true), path);
  EXPECT_EQ(rates.left_out.size(), 1u);
  const std::map<std::string, std::size_t> failing = AsmtCompareFailing(rates, {1e-9, 1e-9, {}});
  EXPECT_EQ(failing.count("Part1.OmegaZ"), 0u);  // the fixed ground link: 0 as stored
  EXPECT_EQ(failing.count("Part2.X"), 0u);
  EXPECT_GT(failing.count("Part2.OmegaZ"), 0u);
  for (const auto& [column, mismatches] : failing)
    EXPECT_TRUE(column.find(".V") != std::string::npos || column.find(".Omega") != std::string::npos ||
                column.find(".A") != std::string::npos)
        << column << ": " << mismatches;
}

// The hinge's reaction and the motor's effort, turned into OndselSolver's forces on marker I's part about marker I's
// origin, agree with the closed form with either marker on the ground; the stored force negated does not.
class AsmtCompareFiles : public test::TestFolder {};
TEST_F(AsmtCompareFiles, JointAndMotorForcesAgreeWithTheClosedFormOnEitherMarker) {
  for (const bool swapped : {false, true}) {
    SCOPED_TRACE(swapped ? "marker I on the arm" : "marker I on the ground");
    const std::string text = AsmtCompareMassivePendulum(swapped);
    const std::string path = write(swapped ? "swapped.asmt" : "pendulum.asmt", text).string();
    const AsmtComparison c = asmt_comparison(AsmtCompareForcesResult(text, path), path);
    EXPECT_TRUE(c.left_out.empty()) << c.left_out.front();
    ASSERT_EQ(c.series.columns.size(), 1u + 18 + 2 * 6);
    EXPECT_EQ(c.series.columns[19], "Hinge.FXonI");
    EXPECT_EQ(c.series.columns[30], "Motor.TZonI");
    EXPECT_TRUE(AsmtCompareFailing(c, {1e-10, 1e-10, {}}).empty());
    // the forces are not zero (gravity and the varying speed load both), and their sign is held
    double largest = 0.0;
    for (const auto& r : c.series.rows) largest = std::max({largest, std::abs(r[20]), std::abs(r[30])});
    EXPECT_GT(largest, 5.0);
    AsmtComparison flipped = c;
    for (auto& r : flipped.series.rows) r[20] = -r[20], r[30] = -r[30];
    const std::map<std::string, std::size_t> failing = AsmtCompareFailing(flipped, {1e-10, 1e-10, {}});
    EXPECT_EQ(failing.size(), 2u);
    EXPECT_EQ(failing.count("Hinge.FYonI") + failing.count("Motor.TZonI"), 2u);
  }
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
