// `phiq animate SCENE -o OUT` without a result (the scene swept in memory with the outputs the drawing needs: the
// same rows as `phiq run`, to the bit), the one line naming the output to add when a result lacks a coordinate the
// drawing reads, a cam with a roller follower animated by its joints, and results of another scene refused by what
// an HDF5 file records and by a CSV's columns.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "phiq/csv_compare.hpp"
#include "phiq/drawn_parts.hpp"
#include "phiq/phiq.hpp"

#include "cli_test_support.hpp"
#include "glb_reader.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

// The viewer's data: the JSON of <script id="phiq-data">.
nlohmann::json viewer_data(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"phiq-data\">";
  const std::size_t a = html.find(open);
  EXPECT_NE(a, std::string::npos);
  const std::size_t b = html.find("</script>", a);
  return nlohmann::json::parse(html.substr(a + open.size(), b - a - open.size()));
}

// The planetary train with every coordinate written (its own output lists the four angles only).
std::string planetary_with_every_coordinate() {
  std::string text = slurp(phiq::test::model_path("transmissions/planetary.yaml"));
  const std::string listed = "  coordinates: [psis, psic, psip, psir]\n";
  const std::size_t at = text.find(listed);
  EXPECT_NE(at, std::string::npos);
  return text.erase(at, listed.size());
}

// Without a result the sweep runs here: its rows are `phiq run`'s, bit for bit, so the .glb (every keyframe) and the
// page's data (positions, velocities, their exact extent) equal those drawn from a run that writes every coordinate.
TEST_F(Cli, AnimateWithoutAResultDrawsTheRunsRowsToTheBit) {
  const std::string planetary = phiq::test::model_path("transmissions/planetary.yaml");
  const fs::path every = write("every.yaml", planetary_with_every_coordinate()), csv = dir_ / "every.csv";
  ASSERT_EQ(run("run -q " + every.string() + " -o " + csv.string()).code, 0);
  Result r = run("animate " + planetary + " -o " + (dir_ / "a.glb").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  ASSERT_EQ(run("animate " + every.string() + " " + csv.string() + " -o " + (dir_ / "b.glb").string()).code, 0);
  const std::string a = slurp(dir_ / "a.glb");
  EXPECT_EQ(a, slurp(dir_ / "b.glb"));
  // and those keyframes are the run's values: the carrier's translation, the planet's turn
  const phiq::CsvTable table = phiq::read_csv_table(csv.string());
  std::map<std::string, std::size_t> col;
  for (std::size_t c = 0; c < table.columns.size(); ++c) col[table.columns[c]] = c;
  const phiq::test::Glb g = phiq::test::parse_glb(a);
  const auto [tin, planet_t] = g.channel(g.node("planet"), "translation");
  const auto [rin, planet_r] = g.channel(g.node("planet"), "rotation");
  ASSERT_GE(planet_t, 0);
  ASSERT_GE(planet_r, 0);
  ASSERT_EQ(g.doc["accessors"][planet_t]["count"], table.rows.size());
  ASSERT_EQ(table.rows.size(), 141u);
  for (std::size_t k = 0; k < table.rows.size(); ++k) {
    const auto& row = table.rows[k];
    EXPECT_EQ(g.floats(tin, k)[0], static_cast<float>(row[col.at("t")]));
    EXPECT_EQ(g.floats(planet_t, k)[0], static_cast<float>(row[col.at("xp")])) << k;
    EXPECT_EQ(g.floats(planet_t, k)[1], static_cast<float>(row[col.at("yp")])) << k;
    EXPECT_EQ(g.floats(planet_r, k)[2], static_cast<float>(std::sin(row[col.at("psip")] / 2))) << k;
  }
  // the page: the same data as from the result, whose name alone differs (in the velocity note and the caption)
  r = run("animate " + planetary + " -o " + (dir_ / "a.html").string());
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_EQ(run("animate " + every.string() + " " + csv.string() + " -o " + (dir_ / "b.html").string()).code, 0);
  const nlohmann::json da = viewer_data(slurp(dir_ / "a.html")), db = viewer_data(slurp(dir_ / "b.html"));
  for (const char* field : {"t", "kept", "lo", "hi", "frames", "velocities", "vmax", "points", "moving", "traces"})
    EXPECT_EQ(da[field], db[field]) << field;
  EXPECT_EQ(da["rows"], 141);
  EXPECT_NE(slurp(dir_ / "a.html").find(planetary + ", its sweep: 141 rows"), std::string::npos);
}

// The result of the scene's own run that leaves out a coordinate the drawing reads: one line that names the
// coordinate, the scene field to add it to, and the command that needs no result; no file written or damaged.
TEST_F(Cli, AnimateNamesTheOutputToAddInOneLine) {
  const std::string planetary = phiq::test::model_path("transmissions/planetary.yaml");
  const fs::path csv = dir_ / "pl.csv";
  ASSERT_EQ(run("run -q " + planetary + " -o " + csv.string()).code, 0);
  // both read the drawn parts' frames, the bodies' (the sun's first) before the sketch's points (the carrier's arm)
  for (const auto& [out, coordinate] : {std::pair<std::string, std::string>{"pl.html", "xs"}, {"pl.glb", "xs"}}) {
    const fs::path target = dir_ / out;
    const Result r = run("animate " + planetary + " " + csv.string() + " -o " + target.string());
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(r.err, "phiq: animate: " + csv.string() + " lacks coordinate '" + coordinate +
                         "': add it to output.coordinates in " + planetary + ", or run `phiq animate " + planetary +
                         " -o " + target.string() + "` without a result\n");
    EXPECT_FALSE(fs::exists(target));
  }
  // with --set, the command to run again repeats it; a good page already there is kept
  const fs::path page = dir_ / "pl.html";
  ASSERT_EQ(run("animate " + planetary + " -o " + page.string() + " --set m=0.005").code, 0);
  const std::string good = slurp(page);
  const Result r = run("animate " + planetary + " " + csv.string() + " -o " + page.string() + " --set m=0.005");
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(phiq::test::one_phiq_line(r.err));
  EXPECT_NE(r.err.find("or run `phiq animate " + planetary + " -o " + page.string() + " --set m=0.005` without"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(slurp(page), good);
  // the larger module moves the planet's centre out: the sweep ran with it (arm = m (24 + 18) / 2, the farthest
  // part origin); the drawing reaches the ring's pitch circle (m 60 / 2) and the half width of its line
  const nlohmann::json d = viewer_data(good);
  EXPECT_NEAR(d["parts"]["hi"][0].get<double>(), 0.005 * 21, 1e-12);
  const nlohmann::json& parts = d["parts"];
  const nlohmann::json& ring = parts["geometries"][parts["geometry"][3].get<int>()];
  ASSERT_EQ(parts["names"][3], "ring");
  ASSERT_EQ(ring.size(), 2u);
  ASSERT_EQ(parts["shapes"][3][1], "planet_ring.pitch_circle");
  EXPECT_NEAR(d["hi"][0].get<double>(), 0.005 * 30 + ring[1]["width"].get<double>() / 2, 1e-12);
}

// A cam with a roller follower draws no line, only its joints (the disc's bearing on ground, the rod's block on
// its guide) over its parts: the joints are its points, the block at the rod's (xf, yf) of every row.
TEST_F(Cli, AnimateACamWithARollerFollowerByItsJoints) {
  const std::string cam = phiq::test::model_path("cams/eccentric_roller.yaml");
  const fs::path csv = dir_ / "cam.csv", html = dir_ / "cam.html";
  ASSERT_EQ(run("run -q " + cam + " -o " + csv.string()).code, 0);
  const Result r = run("animate " + cam + " " + csv.string() + " -o " + html.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const nlohmann::json d = viewer_data(slurp(html));
  ASSERT_EQ(d["points"], 2);
  EXPECT_EQ(d["moving"], "01");
  EXPECT_EQ(d["joints"]["marks"], "rp");
  EXPECT_EQ(d["joints"]["p"], nlohmann::json({0, 1}));
  const phiq::CsvTable table = phiq::read_csv_table(csv.string());
  ASSERT_EQ(d["kept"].size(), table.rows.size());
  // the extent of y: the drawn parts' (the disc's profile, the rod's roller, the guide on ground) at every row, each
  // the tighter of its box's (its shapes' vertices in its frame) posed corners and its origin ± its farthest vertex;
  // the guide reaches above the roller
  double top = 0.0;
  for (const auto& row : table.rows) top = std::max(top, row[5]);
  ASSERT_EQ(table.columns[5], "yf");
  const phiq::Scene scene = phiq::load_scene(cam);
  const std::vector<phiq::Part> parts = phiq::drawn_parts(scene);
  ASSERT_EQ(parts.size(), 3u);
  double lowest = INFINITY, highest = -INFINITY;
  for (const phiq::Part& part : parts) {
    phiq::kin3::V3 a{INFINITY, INFINITY, INFINITY}, b{-INFINITY, -INFINITY, -INFINITY};
    double reach = 0.0;
    for (const phiq::Shape& shape : part.shapes)
      for (const phiq::kin3::V3& v : phiq::shape_triangles(shape, 8).vertices) {
        a = {std::min(a.x, v.x), std::min(a.y, v.y), std::min(a.z, v.z)};
        b = {std::max(b.x, v.x), std::max(b.y, v.y), std::max(b.z, v.z)};
        reach = std::max(reach, std::hypot(v.x, v.y, v.z));
      }
    for (const auto& row : table.rows) {
      Eigen::VectorXd q = scene.model->initial_positions();
      for (std::size_t c = 1; c < 7; ++c) q(scene.model->find_coordinate(table.columns[c])) = row[c];
      const phiq::Pose pose = phiq::part_pose(part.frame, q.data(), row[0]);
      double down = INFINITY, up = -INFINITY;
      for (int k = 0; k < 8; ++k) {
        const double y = pose.apply({k & 1 ? b.x : a.x, k & 2 ? b.y : a.y, k & 4 ? b.z : a.z}).y;
        down = std::min(down, y), up = std::max(up, y);
      }
      lowest = std::min(lowest, std::max(down, pose.at.y - reach));
      highest = std::max(highest, std::min(up, pose.at.y + reach));
    }
  }
  const double lo = d["lo"][1], hi = d["hi"][1];
  EXPECT_EQ(lo, lowest);
  EXPECT_EQ(hi, highest);
  EXPECT_GT(hi, top + 0.01);  // above the roller (rho = 0.01) at the rod's highest
  // the block at (xf, yf) of every row, decoded to the quantization's step over [lo, hi]
  const std::string b64 = d["frames"];
  std::string bytes;
  int bits = 0, value = 0;
  const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  for (char c : b64) {
    if (c == '=') break;
    value = (value << 6) | static_cast<int>(alphabet.find(c));
    if ((bits += 6) >= 8) bytes += static_cast<char>((value >> (bits -= 8)) & 255);
  }
  ASSERT_EQ(bytes.size(), table.rows.size() * 2 * 2 * 2);
  for (std::size_t k = 0; k < table.rows.size(); ++k) {
    const std::size_t at = k * 8 + 6;  // row k, point 1, y
    const auto code = static_cast<std::int16_t>(static_cast<unsigned char>(bytes[at]) |
                                                (static_cast<unsigned char>(bytes[at + 1]) << 8));
    EXPECT_NEAR(lo + (code + 32767) * (hi - lo) / 65534, table.rows[k][5], 0.5 * (hi - lo) / 65534 + 1e-15) << k;
  }
  // without a result: the same page data
  ASSERT_EQ(run("animate " + cam + " -o " + (dir_ / "swept.html").string()).code, 0);
  EXPECT_EQ(viewer_data(slurp(dir_ / "swept.html"))["frames"], d["frames"]);
}

// A result of another scene: an HDF5 file by the scene text and parameters it records, a CSV by its columns (here
// one more than the scene writes, which the check of missing columns alone let through). One line naming both.
TEST_F(Cli, AnimateRefusesAResultOfAnotherSceneByItsRecordAndColumns) {
  const std::string rssr = phiq::test::model_path("spatial/rssr.yaml"),
                    cardan = phiq::test::model_path("spatial/cardan.yaml");
  const fs::path h5 = dir_ / "rssr.h5", glb = dir_ / "m.glb";
  ASSERT_EQ(run("run -q " + rssr + " -o " + h5.string()).code, 0);
  auto refused = [&](const std::string& args, const std::vector<std::string>& says) {
    const Result r = run("animate " + args + " -o " + glb.string());
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_TRUE(phiq::test::one_phiq_line(r.err)) << r.err;
    for (const std::string& s : says) EXPECT_NE(r.err.find(s), std::string::npos) << s << " in " << r.err;
    EXPECT_FALSE(fs::exists(glb));
  };
  refused(cardan + " " + h5.string(),
          {h5.string() + ": not a result of " + cardan, "it records the scene " + rssr + ", whose text differs"});
  // the same file name with another text; the same text with other parameters
  const std::string text = slurp(rssr);
  const fs::path scene = write("s.yaml", text), mine = dir_ / "s.h5";
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + mine.string()).code, 0);
  ASSERT_EQ(run("animate " + scene.string() + " " + mine.string() + " -o " + glb.string()).code, 0);
  fs::remove(glb);
  refused(scene.string() + " " + mine.string() + " --set L=0.93",
          {mine.string() + ": not a result of " + scene.string() + " with L = 0.93: it was run with L = 0.92",
           "--set L=0.92"});
  write("s.yaml", text + "# edited after the run\n");
  refused(scene.string() + " " + mine.string(), {"it records another text of that scene"});
  // a CSV of a four-bar that also traces a point, given the four-bar that does not
  const std::string nat = phiq::test::model_path("seed/fourbar_natural.yaml");
  std::string traced = slurp(nat);
  traced.replace(traced.find("output: {"), std::string("output: {").size(), "output: {points: [B], ");
  const fs::path traced_scene = write("traced.yaml", traced), csv = dir_ / "traced.csv";
  Result r = run("run -q " + traced_scene.string() + " -o " + csv.string());
  ASSERT_EQ(r.code, 0) << r.err;
  refused(nat + " " + csv.string(),
          {csv.string() + ": its columns are not the output of " + nat + ": column 'B.x' is not one it writes"});
  // a run's own columns with --sensitivity and identifier names are its output still
  for (const std::string extra : {"--sensitivity L2", "--names identifiers"}) {
    r = run("run -q " + nat + " " + extra + " -o " + csv.string());
    ASSERT_EQ(r.code, 0) << r.err;
    r = run("animate " + nat + " " + csv.string() + " -o " + (dir_ / "ok.html").string());
    EXPECT_EQ(r.code, 0) << extra << ": " << r.err;
    EXPECT_TRUE(viewer_data(slurp(dir_ / "ok.html"))["velocities"].is_string()) << extra;
  }
}

}  // namespace
