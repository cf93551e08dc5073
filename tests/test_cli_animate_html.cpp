// `phiq animate SCENE RESULT -o OUT.html` (tools/animate/html_motion.*, html_page.*): the page's data decode to the
// result's positions and velocities at every row it keeps (to the 16-bit quantization's half step), the rows kept
// fit the frame budget, first and last included; the plots are `phiq plot`'s columns; the page fetches nothing;
// bad input is one line, exit 2, no file written or damaged. The page in a browser: ctest browser_viewer.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "phiq/drawn_parts.hpp"
#include "phiq/hdf5_reader.hpp"
#include "phiq/phiq.hpp"

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::count;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

// The viewer's data: the JSON of <script id="phiq-data">.
nlohmann::json page_data(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"phiq-data\">";
  const std::size_t a = html.find(open);
  EXPECT_NE(a, std::string::npos);
  const std::size_t b = html.find("</script>", a);
  return nlohmann::json::parse(html.substr(a + open.size(), b - a - open.size()));
}

// base64 of little-endian int16 codes onto [lo, hi] per component, as viewer.js decode() reads them.
std::vector<double> decode(const std::string& b64, const std::vector<double>& lo, const std::vector<double>& hi) {
  std::string bytes;
  int bits = 0, value = 0;
  for (char c : b64) {
    const std::string a = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    if (c == '=') break;
    value = (value << 6) | static_cast<int>(a.find(c));
    if ((bits += 6) >= 8) bytes += static_cast<char>((value >> (bits -= 8)) & 255);
  }
  std::vector<double> out;
  for (std::size_t i = 0; i + 1 < bytes.size(); i += 2) {
    const auto code = static_cast<std::int16_t>(static_cast<unsigned char>(bytes[i]) |
                                                (static_cast<unsigned char>(bytes[i + 1]) << 8));
    const std::size_t c = out.size() % lo.size();
    out.push_back(lo[c] + (code + 32767) * (hi[c] - lo[c]) / 65534);
  }
  return out;
}

class AnimateHtml : public Cli {
 protected:
  // Runs the scene, animates it to an HTML page (extra options appended), reads the result and the page's data.
  std::string animate(const std::string& scene, const std::string& extra = "") {
    const fs::path res = dir_ / "result.csv", html = dir_ / "motion.html";
    EXPECT_EQ(run("run -q " + scene + " -o " + res.string()).code, 0);
    const Result r = run("animate " + scene + " " + res.string() + " -o " + html.string() + " " + extra);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err, "");
    table = phiq::read_result_table(res.string());
    for (std::size_t c = 0; c < table.columns.size(); ++c) col[table.columns[c]] = c;
    const std::string text = slurp(html);
    data = page_data(text);
    return text;
  }
  double at(std::size_t row, const std::string& name) { return table.rows[row][col.at(name)]; }
  // The page's force arrows (`arrows` of them, each over `rows` rows) are `world`'s, to 1e-9, and with `points` at
  // the same points: what a scene written in joint axes draws in world axes all the same.
  void expect_arrows(const nlohmann::json& world, std::size_t arrows, std::size_t rows, bool points) {
    for (std::size_t a = 0; a < arrows; ++a)
      for (std::size_t i = 0; i < 3 * rows; ++i) {
        const double w = world[a]["force"][i], j = data["forces"]["arrows"][a]["force"][i];
        EXPECT_NEAR(j, w, 1e-9 * (1.0 + std::fabs(w))) << a << " " << i;
        if (points) EXPECT_EQ(world[a]["at"][i], data["forces"]["arrows"][a]["at"][i]) << a << " " << i;
      }
  }
  phiq::CsvTable table;
  std::map<std::string, std::size_t> col;
  nlohmann::json data;
};

TEST_F(AnimateHtml, PlanarPointsAndVelocitiesAreTheResultsAtEveryRow) {
  const std::string html = animate(phiq::test::model_path("seed/fourbar_natural.yaml"));
  // the points of the sketch: O, A, B, C (the ends of the three bars), each once; O and C fixed
  ASSERT_EQ(data["dimension"], 2);
  ASSERT_EQ(data["points"], 4);
  EXPECT_EQ(data["moving"], "0110");
  EXPECT_EQ(data["links"], nlohmann::json({0, 1, 1, 2, 3, 2}));  // crank O-A, coupler A-B, rocker C-B
  EXPECT_EQ(data["joints"]["marks"], "oooo");
  EXPECT_EQ(data["joints"]["fixed"], "1001");
  // every row a frame (361 rows fit the budget many times over)
  const std::size_t rows = table.rows.size();
  ASSERT_EQ(data["kept"].size(), rows);
  const std::vector<double> lo = data["lo"], hi = data["hi"];
  const std::vector<double> pos = decode(data["frames"], lo, hi);
  ASSERT_EQ(pos.size(), rows * 4 * 2);
  const double vmax = data["vmax"];
  const std::vector<double> vel = decode(data["velocities"], {-vmax, -vmax}, {vmax, vmax});
  ASSERT_EQ(vel.size(), pos.size());
  // half a quantization step, and float rounding of the limits
  const double tol_x = 0.5 * (hi[0] - lo[0]) / 65534 + 1e-12, tol_y = 0.5 * (hi[1] - lo[1]) / 65534 + 1e-12;
  const double tol_v = vmax / 65534 + 1e-12;
  for (std::size_t k = 0; k < rows; ++k) {
    EXPECT_EQ(data["t"][k].get<double>(), at(k, "t"));
    const double* p = &pos[k * 8];
    EXPECT_NEAR(p[0], 0.0, tol_x);
    EXPECT_NEAR(p[1], 0.0, tol_y);  // O
    EXPECT_NEAR(p[2], at(k, "xA"), tol_x);
    EXPECT_NEAR(p[3], at(k, "yA"), tol_y);
    EXPECT_NEAR(p[4], at(k, "xB"), tol_x);
    EXPECT_NEAR(p[5], at(k, "yB"), tol_y);
    EXPECT_NEAR(p[6], 1.0, tol_x);
    EXPECT_NEAR(p[7], 0.0, tol_y);  // C
    const double* v = &vel[k * 8];
    EXPECT_NEAR(v[2], at(k, "xA.v"), tol_v);
    EXPECT_NEAR(v[3], at(k, "yA.v"), tol_v);
    EXPECT_NEAR(v[4], at(k, "xB.v"), tol_v);
    EXPECT_NEAR(v[5], at(k, "yB.v"), tol_v);
    EXPECT_EQ(v[0], 0.0);
  }
  // the extent holds the points and the drawn links about them: the crank tip reaches x = -0.4, its link's box
  // (radius r about the bar) r beyond at the least, r √2 (a corner turned 45°) at the most
  const nlohmann::json& parts = data["parts"];
  ASSERT_EQ(parts["names"], nlohmann::json({"crank", "coupler", "rocker"}));
  double r = 0.0;
  for (const double c : parts["geometries"][parts["geometry"][0].get<int>()][0]["outline"]) r = std::max(r, -c);
  const phiq::Scene scene = phiq::load_scene(phiq::test::model_path("seed/fourbar_natural.yaml"));
  EXPECT_NEAR(r, scene.model->length_scale() / 50, 1e-12);  // a derived link's radius (drawn_parts.cpp)
  EXPECT_LE(lo[0], -0.4 - r);
  EXPECT_GE(lo[0], -0.4 - r * std::sqrt(2.0) - 1e-12);
  // phiq plot's default columns, with their panels; the planar view's background with its hatched ground pivots
  EXPECT_EQ(count(html, "class=\"panel\""), 2u);  // angle (theta2) and length (xA, yA, xB, yB)
  for (const char* c : {"theta2", "xA", "yA", "xB", "yB"})
    EXPECT_EQ(count(html, std::string("data-column=\"") + c + "\""), 1u) << c;
  EXPECT_EQ(count(html, "<use class=\"ground\" href=\"#ground-pivot\""), 2u);
  // self-contained: no script, style or image fetched (the SVG namespace is a name, not a request)
  EXPECT_EQ(count(html, "<script src"), 0u);
  EXPECT_EQ(count(html, "<link"), 0u);
  EXPECT_EQ(count(html, "http"), count(html, "http://www.w3.org/2000/svg"));
  EXPECT_EQ(count(html, "THREE.WebGLRenderer"), 0u);  // three.js only where it draws: the spatial view
}

TEST_F(AnimateHtml, ColumnsAsAskedAndSpatialScenesInWebGl) {
  const std::string html = animate(phiq::test::model_path("spatial/rssr.yaml"), "--columns crank_e0,rocker_e3");
  EXPECT_EQ(data["dimension"], 3);
  EXPECT_EQ(count(html, "data-column="), 2u);
  EXPECT_EQ(count(html, "data-column=\"crank_e0\""), 1u);
  EXPECT_EQ(count(html, "data-column=\"rocker_e3\""), 1u);
  // three.js r111 and its orbit controls, inlined; the WebGL host instead of the planar SVG
  EXPECT_EQ(count(html, "REVISION=\"111\""), 1u);
  EXPECT_EQ(count(html, "OrbitControls = function"), 1u);
  EXPECT_EQ(count(html, "<div id=\"gl\">"), 1u);
  EXPECT_EQ(count(html, "id=\"mechanism-svg\""), 0u);
  EXPECT_EQ(count(html, "<script src"), 0u);
  const std::vector<double> lo = data["lo"], hi = data["hi"];
  EXPECT_EQ(lo.size(), 3u);
  EXPECT_EQ(decode(data["frames"], lo, hi).size(), table.rows.size() * data["points"].get<std::size_t>() * 3);
}

TEST_F(AnimateHtml, ForceArrowsHoldTheResultsEffortsAndReactionsAtTheirJoints) {
  // the four-bar of models/dynamics with its pins' loads: an arrow per pin (O, A, B, C) and the motor's torque at
  // the crank's ground pin O, the values the result's columns at every kept row, each pin's point where it is
  std::string text = slurp(phiq::test::model_path("dynamics/fourbar_pin_loads.yaml"));
  text.erase(text.find("output:"));  // every coordinate written: the drawing reads them from the result
  const fs::path scene = write("pins.yaml", text + "output: {efforts: all, reactions: all}\n");
  const std::string html = animate(scene.string(), "--forces 0.05");
  const nlohmann::json& f = data["forces"];
  EXPECT_EQ(f["scale"], 0.05);
  EXPECT_EQ(f["unplaced"].size(), 0u);
  ASSERT_EQ(f["arrows"].size(), 5u);
  const std::size_t rows = table.rows.size();
  ASSERT_EQ(data["kept"].size(), rows);
  const double l2 = 0.4;
  for (std::size_t a = 0; a < 5; ++a) {
    const nlohmann::json& arrow = f["arrows"][a];
    const std::string name = arrow["name"];
    EXPECT_EQ(name, a < 4 ? std::string(1, "OABC"[a]) : "motor");
    EXPECT_EQ(arrow["kind"], a < 4 ? "reaction" : "effort");
    ASSERT_EQ(arrow["at"].size(), 3 * rows);
    for (std::size_t k = 0; k < rows; ++k) {
      if (a < 4) {
        EXPECT_EQ(arrow["force"][3 * k].get<double>(), at(k, name + ".Fx")) << name << " " << k;
        EXPECT_EQ(arrow["force"][3 * k + 1].get<double>(), at(k, name + ".Fy")) << name << " " << k;
        EXPECT_EQ(arrow["moment"][3 * k + 2].get<double>(), at(k, name + ".Mz")) << name << " " << k;
      } else {
        EXPECT_EQ(arrow["moment"][3 * k + 2].get<double>(), at(k, "motor.effort")) << k;
        EXPECT_EQ(arrow["force"][3 * k].get<double>(), 0.0);
      }
      const double x = arrow["at"][3 * k], y = arrow["at"][3 * k + 1];
      if (a == 0 || a == 4) {  // O: the ground pin at the origin
        EXPECT_NEAR(x, 0.0, 1e-9);
        EXPECT_NEAR(y, 0.0, 1e-9);
      } else if (a == 1) {  // A: the crank's tip, L2 from O at the crank's angle
        EXPECT_NEAR(x, l2 * std::cos(at(k, "psi2")), 1e-9);
        EXPECT_NEAR(y, l2 * std::sin(at(k, "psi2")), 1e-9);
      } else if (a == 3) {  // C: the rocker's ground pin
        EXPECT_NEAR(x, 1.0, 1e-9);
        EXPECT_NEAR(y, 0.0, 1e-9);
      }
    }
  }
  EXPECT_EQ(count(html, "id=\"forces\""), 1u);  // the page's check box
  // the loads written along each pin's body (output.reaction_axes: joint) are drawn in world axes all the same
  const nlohmann::json world = f["arrows"];
  std::vector<double> world_a;
  for (std::size_t k = 0; k < rows; ++k) world_a.push_back(at(k, "A.Fx"));
  animate(write("turned.yaml", text + "output: {efforts: all, reactions: all, reaction_axes: joint}\n").string(),
          "--forces 0.05");
  ASSERT_EQ(table.rows.size(), rows);
  double turned = 0.0;  // how far the columns moved: they are along the crank's axes now
  for (std::size_t k = 0; k < rows; ++k) turned = std::max(turned, std::fabs(at(k, "A.Fx") - world_a[k]));
  EXPECT_GT(turned, 1.0);
  expect_arrows(world, 4, rows, false);
  // asked for where the scene writes no efforts or reactions, or with a scale that is not positive: one line, exit 2
  const Result none = run("animate " + phiq::test::model_path("seed/fourbar_natural.yaml") + " -o " +
                          (dir_ / "n.html").string() + " --forces 0.1");
  EXPECT_EQ(none.code, 2);
  EXPECT_NE(none.err.find("--forces draws the efforts and reactions the scene writes"), std::string::npos) << none.err;
  const Result negative = run("animate " + phiq::test::model_path("seed/fourbar_natural.yaml") + " -o " +
                              (dir_ / "n.html").string() + " --forces -1");
  EXPECT_EQ(negative.code, 2);
  EXPECT_NE(negative.err.find("a positive number of metres per newton"), std::string::npos) << negative.err;
  EXPECT_FALSE(fs::exists(dir_ / "n.html"));
}

// Natural joints written along their bodies' axes (a bar's length and across it) are drawn in world axes too: the
// four-bar of models/dynamics/fourbar_motor_torque.yaml, its shared points O, A, B, C.
TEST_F(AnimateHtml, ForceArrowsOfNaturalJointsAreTheSameInBothAxes) {
  std::string text = slurp(phiq::test::model_path("dynamics/fourbar_motor_torque.yaml"));
  text.erase(text.find("output:"));
  animate(write("natural.yaml", text + "output: {reactions: all}\n").string(), "--forces 0.05");
  const nlohmann::json world = data["forces"]["arrows"];
  ASSERT_EQ(world.size(), 4u);
  const std::size_t rows = table.rows.size();
  std::vector<double> world_b;
  for (std::size_t k = 0; k < rows; ++k) world_b.push_back(at(k, "B.Fy"));
  animate(write("natural_turned.yaml", text + "output: {reactions: all, reaction_axes: joint}\n").string(),
          "--forces 0.05");
  ASSERT_EQ(table.rows.size(), rows);
  double turned = 0.0;  // the columns moved: along the coupler's axes now
  for (std::size_t k = 0; k < rows; ++k) turned = std::max(turned, std::fabs(at(k, "B.Fy") - world_b[k]));
  EXPECT_GT(turned, 1.0);
  expect_arrows(world, 4, rows, true);
}

TEST_F(AnimateHtml, LargeChainsKeepEvenlySpreadRowsWithinTheBudget) {
  constexpr std::size_t kFrameBudget = std::size_t{8} << 20;  // tools/animate/html_motion.hpp (in the phiq program)
  const fs::path scene = dir_ / "chain.yaml";
  ASSERT_EQ(run("generate nfourbar 2000 --steps 300 --outputs q,v -o " + scene.string()).code, 0);
  const std::string html = animate(scene.string());
  const std::size_t rows = table.rows.size(), points = data["points"];
  ASSERT_EQ(rows, 301u);
  EXPECT_EQ(points, 2u * 2001);  // the crank pivots (i, 0) and the tips P_i (the driving angle's O is the pivot (0, 0))
  // a drawn part per crank, coupler and rocker, and the ground's pins
  const std::size_t parts = data["parts"]["names"].size();
  EXPECT_EQ(parts, phiq::drawn_parts(phiq::load_scene(scene.string())).size());
  // bytes of a frame: positions and velocities, 2 bytes a component, and the parts' poses (origin and quaternion),
  // base64; the rows kept are as many as fit kFrameBudget
  const std::size_t per_frame = (points * 2 * 2 * 2 * 4 + parts * 7 * 2 * 4 + 2) / 3, most = kFrameBudget / per_frame;
  ASSERT_LT(most, rows);
  const std::vector<std::size_t> kept = data["kept"];
  ASSERT_EQ(kept.size(), most);
  for (std::size_t k = 0; k < most; ++k)
    EXPECT_EQ(kept[k], static_cast<std::size_t>(std::llround(k * 300.0 / (most - 1))));
  const std::size_t frames = data["frames"].get<std::string>().size(),
                    velocities = data["velocities"].get<std::string>().size(),
                    poses = data["parts"]["poses"].get<std::string>().size();
  EXPECT_EQ(frames, (most * points * 2 * 2 + 2) / 3 * 4);
  EXPECT_EQ(velocities, frames);
  EXPECT_EQ(poses, (most * parts * 7 * 2 + 2) / 3 * 4);
  EXPECT_LE(frames + velocities + poses, kFrameBudget + 12);  // base64's padding, one per string
  EXPECT_LT(html.size(), std::size_t{10} << 20);
}

TEST_F(Cli, AnimateHtmlRefusesBadInputInOneLine) {
  const std::string nat = phiq::test::model_path("seed/fourbar_natural.yaml");
  const fs::path csv = dir_ / "nat.csv", html = dir_ / "m.html";
  ASSERT_EQ(run("run -q " + nat + " -o " + csv.string()).code, 0);
  auto refused = [&](const std::string& args, const std::string& message, const fs::path& out) {
    const Result r = run("animate " + nat + " " + args + " -o " + out.string());
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_TRUE(phiq::test::one_phiq_line(r.err)) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
  };
  refused(csv.string() + " --columns theta2,nope", "--columns: no column 'nope'", html);
  EXPECT_FALSE(fs::exists(html));
  const fs::path bad = write("bad.csv", phiq::test::with_nan_xA(slurp(csv)));
  refused(bad.string(), "data row 2, column 'xA': not a finite number", html);
  EXPECT_FALSE(fs::exists(html));
  refused(csv.string() + " --columns xA", "--columns: the plots are the HTML viewer's", dir_ / "m.glb");
  EXPECT_FALSE(fs::exists(dir_ / "m.glb"));
  refused(csv.string(), "*.glb", dir_ / "m.txt");
  EXPECT_FALSE(fs::exists(dir_ / "m.txt"));
  // a good page already there is kept as it was
  ASSERT_EQ(run("animate " + nat + " " + csv.string() + " -o " + html.string()).code, 0);
  const std::string good = slurp(html);
  refused(bad.string(), "column 'xA'", html);
  EXPECT_EQ(slurp(html), good);
  EXPECT_EQ(files(), (std::vector<std::string>{"bad.csv", "m.html", "nat.csv", "stderr.txt", "stdout.txt"}));
}

}  // namespace
