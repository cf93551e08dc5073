// `phiq modes` (tools/README.md): the report (count, paths, each mode, the placement's mode), the modes written as
// CSV, JSON and YAML with the same numbers, and a cam scene refused with its constraint named, exit 2, no file.
#include <nlohmann/json.hpp>

#include "cli_test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

std::string cli_modes_model(const std::string& rel) {
  std::string path = PHIQ_MODELS_DIR;
  path += '/';
  path += rel;
  return path;
}

TEST_F(Cli, ModesReportsTheFourBarsTwoModesAndThePlacementsOne) {
  const std::string scene = cli_modes_model("seed/fourbar_mixed.yaml");
  Result r = run("modes " + scene + " --threads 1");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("at t = 0: 2 real assembly modes (4 paths: 2 real, 0 complex"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  mode 1: theta2 = 0; xA = 0.4; yA = 0; "), std::string::npos) << r.out;
  // the placement (xB, yB) = (1.1, 1.0) is the open assembly, B above the ground: yB > 0 at θ2 = 0
  const std::vector<std::string> yb = phiq::test::captures(r.out, "yB = ([-0-9.e]+)");
  ASSERT_EQ(yb.size(), 2u);
  const std::size_t open = std::stod(yb[0]) > 0 ? 1 : 2;
  EXPECT_NE(r.out.find("the rough placement assembles into mode " + std::to_string(open) + " (distance "),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("the next nearest, mode " + std::to_string(3 - open) + ", is "), std::string::npos) << r.out;

  const fs::path csv = dir_ / "m.csv", json = dir_ / "m.json", yaml = dir_ / "m.yaml";
  ASSERT_EQ(run("modes " + scene + " -q --at 0.5 -o " + csv.string()).code, 0);
  ASSERT_EQ(run("modes " + scene + " -q --at 0.5 -o " + json.string()).code, 0);
  ASSERT_EQ(run("modes " + scene + " -q --at 0.5 -o " + yaml.string()).code, 0);
  const std::string text = slurp(csv);
  EXPECT_EQ(text.substr(0, text.find('\n')), "mode,singular,residual,condition,theta2,xA,yA,x3,y3,psi3,xB,yB");
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 3);
  const nlohmann::json j = nlohmann::json::parse(slurp(json));
  EXPECT_EQ(j["real"], 2);
  EXPECT_EQ(j["paths"], 4);
  ASSERT_EQ(j["modes"].size(), 2u);
  EXPECT_EQ(j["modes"][0]["q"][0].get<double>(), 0.5);  // θ2 = t
  // the CSV's first mode's xB is the JSON's, digit for digit
  const std::string row = text.substr(text.find('\n') + 1, text.find('\n', text.find('\n') + 1) - text.find('\n') - 1);
  EXPECT_EQ(std::stod(row.substr(row.rfind(',', row.rfind(',') - 1) + 1)), j["modes"][0]["q"][6].get<double>());
  EXPECT_NE(slurp(yaml).find("real: 2\n"), std::string::npos) << slurp(yaml);
}

TEST_F(Cli, ModesRefusesACamWithItsConstraintNamedAndWritesNothing) {
  const fs::path out = dir_ / "m.csv";
  const Result r = run("modes " + cli_modes_model("cams/eccentric_knife.yaml") + " -o " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("constraint 'cam' is not polynomial in its coordinates"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(files(), std::vector<std::string>({"stderr.txt", "stdout.txt"}));
}

TEST_F(Cli, ModesRefusesMorePathsThanAllowed) {
  const Result r = run("modes " + cli_modes_model("seed/fourbar_mixed.yaml") + " --max-paths 3");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("the total degree is 4 paths, above the limit of 3"), std::string::npos) << r.err;
}

}  // namespace

namespace {

// The value of column `name` in data row `row` (1: the first) of a CSV.
double cli_modes_cell(const std::string& csv, const std::string& name, int row) {
  std::istringstream lines(csv);
  std::string header, line;
  std::getline(lines, header);
  std::vector<std::string> names;
  for (std::istringstream h(header); std::getline(h, line, ',');) names.push_back(line);
  for (int k = 0; k < row; ++k) std::getline(lines, line);
  std::istringstream cells(line);
  std::string cell;
  for (std::size_t c = 0; std::getline(cells, cell, ','); ++c)
    if (names[c] == name) return std::stod(cell);
  return std::nan("");
}

TEST_F(Cli, RunFromEachModeStartsThereAndStaysOnItsBranch) {
  const std::string scene = cli_modes_model("seed/fourbar_mixed.yaml");
  const fs::path modes = dir_ / "m.csv";
  ASSERT_EQ(run("modes " + scene + " -q -o " + modes.string()).code, 0);
  const std::string listed = slurp(modes);
  for (int k = 1; k <= 2; ++k) {
    SCOPED_TRACE(k);
    const fs::path out = dir_ / ("r" + std::to_string(k) + ".csv");
    const Result r = run("run " + scene + " -q --mode " + std::to_string(k) + " -o " + out.string());
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string rows = slurp(out);
    EXPECT_NEAR(cli_modes_cell(rows, "xB", 1), cli_modes_cell(listed, "xB", k), 1e-12);
    EXPECT_NEAR(cli_modes_cell(rows, "yB", 1), cli_modes_cell(listed, "yB", k), 1e-12);
    // a crank-rocker keeps its branch all the way round: B on the side it started, at every row
    const double side = cli_modes_cell(listed, "y3", k) > 0 ? 1.0 : -1.0;
    for (int row = 1; row <= 361; row += 45) EXPECT_GT(side * cli_modes_cell(rows, "psi3", row), 0.0) << row;
  }
  const Result r = run("run " + scene + " -q --mode 3 -o " + (dir_ / "r3.csv").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--mode 3: the scene has 2 real assembly modes at t = 0"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "r3.csv"));
}

}  // namespace
