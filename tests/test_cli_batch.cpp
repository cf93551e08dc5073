// `phiq batch`: one CSV per case against its closed form, a failing case alone, more cases than open files,
// redundant scenes on their independent rows, each case's own output points, and naming the case only for its
// own errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "phiq/csv_compare.hpp"

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::kFourbarOutputs;
using phiq::test::one_phiq_line;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

// phiq batch: one CSV per case, each the closed form of its own crank length; a case that cannot run writes
// nothing and makes the exit status 1, without stopping the others.
TEST_F(Cli, BatchSweepsEveryParameterSetInParallel) {
  const fs::path cases = write("cases.csv", "L2,L3\n0.2,1.0\n0.3,1.0\n0.4,1.2\n1.5,1.0\n");
  const fs::path out = dir_ / "out";
  Result r = run("batch " + phiq::test::model_path("seed/crank_slider_mixed.yaml") + " " + cases.string() + " -o " +
                 out.string() + " --threads 2");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("case 3: step "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("3 of 4 cases"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("4 cases on one symbolic analysis"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "case3.csv"));
  const double l2[] = {0.2, 0.3, 0.4}, l3[] = {1.0, 1.0, 1.2};
  for (int k = 0; k < 3; ++k) {
    const phiq::CsvTable t = phiq::read_csv_table((out / ("case" + std::to_string(k) + ".csv")).string());
    ASSERT_EQ(t.rows.size(), 181u);
    ASSERT_EQ(t.columns[1], "theta2");
    ASSERT_EQ(t.columns[4], "xB");
    double worst = 0;
    for (const auto& row : t.rows) {
      const double th = row[1], s = std::sin(th);
      worst = std::max(worst,
                       std::fabs(row[4] - (l2[k] * std::cos(th) + std::sqrt(l3[k] * l3[k] - l2[k] * l2[k] * s * s))));
    }
    EXPECT_LT(worst, 1e-9) << "case " << k;
  }
  // a column that is not a parameter of the scene: one line naming it at the header (line 1: no case's fault) and
  // the scene's parameters, nothing written
  const fs::path bad = write("bad.csv", "L2,L9\n0.2,1\n");
  r = run("batch " + phiq::test::model_path("seed/crank_slider_mixed.yaml") + " " + bad.string() + " -o " +
          (dir_ / "bad").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("phiq: " + bad.string() + ":1: 'L9' is not a parameter of "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(its parameters: L2, L3)"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("case 0"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
}

// phiq batch holds no descriptor per case between writes: 150 cases under a limit of 64 open files all run, each
// ending at its own closed form (θ2 = 2π: x_B = L2 + L3).
TEST_F(Cli, BatchRunsMoreCasesThanTheOpenFileLimit) {
  std::string text = "L2\n";
  const int cases = 150;
  for (int k = 0; k < cases; ++k) text += std::to_string(0.2 + 0.001 * k) + "\n";
  const fs::path list = write("cases.csv", text);
  const fs::path out = dir_ / "out";
  Result r = run_prefixed("ulimit -n 64; ", "batch -q " + phiq::test::model_path("seed/crank_slider_mixed.yaml") + " " +
                                                list.string() + " -o " + out.string() + " --threads 2");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  int files = 0;
  for (auto& e : fs::directory_iterator(out)) files += e.path().extension() == ".csv";
  EXPECT_EQ(files, cases) << "no temporaries left beside the case files";
  for (int k = 0; k < cases; ++k) {
    const phiq::CsvTable t = phiq::read_csv_table((out / ("case" + std::to_string(k) + ".csv")).string());
    ASSERT_EQ(t.rows.size(), 181u) << k;
    EXPECT_NEAR(t.rows.back()[4], 0.2 + 0.001 * k + 1.0, 1e-9) << k;
  }
}

// phiq batch on a redundant scene: each case is assembled and swept on its independent rows, as `phiq run` does
// (the door on three hinges, the third hinge's ground point moved by a parameter): on the axis, or 1e-12 off it,
// the door turns about z as driven; 1 cm off, the hinges cannot all hold and that case alone fails, naming hinge3.
TEST_F(Cli, BatchSweepsRedundantScenesOnTheirIndependentRows) {
  std::string text = slurp(phiq::test::model_path("redundant/door_three_hinges.yaml"));
  text.replace(text.find("dimension: 3"), 12, "dimension: 3\nparameters: {off: 0}");
  text.replace(text.find("at: [0, 0, 2]}, {body: door"), 13, "at: [off, 0, 2]");
  const fs::path scene = write("door.yaml", text);
  const fs::path cases = write("cases.csv", "off\n0\n1e-12\n0.01\n");
  const fs::path out = dir_ / "out";
  Result r = run("batch " + scene.string() + " " + cases.string() + " -o " + out.string() + " --threads 2");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("case 2: t = "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("hinge3"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("2 of 3 cases"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "case2.csv"));
  for (int k = 0; k < 2; ++k) {
    const phiq::CsvTable t = phiq::read_csv_table((out / ("case" + std::to_string(k) + ".csv")).string());
    ASSERT_EQ(t.rows.size(), 31u);
    ASSERT_EQ(t.columns[4], "door_e0");
    ASSERT_EQ(t.columns[7], "door_e3");
    double worst = 0;
    for (const auto& row : t.rows)  // a turn by t about z: e0 = cos(t/2), e3 = sin(t/2)
      worst = std::max({worst, std::fabs(row[4] - std::cos(row[0] / 2)), std::fabs(row[7] - std::sin(row[0] / 2))});
    EXPECT_LT(worst, 1e-9) << "case " << k;
  }
}

// Batch cases each get their own output points: a point placed by a parameter moves with it.
TEST_F(Cli, BatchCasesWriteTheirOwnOutputPoints) {
  std::string text = kFourbarOutputs;
  text.replace(text.find("parameters: {"), 13, "parameters: {h: 0.3, ");
  text.replace(text.find("at: [0, 0.3]"), 12, "at: [0, h]");
  const fs::path scene = write("f.yaml", text), cases = write("cases.csv", "h\n0.1\n0.5\n");
  Result r = run("batch -q " + scene.string() + " " + cases.string() + " -o " + (dir_ / "out").string());
  ASSERT_EQ(r.code, 0) << r.err;
  for (int k = 0; k < 2; ++k) {
    const double h = k == 0 ? 0.1 : 0.5;
    const phiq::CsvTable t = phiq::read_csv_table((dir_ / "out" / ("case" + std::to_string(k) + ".csv")).string());
    ASSERT_EQ(t.columns[21], "P.x");
    for (const auto& row : t.rows) {  // P = r3 + R(ψ3) (0, h)
      EXPECT_NEAR(row[21], row[4] - std::sin(row[6]) * h, 1e-12) << "case " << k;
      EXPECT_NEAR(row[22], row[5] + std::cos(row[6]) * h, 1e-12) << "case " << k;
    }
  }
}

// batch names the case only when the error comes from the case's parameters, not for an error of the scene itself.
TEST_F(Cli, BatchNamesTheCaseOnlyForItsOwnErrors) {
  const fs::path broken = write("broken.yaml", "parameters: {L2: 0.3}\ncoordinates: {x: [0\n");
  const fs::path cases = write("cases.csv", "L2\n0.2\n");
  Result r = run("batch " + broken.string() + " " + cases.string() + " -o " + (dir_ / "out").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_phiq_line(r.err));
  EXPECT_NE(r.err.find("broken.yaml:"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("case 0"), std::string::npos) << r.err;
  // a value of the case that makes the scene invalid: named with the case
  std::string text = slurp(phiq::test::model_path("seed/crank_slider_mixed.yaml"));
  const fs::path scene = write("cs.yaml", text);
  const fs::path neg = write("neg.csv", "L2,L3\n0.2,1\n0.3,-1\n");
  r = run("batch " + scene.string() + " " + neg.string() + " -o " + (dir_ / "out").string());
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(one_phiq_line(r.err));
  EXPECT_NE(r.err.find("(case 1 of " + neg.string() + ", line 3)"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

}  // namespace
