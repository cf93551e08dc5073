// `phiq modes` (tools/README.md): the report (count, paths, each mode, the placement's mode), the modes written as
// CSV, JSON and YAML with the same numbers, and a cam scene refused with its constraint named, exit 2, no file;
// the modes in `phiq check` (text, --json; the cam's line, the bound), the run summary, `phiq animate --modes`, and
// `--along` against the Grashof limit.
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <numbers>

#include "cli_test_support.hpp"
#include "modes_stewart.hpp"

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

namespace {

// The JSON object of the `<script id="phiq-data">` element of a page `phiq animate` wrote.
nlohmann::json cli_modes_page_data(const std::string& page) {
  const std::string open = "<script type=\"application/json\" id=\"phiq-data\">";
  const std::size_t from = page.find(open);
  if (from == std::string::npos) return {};
  const std::size_t begin = from + open.size();
  return nlohmann::json::parse(page.substr(begin, page.find("</script>", begin) - begin));
}

TEST_F(Cli, CheckCountsTheFourBarsModesAndSaysWhichOneThePlacementIsIn) {
  const std::string scene = cli_modes_model("seed/fourbar_mixed.yaml");
  const Result text = run("check " + scene);
  ASSERT_EQ(text.code, 0) << text.err;
  const Result json = run("check --json " + scene);
  ASSERT_EQ(json.code, 0) << json.err;
  const nlohmann::json m = nlohmann::json::parse(json.out)["modes"];
  EXPECT_EQ(m["status"], "counted");
  EXPECT_EQ(m["time"], 0.0);
  EXPECT_EQ(m["real"], 2);
  EXPECT_EQ(m["singular"], 0);
  EXPECT_EQ(m["paths"], 4);
  EXPECT_EQ(m["assembled"], true);
  ASSERT_TRUE(m["mode"].is_number_integer()) << m;
  const int mode = m["mode"];
  EXPECT_EQ(m["next_mode"], 3 - mode);
  EXPECT_LT(m["distance"].get<double>(), 1e-9);
  // the placement (B above the ground) is the mode with yB > 0 in phiq modes' list, numbered as run --mode takes it
  const fs::path listed = dir_ / "m.json";
  ASSERT_EQ(run("modes " + scene + " -q -o " + listed.string()).code, 0);
  const nlohmann::json modes = nlohmann::json::parse(slurp(listed));
  EXPECT_GT(modes["modes"][mode - 1]["q"][7].get<double>(), 0.0);
  EXPECT_LT(modes["modes"][2 - mode]["q"][7].get<double>(), 0.0);
  EXPECT_EQ(modes["placement"]["next_distance"], m["next_distance"]);
  EXPECT_NE(text.out.find("modes         2 real at t = 0 (4 paths); the placement is mode " + std::to_string(mode) +
                          " (phiq run --mode " + std::to_string(mode) + "), "),
            std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("; the next nearest, mode " + std::to_string(3 - mode) + ", is "), std::string::npos);
  EXPECT_NE(
      text.out.find(
          "away (max over coordinates of |dq| / scale: lengths over the length scale, angles in rad modulo 2 pi)"),
      std::string::npos);
}

TEST_F(Cli, CheckCountsTheCrankSlidersTwoModesAndSaysACamIsNotPolynomial) {
  const Result slider = run("check --json " + cli_modes_model("seed/crank_slider_mixed.yaml"));
  ASSERT_EQ(slider.code, 0) << slider.err;
  const nlohmann::json m = nlohmann::json::parse(slider.out)["modes"];
  EXPECT_EQ(m["status"], "counted");
  EXPECT_EQ(m["real"], 2);
  EXPECT_TRUE(m["mode"] == 1 || m["mode"] == 2) << m;
  // a cam: one line naming the constraint, and the check passes as before (its exit status is the assembly's)
  const Result cam = run("check " + cli_modes_model("cams/eccentric_knife.yaml"));
  EXPECT_EQ(cam.code, 0) << cam.err;
  const std::vector<std::string> line = phiq::test::captures(cam.out, "(modes  [^\n]*)");
  ASSERT_EQ(line.size(), 1u) << cam.out;
  EXPECT_EQ(line[0].find("modes         not available: constraint 'cam' is not polynomial in its coordinates"), 0u)
      << line[0];
}

TEST_F(Cli, CheckSkipsTheCountAboveItsBoundsAndSaysSo) {
  const fs::path big = dir_ / "big.yaml";
  ASSERT_EQ(run("generate nfourbar 20 --coords natural -o " + big.string()).code, 0);
  const Result r = run("check --json " + big.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["coordinates"].get<int>(), 40);
  EXPECT_EQ(j["modes"]["status"], "skipped");
  EXPECT_EQ(j["modes"]["message"], "not counted here: " + std::to_string(j["coordinates"].get<int>()) +
                                       " coordinates, above 40 (phiq modes counts them)");
  EXPECT_TRUE(j["modes"]["real"].is_null());
  // four loops: few coordinates; block by block 110 paths (ModesBlocks), past the 64 check tracks at the third
  // block (its singular solutions join the blocks after it), then the whole system's 4⁴ · 2: why, in one line
  const fs::path four = dir_ / "four.yaml";
  ASSERT_EQ(run("generate nfourbar 4 --coords natural -o " + four.string()).code, 0);
  const Result paths = run("check " + four.string());
  ASSERT_EQ(paths.code, 0) << paths.err;
  EXPECT_NE(paths.out.find("\nmodes         not counted here: the block solve gave up at blocks 3 to 5 of 5 (6 "
                           "unknowns): the blocks' paths pass the limit of 64; the whole system takes 512 paths, "
                           "above 64 (phiq modes counts them)\n"),
            std::string::npos)
      << paths.out;
  // the Stewart–Gough platform: the paths its solve would take (degrees lowered: 432), not its total degree (8192)
  const fs::path stewart = write("stewart.yaml", phiq::test::kModesStewartScene);
  const Result lowered = run("check " + stewart.string());
  EXPECT_NE(lowered.out.find("\nmodes         not counted here: 432 paths, above 64 (phiq modes counts them)\n"),
            std::string::npos)
      << lowered.out << lowered.err;
}

TEST_F(Cli, RunSummaryNamesTheModeOfItsFirstRow) {
  const std::string scene = cli_modes_model("seed/fourbar_mixed.yaml");
  const fs::path summary = dir_ / "s.json", two = dir_ / "s2.json";
  ASSERT_EQ(run("run " + scene + " -q -o " + (dir_ / "r.csv").string() + " --summary " + summary.string()).code, 0);
  const nlohmann::json m = nlohmann::json::parse(slurp(summary))["modes"];
  EXPECT_EQ(m["status"], "counted");
  EXPECT_EQ(m["real"], 2);
  ASSERT_TRUE(m["mode"] == 1 || m["mode"] == 2) << m;
  EXPECT_LT(m["distance"].get<double>(), 1e-9);
  // started from the other mode, the first row is in it
  const int other = 3 - m["mode"].get<int>();
  ASSERT_EQ(run("run " + scene + " -q --mode " + std::to_string(other) + " -o " + (dir_ / "r2.csv").string() +
                " --summary " + two.string())
                .code,
            0);
  const nlohmann::json m2 = nlohmann::json::parse(slurp(two))["modes"];
  EXPECT_EQ(m2["mode"], other);
  EXPECT_LT(m2["distance"].get<double>(), 1e-12);
  EXPECT_NEAR(m2["next_distance"].get<double>(), m["next_distance"].get<double>(), 1e-9);
  // the ground 5 long: no real mode, and the failed run's summary says so (no row: nothing assembled)
  const fs::path none = dir_ / "s0.json";
  ASSERT_EQ(
      run("run " + scene + " -q --set L1=5 -o " + (dir_ / "r0.csv").string() + " --summary " + none.string()).code, 1);
  const nlohmann::json m0 = nlohmann::json::parse(slurp(none))["modes"];
  EXPECT_EQ(m0["status"], "counted");
  EXPECT_EQ(m0["real"], 0);
  EXPECT_EQ(m0["assembled"], false);
  EXPECT_TRUE(m0["mode"].is_null());
}

TEST_F(Cli, AnimateModesDrawsOnePosePerModeAndRefusesASceneWithNone) {
  const std::string scene = cli_modes_model("seed/fourbar_mixed.yaml");
  const fs::path page = dir_ / "modes.html";
  const Result r = run("animate " + scene + " --modes -o " + page.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json data = cli_modes_page_data(slurp(page));
  ASSERT_TRUE(data.is_object());
  EXPECT_EQ(data["rows"], 2);
  EXPECT_EQ(data["t"], nlohmann::json({1.0, 2.0}));
  ASSERT_EQ(data["row_labels"].size(), 2u);
  EXPECT_EQ(data["row_labels"][0].get<std::string>().rfind("mode 1 of 2 at t = 0", 0), 0u) << data["row_labels"];
  EXPECT_EQ(data["row_labels"][1].get<std::string>().rfind("mode 2 of 2 at t = 0", 0), 0u) << data["row_labels"];
  int placements = 0;
  for (const auto& label : data["row_labels"])
    placements += label.get<std::string>().find("(the placement's)") != std::string::npos ? 1 : 0;
  EXPECT_EQ(placements, 1);
  // the ground 5 long: the crank's tip 4.6 from C, out of reach of coupler and rocker (2.2): no real mode
  const fs::path none = dir_ / "none.html";
  const Result bad = run("animate " + scene + " --set L1=5 --modes -o " + none.string());
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find(": --modes: no real assembly mode at t = 0 (4 paths: 2 complex"), std::string::npos)
      << bad.err;
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
  EXPECT_FALSE(fs::exists(none));
  const Result glb = run("animate " + scene + " --modes -o " + (dir_ / "m.glb").string());
  EXPECT_EQ(glb.code, 2);
  EXPECT_NE(glb.err.find("--modes: the modes are drawn from the scene alone, in the HTML viewer (-o OUT.html)"),
            std::string::npos)
      << glb.err;
}

TEST_F(Cli, ModesAlongTheDriveCountsAsTheGrashofLimitSaysAndMarksTheChanges) {
  // crank 1.5: the loop closes (2 modes) while |AC| <= coupler + rocker = 2.2, cos θ2 >= (1 + 2.25 - 2.2²) / 3
  // (θ2 = t over 0 … 2π), and has no real mode beyond: 13 samples π/6 apart change count twice
  const std::string scene = cli_modes_model("seed/fourbar_mixed.yaml");
  const fs::path csv = dir_ / "along.csv";
  const Result r = run("modes " + scene + " --set L2=1.5 --along 13 --threads 1 -o " + csv.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string text = slurp(csv);
  EXPECT_EQ(text.substr(0, text.find('\n')), "t,real,complex,singular,at_infinity,failed_paths");
  const double limit = (1.0 + 2.25 - 2.2 * 2.2) / 3.0;
  std::vector<std::size_t> changes;
  for (int k = 0; k < 13; ++k) {
    const double t = 2.0 * std::numbers::pi * k / 12;
    EXPECT_NEAR(cli_modes_cell(text, "t", k + 1), t, 1e-12);
    const double expected = std::cos(t) >= limit ? 2.0 : 0.0;
    EXPECT_EQ(cli_modes_cell(text, "real", k + 1), expected) << "t = " << t;
    EXPECT_EQ(cli_modes_cell(text, "real", k + 1) + cli_modes_cell(text, "complex", k + 1), 2.0) << "t = " << t;
    if (k > 0 && (std::cos(t) >= limit) != (std::cos(2.0 * std::numbers::pi * (k - 1) / 12) >= limit))
      changes.push_back(static_cast<std::size_t>(k));
  }
  ASSERT_EQ(changes, std::vector<std::size_t>({5, 8}));
  EXPECT_NE(r.out.find("real assembly modes at 13 times from t = 0 to 6.283185307 (2 changes)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("the count changes from 2 to 0 between t = 2.094395102 and t = 2.617993878"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("the count changes from 0 to 2 between t = 3.665191429 and t = 4.188790205"), std::string::npos)
      << r.out;
  const Result bad = run("modes " + scene + " --along 5 --at 1");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("--along"), std::string::npos) << bad.err;
}

}  // namespace
