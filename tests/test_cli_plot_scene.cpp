// `phiq plot SCENE -o OUT.svg` without a result (the scene swept in memory: the same SVG as from its run's
// result), default columns that prefer the joints' measures and the driven coordinates to Euler parameters, HDF5
// results read as `phiq compare` and `phiq animate` read them, and results of another scene refused in one line.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::captures;
using phiq::test::Cli;
using phiq::test::count;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

// The SVG without its <title> (which names the result).
std::string without_title(std::string svg) {
  const std::size_t a = svg.find("<title>"), b = svg.find("</title>");
  EXPECT_NE(a, std::string::npos);
  return svg.erase(a, b - a);
}

// A scene written with every coordinate is drawn from its own sweep exactly as from its run's CSV or HDF5 file.
TEST_F(Cli, PlotWithoutAResultOrFromHdf5DrawsAsFromTheCsv) {
  const std::string nat = phiq::test::model_path("seed/fourbar_natural.yaml");
  const fs::path csv = dir_ / "r.csv", h5 = dir_ / "r.h5";
  ASSERT_EQ(run("run -q " + nat + " -o " + csv.string()).code, 0);
  ASSERT_EQ(run("run -q " + nat + " -o " + h5.string()).code, 0);
  Result r = run("plot " + nat + " " + csv.string() + " -o " + (dir_ / "csv.svg").string());
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string from_csv = slurp(dir_ / "csv.svg");
  r = run("plot " + nat + " " + h5.string() + " -o " + (dir_ / "h5.svg").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(without_title(slurp(dir_ / "h5.svg")), without_title(from_csv));
  r = run("plot " + nat + " -o " + (dir_ / "swept.svg").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const std::string swept = slurp(dir_ / "swept.svg");
  EXPECT_EQ(without_title(swept), without_title(from_csv));
  EXPECT_NE(swept.find("<title>fourbar_natural: its sweep</title>"), std::string::npos);
  EXPECT_EQ(count(swept, "<polyline class=\"mechanism\""), 15u);  // 5 rows × crank, coupler, rocker
  // a scene whose output lists four angles only: its mechanism is drawn from the sweep, its columns as asked
  const std::string planetary = phiq::test::model_path("transmissions/planetary.yaml");
  r = run("plot " + planetary + " -o " + (dir_ / "pl.svg").string() + " --columns psic,planet_centre.x");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string pl = slurp(dir_ / "pl.svg");
  EXPECT_EQ(captures(pl, "data-column=\"([^\"]+)\""), (std::vector<std::string>{"psic", "planet_centre.x"}));
  EXPECT_EQ(count(pl, "<polyline class=\"trace\""), 1u);
  EXPECT_EQ(count(pl, "data-point=\"planet_centre\""), 1u);
  EXPECT_GT(count(pl, "<polyline class=\"mechanism\""), 0u);
  // the files are the SVGs asked for, nothing else
  EXPECT_EQ(files(), (std::vector<std::string>{"csv.svg", "h5.svg", "pl.svg", "r.csv", "r.h5", "stderr.txt",
                                               "stdout.txt", "swept.svg"}));
}

// Default columns: the measures of the joints (a driven hinge's first) and the driven coordinates before the other
// coordinates, Euler parameters last; the joints' measures in an angle panel.
TEST_F(Cli, PlotDefaultColumnsPreferJointsAndDrivenCoordinatesToEulerParameters) {
  const std::string rssr = phiq::test::model_path("spatial/rssr.yaml");
  const fs::path svg = dir_ / "p.svg";
  Result r = run("plot " + rssr + " -o " + svg.string());
  ASSERT_EQ(r.code, 0) << r.err;
  std::string s = slurp(svg);
  EXPECT_EQ(captures(s, "data-column=\"([^\"]+)\""),
            (std::vector<std::string>{"crank_hinge.angle", "rocker_hinge.angle", "crank_e0", "crank_e3", "rocker_e0",
                                      "rocker_e1"}));
  EXPECT_EQ(captures(s, "data-quantity=\"([^\"]+)\""), (std::vector<std::string>{"angle", "unitless"}));
  // the Cardan joint: its driven hinge's angle first
  const std::string cardan = phiq::test::model_path("spatial/cardan.yaml");
  r = run("plot " + cardan + " -o " + svg.string());
  ASSERT_EQ(r.code, 0) << r.err;
  s = slurp(svg);
  const std::vector<std::string> cols = captures(s, "data-column=\"([^\"]+)\"");
  ASSERT_EQ(cols.size(), 6u);
  EXPECT_EQ(cols[0], "hinge1.angle");
  for (std::size_t k = 1; k < cols.size(); ++k) EXPECT_NE(cols[k].find("_e"), std::string::npos) << cols[k];
  // a result that writes the scene's joint outputs: they come first there too
  std::string text = slurp(rssr);
  text.replace(text.find("output: {"), std::string("output: {").size(), "output: {joints: [rocker_hinge], ");
  const fs::path scene = write("j.yaml", text), csv = dir_ / "j.csv";
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + csv.string()).code, 0);
  r = run("plot " + scene.string() + " " + csv.string() + " -o " + svg.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(captures(slurp(svg), "data-column=\"([^\"]+)\""),
            (std::vector<std::string>{"rocker_hinge.angle", "crank_e0", "crank_e3", "rocker_e0", "rocker_e1"}));
  // a planar coordinate driver first, then the coordinates that move
  const std::string slider = phiq::test::model_path("seed/fourbar_natural.yaml");
  r = run("plot " + slider + " -o " + svg.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(captures(slurp(svg), "data-column=\"([^\"]+)\""),
            (std::vector<std::string>{"theta2", "xA", "yA", "xB", "yB"}));
}

// A result of another scene, by what an HDF5 file records or by a CSV's columns: one line naming both, exit 2, no
// file.
TEST_F(Cli, PlotRefusesAResultOfAnotherSceneInOneLine) {
  const std::string rssr = phiq::test::model_path("spatial/rssr.yaml"),
                    cardan = phiq::test::model_path("spatial/cardan.yaml");
  const fs::path h5 = dir_ / "rssr.h5", svg = dir_ / "p.svg";
  ASSERT_EQ(run("run -q " + rssr + " -o " + h5.string()).code, 0);
  Result r = run("plot " + cardan + " " + h5.string() + " -o " + svg.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "phiq: plot: " + h5.string() + ": not a result of " + cardan + ": it records the scene " + rssr +
                       ", whose text differs\n");
  EXPECT_FALSE(fs::exists(svg));
  // the rssr's CSV with a column more than the scene writes
  const fs::path csv = dir_ / "r.csv";
  ASSERT_EQ(run("run -q " + rssr + " -o " + csv.string()).code, 0);
  std::istringstream lines(slurp(csv));
  std::string text;
  for (std::string line; std::getline(lines, line);) text += line + (text.empty() ? ",extra\n" : ",0\n");
  const fs::path more = write("more.csv", text);
  r = run("plot " + rssr + " " + more.string() + " -o " + svg.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "phiq: plot: " + more.string() + ": its columns are not the output of " + rssr +
                       ": column 'extra' is not one it writes\n");
  EXPECT_FALSE(fs::exists(svg));
  // an HDF5 file that is not phiq's results: named, exit 2
  const fs::path junk = write("junk.h5", "not HDF5 at all\n");
  r = run("plot " + rssr + " " + junk.string() + " -o " + svg.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(phiq::test::one_phiq_line(r.err));
  EXPECT_EQ(r.err.rfind("phiq: plot: " + junk.string() + ": not a readable HDF5 file", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(svg));
}

// Without a result, a scene that cannot be swept exits 1 as `phiq run` does, with its reason in one line, and no file.
TEST_F(Cli, PlotAndAnimateWithoutAResultSayWhyTheSceneCannotBeSwept) {
  const std::string nat = phiq::test::model_path("seed/fourbar_natural.yaml");  // a rocker of 5 m cannot close it
  for (const std::string command : {"plot", "animate"}) {
    const fs::path out = dir_ / (command == "plot" ? "p.svg" : "p.html");
    const Result r = run(command + " " + nat + " --set L4=5 -o " + out.string());
    EXPECT_EQ(r.code, 1) << command;
    EXPECT_TRUE(phiq::test::one_phiq_line(r.err)) << r.err;
    EXPECT_EQ(r.err.rfind("phiq: " + command + ": " + nat + ": step 0, t = 0: initial assembly failed", 0), 0u)
        << r.err;
    EXPECT_FALSE(fs::exists(out)) << command;
  }
  EXPECT_EQ(files(), (std::vector<std::string>{"stderr.txt", "stdout.txt"}));
}

}  // namespace
