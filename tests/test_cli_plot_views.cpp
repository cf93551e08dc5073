// `phiq plot`'s views: axes with ticks and units, one panel per quantity, default columns that move, the ground,
// joints and guides drawn, spatial scenes in an isometric view with their axes, and a NaN refused in one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <array>
#include <filesystem>
#include <map>
#include <regex>
#include <string>

#include "phiq/csv_compare.hpp"
#include "phiq/drawn_parts.hpp"
#include "phiq/phiq.hpp"

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::captures;
using phiq::test::Cli;
using phiq::test::count;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

class Plot : public Cli {
 protected:
  std::string plot(const std::string& model, const std::string& extra = "") {
    const fs::path csv = dir_ / "r.csv", svg = dir_ / "p.svg";
    EXPECT_EQ(run("run -q " + phiq::test::model_path(model) + " -o " + csv.string()).code, 0);
    table = phiq::read_csv_table(csv.string());
    const Result r = run("plot " + phiq::test::model_path(model) + " " + csv.string() + " -o " + svg.string() + extra);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err, "");
    return slurp(svg);
  }
  // min and max of a column of the result
  std::pair<double, double> range(const std::string& column) {
    const std::size_t c =
        static_cast<std::size_t>(std::find(table.columns.begin(), table.columns.end(), column) - table.columns.begin());
    double lo = 1e300, hi = -1e300;
    for (const auto& row : table.rows) lo = std::min(lo, row[c]), hi = std::max(hi, row[c]);
    return {lo, hi};
  }
  phiq::CsvTable table;
};

TEST_F(Plot, SpatialMechanismIsDrawnInIsometricViewWithItsAxesAndMovingColumns) {
  const std::string s = plot("spatial/rssr.yaml");
  // the mechanism: 5 rows × (the coupler bar and the two arms to its ends), the two ground hinges hatched, the
  // coupler's ends as dots at every row, and the three axes
  EXPECT_EQ(count(s, "<polyline class=\"mechanism\""), 15u);
  EXPECT_EQ(count(s, "<g class=\"ground\">"), 2u);
  EXPECT_EQ(count(s, "class=\"joint revolute\""), 2u);  // still: drawn once
  EXPECT_EQ(count(s, "class=\"joint point\""), 10u);
  for (const char* a : {"x", "y", "z"}) EXPECT_EQ(count(s, std::string("class=\"axis3d\" data-axis=\"") + a), 1u);
  EXPECT_NE(s.find("isometric view"), std::string::npos);
  // the view from (1, 1, 1), right-handed as space is: x towards the lower left, y towards the lower right, z up
  // (screen coordinates: y down), so that x turns to y counterclockwise seen from the viewer, as about z
  std::map<std::string, std::array<double, 2>> axis;
  const std::regex line(
      "data-axis=\"([xyz])\" x1=\"([-0-9.]+)\" y1=\"([-0-9.]+)\" x2=\"([-0-9.]+)\" "
      "y2=\"([-0-9.]+)\"");
  for (auto it = std::sregex_iterator(s.begin(), s.end(), line); it != std::sregex_iterator(); ++it)
    axis[(*it)[1]] = {std::stod((*it)[4]) - std::stod((*it)[2]), -(std::stod((*it)[5]) - std::stod((*it)[3]))};
  ASSERT_EQ(axis.size(), 3u);
  EXPECT_LT(axis["x"][0], 0.0);
  EXPECT_LT(axis["x"][1], 0.0);
  EXPECT_GT(axis["y"][0], 0.0);
  EXPECT_LT(axis["y"][1], 0.0);
  EXPECT_NEAR(axis["z"][0], 0.0, 0.01);
  EXPECT_GT(axis["z"][1], 0.0);
  EXPECT_GT(axis["x"][0] * axis["y"][1] - axis["x"][1] * axis["y"][0], 0.0) << "a mirrored view";
  // no constant column: the default columns are those that change (the Euler parameters that turn)
  const std::vector<std::string> cols = captures(s, "data-column=\"([^\"]+)\"");
  EXPECT_EQ(cols, (std::vector<std::string>{"crank_e0", "crank_e3", "rocker_e0", "rocker_e1"}));
  for (const std::string& c : cols) {
    const auto [lo, hi] = range(c);
    EXPECT_GT(hi - lo, 0.1) << c;
  }
  // one panel, the Euler parameters' (unitless), with ticks and its unit
  EXPECT_EQ(captures(s, "data-quantity=\"([^\"]+)\""), (std::vector<std::string>{"unitless"}));
  EXPECT_NE(s.find(">unitless (1)</text>"), std::string::npos);
  EXPECT_NE(s.find(">t (s)</text>"), std::string::npos);
}

TEST_F(Plot, PanelsPerQuantityWithTicksAndUnits) {
  const std::string s =
      plot("seed/fourbar_reference_point.yaml", " --columns psi2,x3,psi3.v,x3.v,x3.a,psi2.a --positions 4");
  // one panel per quantity, in order of first use, each labelled with its unit
  EXPECT_EQ(captures(s, "data-quantity=\"([^\"]+)\""),
            (std::vector<std::string>{"angle", "length", "angular velocity", "velocity", "acceleration",
                                      "angular acceleration"}));
  EXPECT_EQ(captures(s, "data-unit=\"([^\"]+)\""),
            (std::vector<std::string>{"rad", "m", "rad/s", "m/s", "m/s²", "rad/s²"}));
  for (const char* label : {">angle (rad)<", ">length (m)<", ">angular velocity (rad/s)<", ">velocity (m/s)<",
                            ">acceleration (m/s²)<", ">angular acceleration (rad/s²)<", ">x (m)<", ">y (m)<"})
    EXPECT_NE(s.find(label), std::string::npos) << label;
  // the ticks of the angle panel: psi2 runs 0 … 2π: 0, 2, 4, 6 rad (4 asked for); t: 0, 1, …, 6 s (8 asked for)
  const std::size_t angle = s.find("data-quantity=\"angle\""), next = s.find("</g>", angle);
  const std::string panel = s.substr(angle, next - angle);
  std::vector<std::string> labels = captures(panel, "class=\"tick-label\"[^>]*>([^<]+)<");
  EXPECT_EQ(labels, (std::vector<std::string>{"0", "1", "2", "3", "4", "5", "6", "0", "2", "4", "6"}));
  EXPECT_EQ(count(panel, "class=\"tick\""), count(panel, "class=\"tick-label\""));
  // the ground pivots O and C hatched; the two moving pivots as circles at each of the 4 rows (a full turn: the
  // last row, the first again, is not drawn on top of it)
  EXPECT_EQ(count(s, "<g class=\"ground\">"), 2u);
  EXPECT_EQ(count(s, "class=\"joint revolute\""), 2u + 2u * 4u);
  const std::vector<std::string> t = captures(s, "class=\"position\" data-t=\"([^\"]+)\"");
  EXPECT_EQ(t, (std::vector<std::string>{"0", "1.571", "3.142", "4.712"}));
  // the default columns: the driven coordinate psi2 first, then the first 5 moving ones in column order (x2, y2, x3,
  // y3, psi3; not x4 …), drawn by quantity: the angles' panel, then the lengths'
  const std::string d = plot("seed/fourbar_reference_point.yaml");
  EXPECT_EQ(captures(d, "data-column=\"([^\"]+)\""),
            (std::vector<std::string>{"psi2", "psi3", "x2", "y2", "x3", "y3"}));
}

// A crank-slider of three bodies in reference-point coordinates, the slider on a guide along ground's x axis.
constexpr const char* kSlider = R"(phiq: 1
name: slider
parameters: {L2: 0.4, L3: 1.2}
coordinates: {x2: 0.2, y2: 0, psi2: 0, x3: 1.0, y3: 0, psi3: 0, x4: 1.6, y4: 0, psi4: 0}
bodies: {crank: [x2, y2, psi2], rod: [x3, y3, psi3], slider: [x4, y4, psi4]}
constraints:
  - {name: O, type: revolute, between: [{body: crank, at: [-L2/2, 0]}, {body: ground, at: [0, 0]}]}
  - {name: A, type: revolute, between: [{body: crank, at: [L2/2, 0]}, {body: rod, at: [-L3/2, 0]}]}
  - {name: B, type: revolute, between: [{body: rod, at: [L3/2, 0]}, {body: slider, at: [0, 0]}]}
  - {name: slide, type: prismatic, between: [{body: ground}, {body: slider}], axis: [1, 0]}
drivers: [{name: motor, coordinate: psi2, law: {type: linear, initial: 0, rate: 1}}]
time: {start: 0, end: 2*pi, steps: 72}
)";

TEST_F(Plot, PrismaticPairsAreBlocksOnTheirGuides) {
  const fs::path scene = write("slider.yaml", kSlider), csv = dir_ / "r.csv", svg = dir_ / "p.svg";
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + csv.string()).code, 0);
  const Result r = run("plot " + scene.string() + " " + csv.string() + " -o " + svg.string() + " --positions 3");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string s = slurp(svg);
  EXPECT_EQ(count(s, "class=\"joint prismatic\""), 3u);
  EXPECT_EQ(count(s, "class=\"guide\""), 3u);
  EXPECT_EQ(count(s, "class=\"hatch\""), 3u * 5u + 6u);  // the guide on ground at each row, the ground pivot O
  EXPECT_EQ(count(s, "<g class=\"ground\">"), 1u);
  // the block lies along the guide: ground's x axis, no rotation
  EXPECT_EQ(captures(s, "class=\"joint prismatic\"[^>]*rotate\\((-?[0-9.]+) "),
            (std::vector<std::string>{"0.0", "0.0", "0.0"}));
}

// The parts under the sketch: a filled outline per planar shape at each drawn row (a box a rectangle of its sides'
// ratio, centred between the crank's pins; a cylinder seen along z a circle; a polygon its outline), a curve a
// polyline of its width.
TEST_F(Plot, PlanarPartsAreFilledOutlinesUnderTheSketch) {
  std::string text = slurp(phiq::test::model_path("seed/fourbar_reference_point.yaml"));
  text +=
      "parts:\n"
      "  crank: {shapes: [{name: bar, type: box, size: [0.4, 0.05, 0.01]},"
      " {name: hub, type: cylinder, radius: 0.03, length: 0.02, at: [0.2, 0]}]}\n"
      "  coupler: {colour: \"#e6801a\", shapes: [{name: plate, type: polygon, points: [[-0.3, 0], [0.3, 0], [0, 0.1]],"
      " thickness: 0.01}]}\n"
      "  rocker: {shapes: [{name: slot, type: curve, points: [[-0.3, 0], [0.3, 0]], width: 0.02}]}\n";
  const fs::path scene = write("parts.yaml", text), svg = dir_ / "p.svg";
  const Result r = run("plot " + scene.string() + " -o " + svg.string() + " --positions 3");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string s = slurp(svg);
  // a path per shape of each drawn part at each row: the four stated, and the ground's derived pins at O and C
  std::size_t shapes = 0;
  for (const phiq::Part& part : phiq::drawn_parts(phiq::load_scene(scene.string()))) shapes += part.shapes.size();
  EXPECT_EQ(shapes, 4u + 2u);
  EXPECT_EQ(count(s, "class=\"part\""), shapes * 3u);
  EXPECT_EQ(count(s, "class=\"part\" data-part=\"ground\""), 2u * 3u);
  EXPECT_EQ(count(s, "class=\"part\" data-part=\"crank\" data-shape=\"bar\""), 3u);
  // the last row: its parts come before its sketch (drawn under it)
  const std::string last = s.substr(s.rfind("<g class=\"position\""));
  ASSERT_LT(last.find("class=\"part\""), last.find("class=\"joint"));
  auto points = [&](const std::string& shape) {
    const std::vector<std::string> d = captures(last, "data-shape=\"" + shape + "\" d=\"([^\"]+)\"");
    EXPECT_EQ(d.size(), 1u) << shape;
    std::vector<std::array<double, 2>> p;
    const std::regex num("[ML](-?[0-9.]+) (-?[0-9.]+)");
    for (auto it = std::sregex_iterator(d[0].begin(), d[0].end(), num); it != std::sregex_iterator(); ++it)
      p.push_back({std::stod((*it)[1]), std::stod((*it)[2])});
    return p;
  };
  const auto bar = points("bar"), hub = points("hub"), plate = points("plate"), slot = points("slot");
  ASSERT_EQ(bar.size(), 4u);
  const double side0 = std::hypot(bar[1][0] - bar[0][0], bar[1][1] - bar[0][1]),
               side1 = std::hypot(bar[2][0] - bar[1][0], bar[2][1] - bar[1][1]);
  EXPECT_NEAR(std::max(side0, side1) / std::min(side0, side1), 8.0, 0.1);
  // the bar's centre is the crank's reference point, midway between its pins O and A (the first two joints)
  const std::vector<std::string> cx = captures(last, "class=\"joint revolute\" cx=\"([0-9.]+)\""),
                                 cy = captures(last, "class=\"joint revolute\" cx=\"[0-9.]+\" cy=\"([0-9.]+)\"");
  ASSERT_GE(cx.size(), 2u);
  EXPECT_NEAR((bar[0][0] + bar[2][0]) / 2, (std::stod(cx[0]) + std::stod(cx[1])) / 2, 0.15);
  EXPECT_NEAR((bar[0][1] + bar[2][1]) / 2, (std::stod(cy[0]) + std::stod(cy[1])) / 2, 0.15);
  // the hub seen along z: 32 points at one distance from their centre, the pin A's
  ASSERT_EQ(hub.size(), 32u);
  double mx = 0, my = 0;
  for (const auto& p : hub) mx += p[0] / 32, my += p[1] / 32;
  for (const auto& p : hub)
    EXPECT_NEAR(std::hypot(p[0] - mx, p[1] - my), side0 < side1 ? side0 * 0.6 : side1 * 0.6, 0.2);
  EXPECT_EQ(plate.size(), 3u);
  EXPECT_EQ(slot.size(), 2u);
  EXPECT_NE(last.find("data-shape=\"plate\" d=\"" + captures(last, "data-shape=\"plate\" d=\"([^\"]+)\"")[0] +
                      "\" fill=\"#e6801a\""),
            std::string::npos);
  // the slot: a stroke as wide as 0.02 m is in pixels (the bar's 0.05 m side)
  const std::vector<std::string> width =
      captures(last, "data-shape=\"slot\" d=\"[^\"]+\" fill=\"none\"[^>]*stroke-width=\"([0-9.]+)\"");
  ASSERT_EQ(width.size(), 1u);
  EXPECT_NEAR(std::stod(width[0]), 0.4 * std::min(side0, side1), 0.15);
}

TEST_F(Cli, PlotRefusesAColumnWithNaNInOneLine) {
  const std::string scene = phiq::test::model_path("seed/fourbar_natural.yaml");
  const fs::path csv = dir_ / "r.csv", svg = dir_ / "p.svg";
  ASSERT_EQ(run("run -q " + scene + " -o " + csv.string()).code, 0);
  const fs::path bad = write("bad.csv", phiq::test::with_nan_xA(slurp(csv)));
  const Result r = run("plot " + scene + " " + bad.string() + " -o " + svg.string() + " --columns xA");
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(phiq::test::one_phiq_line(r.err));
  EXPECT_NE(r.err.find("column 'xA', data row 2: nan"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(svg));
}

TEST_F(Plot, DriverEffortsGetAPanelPerUnitByDefault) {
  // the motor's torque and power after the angle it drives: one panel each, in N·m and W
  const std::string s = plot("dynamics/fourbar_motor_torque.yaml");
  EXPECT_EQ(captures(s, "data-quantity=\"([^\"]+)\""), (std::vector<std::string>{"angle", "torque", "power"}));
  EXPECT_EQ(captures(s, "data-unit=\"([^\"]+)\""), (std::vector<std::string>{"rad", "N·m", "W"}));
  const auto [lo, hi] = range("motor.effort");
  EXPECT_GT(hi - lo, 1.0);  // newton-metres that change over the turn
  EXPECT_EQ(count(s, "class=\"limit\""), 0u);
}

TEST_F(Plot, LossesGetAPanelPerUnit) {
  // two bearings' friction moments in one N·m panel, a bearing's dissipated power in a W one
  const std::string s =
      plot("dynamics/fourbar_pin_friction.yaml", " --columns O_bearing.friction O_bearing.loss C_bearing.friction");
  EXPECT_EQ(captures(s, "data-quantity=\"([^\"]+)\""), (std::vector<std::string>{"torque", "power"}));
  EXPECT_EQ(captures(s, "data-unit=\"([^\"]+)\""), (std::vector<std::string>{"N·m", "W"}));
  EXPECT_GT(range("O_bearing.friction").second, 0.1);
}

TEST_F(Plot, ALimitsEndsAreDashedAcrossItsColumnsPanel) {
  // models/dynamics/fourbar_gearmotor.yaml's rated torque, ±25 N·m, on the motor's effort (its rocker's swing, an
  // expression, has no column): two dashed lines spanning the torque panel, at ±25 on its scale
  const std::string s = plot("dynamics/fourbar_gearmotor.yaml");
  EXPECT_EQ(captures(s, "class=\"limit\"[^>]*data-limit=\"([^\"]+)\""),
            (std::vector<std::string>{"rated_torque", "rated_torque"}));
  EXPECT_EQ(captures(s, "class=\"limit\"[^>]*data-value=\"([^\"]+)\""), (std::vector<std::string>{"-25", "25"}));
  const std::vector<std::string> y = captures(s, "class=\"limit\"[^>]*points=\"[0-9.]+,([0-9.]+) ");
  ASSERT_EQ(y.size(), 2u);
  EXPECT_GT(std::stod(y[0]), std::stod(y[1]));  // −25 below +25 (SVG's y grows downward)
}

}  // namespace
