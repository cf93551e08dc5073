// `phiq plot`: the SVG's mechanism lines, traces and series, a CSV without the coordinates drawn from a sweep
// checked against it, a scene with nothing of the mechanism to draw, and bad input refused in one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "phiq/csv_compare.hpp"

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::kFourbarOutputs;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

TEST_F(Cli, PlotDrawsTheMechanismTracesAndColumns) {
  const fs::path scene = write("f.yaml", kFourbarOutputs), csv = dir_ / "f.csv", svg = dir_ / "f.svg";
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + csv.string()).code, 0);
  Result r = run("plot " + scene.string() + " " + csv.string() + " -o " + svg.string() + " --columns theta2,P.x,P.vx");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string s = slurp(svg);
  EXPECT_EQ(s.rfind("<?xml", 0), 0u);
  EXPECT_NE(s.find("<svg xmlns=\"http://www.w3.org/2000/svg\""), std::string::npos);
  EXPECT_EQ(s.substr(s.size() - 7), "</svg>\n");
  auto count = [&](const std::string& what) {
    std::size_t n = 0;
    for (std::size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
    return n;
  };
  // 5 positions × 4 lines (crank O–A, the coupler's two arms, rocker C–B); 2 traced points; 3 columns
  EXPECT_EQ(count("<polyline class=\"mechanism\""), 20u);
  EXPECT_EQ(count("<polyline class=\"trace\""), 2u);
  EXPECT_EQ(count("<polyline class=\"series\""), 3u);
  EXPECT_EQ(count("<polyline"), 25u);
  EXPECT_EQ(count("<g"), count("</g>"));
  // each trace has a vertex per row
  const std::size_t p = s.find("data-point=\"P\" points=\"");
  ASSERT_NE(p, std::string::npos);
  const std::string pts = s.substr(p, s.find('"', p + 23) - p);
  EXPECT_EQ(static_cast<std::size_t>(std::count(pts.begin(), pts.end(), ',')), 73u);
  // default columns: the coordinates (at most 6)
  ASSERT_EQ(run("plot " + scene.string() + " " + csv.string() + " -o " + svg.string() + " --positions 3").code, 0);
  const std::string d = slurp(svg);
  std::size_t series = 0, mech = 0;
  for (std::size_t q = d.find("class=\"series\""); q != std::string::npos; q = d.find("class=\"series\"", q + 1))
    ++series;
  for (std::size_t q = d.find("class=\"mechanism\""); q != std::string::npos; q = d.find("class=\"mechanism\"", q + 1))
    ++mech;
  EXPECT_EQ(series, 6u);
  EXPECT_EQ(mech, 12u);
  // a redundant scene writing only its crank angle: drawn from a sweep solved as `phiq run` solves it
  std::string red = slurp(phiq::test::model_path("redundant/parallelogram_fifth_bar.yaml"));
  red.replace(red.find("output:"), std::string::npos, "output: {coordinates: [psi1], residuals: [A3]}\n");
  const fs::path red_scene = write("red.yaml", red), red_csv = dir_ / "red.csv";
  ASSERT_EQ(run("run -q " + red_scene.string() + " -o " + red_csv.string()).code, 0);
  Result rr = run("plot " + red_scene.string() + " " + red_csv.string() + " -o " + svg.string());
  ASSERT_EQ(rr.code, 0) << rr.err;
  const std::string rs = slurp(svg);
  std::size_t red_lines = 0;
  for (std::size_t q = rs.find("class=\"mechanism\""); q != std::string::npos;
       q = rs.find("class=\"mechanism\"", q + 1))
    ++red_lines;
  EXPECT_EQ(red_lines, 25u);  // 5 rows × (3 crank arms + 2 coupler arms)
  // the left-out redundant row is still within the tolerance, evaluated on the whole scene model
  const phiq::CsvTable rt = phiq::read_csv_table(red_csv.string());
  ASSERT_EQ(rt.columns.back(), "A3.residual");
  for (const auto& row : rt.rows) EXPECT_LE(row.back(), 1e-10);
}

// A scene whose mechanism draws nothing (coordinates tied by an equation alone) got an empty panel without a word.
TEST_F(Cli, PlotSaysWhenThereIsNothingOfTheMechanismToDraw) {
  const fs::path scene = write("c.yaml", R"(phiq: 1
coordinates: {a: 0, b: 0}
constraints: [{name: tie, type: equation, expr: "b - 2*a", unit: length}]
drivers: [{name: m, coordinate: a, law: {type: linear, initial: 0, rate: 1}}]
time: {start: 0, end: 1, steps: 10}
)"),
                 csv = dir_ / "c.csv", svg = dir_ / "c.svg";
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + csv.string()).code, 0);
  Result r = run("plot " + scene.string() + " " + csv.string() + " -o " + svg.string());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.rfind("phiq: plot: " + scene.string() + ": nothing of the mechanism to draw (", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  const std::string drawn = slurp(svg);
  EXPECT_EQ(drawn.find("class=\"mechanism\""), std::string::npos);
  EXPECT_NE(drawn.find("class=\"series\""), std::string::npos);
  // a planar generated scene draws its bars, silently
  ASSERT_EQ(run("generate nfourbar 3 --steps 10 -o " + scene.string()).code, 0);
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + csv.string()).code, 0);
  r = run("plot " + scene.string() + " " + csv.string() + " -o " + svg.string());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_NE(slurp(svg).find("class=\"mechanism\""), std::string::npos);
}

TEST_F(Cli, PlotRefusesBadInputWithOneLineAndNoFile) {
  const fs::path scene = write("f.yaml", kFourbarOutputs), csv = dir_ / "f.csv", svg = dir_ / "f.svg";
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + csv.string()).code, 0);
  auto one_line_failure = [&](const std::string& args, const std::string& says) {
    Result r = run("plot " + args + " -o " + svg.string());
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(svg)) << args;
  };
  one_line_failure(scene.string() + " " + csv.string() + " --columns theta2,nope", "no column 'nope'");
  // a CSV of another scene (here: positions only, the coordinates alone)
  std::string other = kFourbarOutputs;
  other = other.substr(0, other.find("output:")) + "output: {coordinates: [theta2]}\n";
  const fs::path other_scene = write("g.yaml", other), other_csv = dir_ / "g.csv";
  ASSERT_EQ(run("run -q " + other_scene.string() + " -o " + other_csv.string()).code, 0);
  one_line_failure(scene.string() + " " + other_csv.string(), "its columns are not the output of");
  // a CSV without the coordinates the drawing needs: the positions are solved again, and checked against the
  // columns it has
  Result ok = run("plot " + other_scene.string() + " " + other_csv.string() + " -o " + svg.string());
  ASSERT_EQ(ok.code, 0) << ok.err;
  const std::string drawn = slurp(svg);
  std::size_t lines = 0;
  for (std::size_t q = drawn.find("class=\"mechanism\""); q != std::string::npos;
       q = drawn.find("class=\"mechanism\"", q + 1))
    ++lines;
  EXPECT_EQ(lines, 20u);
  fs::remove(svg);
  std::string tampered = slurp(other_csv);
  const std::size_t row3 = tampered.find('\n', tampered.find('\n', tampered.find('\n') + 1) + 1) + 1;
  tampered.replace(tampered.find(',', row3) + 1, tampered.find('\n', row3) - tampered.find(',', row3) - 1, "0.5");
  const fs::path bad_csv = write("bad.csv", tampered);
  one_line_failure(other_scene.string() + " " + bad_csv.string(), "is not the result of");
  one_line_failure(scene.string() + " " + (dir_ / "missing.csv").string(), "missing.csv");
  one_line_failure((dir_ / "missing.yaml").string() + " " + csv.string(), "missing.yaml");
}

}  // namespace
