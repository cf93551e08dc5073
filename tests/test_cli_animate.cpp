// `phiq animate SCENE RESULT -o OUT.glb`: the transforms of the glTF's nodes (one per drawn part) at every row
// equal the poses computed here from the result's coordinates (planar reference-point bodies, natural-coordinate
// links, spatial bodies with Euler parameters), its time accessor is the result's t, its container and accessors are
// consistent; bad input is one line, exit 2, and no file written or damaged. The Khronos validator runs on the same
// files in ctest gltf_validator.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <map>
#include <string>

#include "phiq/drawn_parts.hpp"
#include "phiq/hdf5_reader.hpp"
#include "phiq/phiq.hpp"

#include "cli_test_support.hpp"
#include "glb_reader.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::Glb;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;
using Pose = std::pair<std::array<double, 3>, std::array<double, 4>>;  // translation; rotation (x, y, z, w)

// Stored as float32: equal to the pose within its rounding (half an ulp, 2⁻²⁴ relative) and 1e-9.
bool close(double stored, double exact) {
  return std::fabs(stored - exact) <= 1e-9 + std::ldexp(std::fabs(exact), -24);
}

class Animate : public Cli {
 protected:
  // Runs the scene (result in `ext` format), animates it, and parses the .glb; `table` is the result.
  Glb animate(const std::string& model, const std::string& ext) {
    const fs::path res = dir_ / ("result" + ext), glb = dir_ / "motion.glb";
    EXPECT_EQ(run("run -q " + phiq::test::model_path(model) + " -o " + res.string()).code, 0);
    const Result r = run("animate " + phiq::test::model_path(model) + " " + res.string() + " -o " + glb.string());
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err, "");
    table = phiq::read_result_table(res.string());
    for (std::size_t c = 0; c < table.columns.size(); ++c) col[table.columns[c]] = c;
    return phiq::test::parse_glb(slurp(glb));
  }
  double at(std::size_t row, const std::string& name) { return table.rows[row][col.at(name)]; }

  // Node `name`'s translation and rotation at every row equal pose(row); `either_sign`: q and −q, the same
  // rotation, both accepted (the links' frames, whose quaternion sign is chosen for interpolation).
  template <class F>
  void expect_poses(const Glb& g, const std::string& name, F&& pose, bool either_sign = false) {
    const int n = g.node(name);
    ASSERT_GE(n, 0) << name;
    const auto [tin, tout] = g.channel(n, "translation");
    const auto [rin, rout] = g.channel(n, "rotation");
    ASSERT_GE(tout, 0) << name;
    ASSERT_GE(rout, 0) << name;
    EXPECT_EQ(g.doc["accessors"][tout]["count"], table.rows.size());
    EXPECT_EQ(g.doc["accessors"][rout]["count"], table.rows.size());
    EXPECT_EQ(tin, rin);
    for (std::size_t k = 0; k < table.rows.size(); ++k) {
      const Pose p = pose(k);
      EXPECT_FLOAT_EQ(g.floats(tin, k)[0], static_cast<float>(at(k, "t")));
      const std::vector<double> t = g.floats(tout, k), r = g.floats(rout, k);
      for (int c = 0; c < 3; ++c) ASSERT_TRUE(close(t[c], p.first[c])) << name << " row " << k << " t" << c;
      const double sign = either_sign && r[3] * p.second[3] + r[2] * p.second[2] < 0 ? -1.0 : 1.0;
      for (int c = 0; c < 4; ++c)
        ASSERT_TRUE(close(r[c], sign * p.second[c]))
            << name << " row " << k << " r" << c << ": " << r[c] << " vs " << sign * p.second[c];
    }
  }
  // The time accessor: a keyframe per row, min and max the first and last t.
  void expect_times(const Glb& g) {
    const auto [in, out] = g.channel(0, "translation");
    ASSERT_GE(in, 0);
    const auto& a = g.doc["accessors"][in];
    EXPECT_EQ(a["count"], table.rows.size());
    EXPECT_EQ(a["min"][0].get<double>(), static_cast<float>(table.rows.front()[0]));
    EXPECT_EQ(a["max"][0].get<double>(), static_cast<float>(table.rows.back()[0]));
    // one sampler per node and channel, each with its own output
    const auto& anim = g.doc["animations"][0];
    EXPECT_EQ(anim["channels"].size(), anim["samplers"].size());
  }

  phiq::CsvTable table;
  std::map<std::string, std::size_t> col;
};

Pose planar(double x, double y, double psi) { return {{x, y, 0.0}, {0.0, 0.0, std::sin(psi / 2), std::cos(psi / 2)}}; }

TEST_F(Animate, ReferencePointBodiesFollowTheirCoordinates) {
  const Glb g = animate("seed/fourbar_reference_point.yaml", ".csv");
  EXPECT_EQ(g.doc["scenes"][0]["name"], "fourbar_reference_point");
  EXPECT_EQ(g.doc["animations"][0]["name"], "fourbar_reference_point");
  // a node per drawn part: the three bodies and the ground, which holds the pins of O and C (still: no channel)
  const phiq::Scene scene = phiq::load_scene(phiq::test::model_path("seed/fourbar_reference_point.yaml"));
  ASSERT_EQ(phiq::drawn_parts(scene).size(), 4u);
  EXPECT_EQ(g.doc["nodes"].size(), 4u);
  for (const char* p : {"crank", "coupler", "rocker", "ground"}) EXPECT_GE(g.node(p), 0) << p;
  EXPECT_EQ(g.channel(g.node("ground"), "translation").second, -1);
  EXPECT_GE(g.channel(g.node("crank"), "translation").second, 0);
  expect_times(g);
  for (const char* b : {"crank", "coupler", "rocker"}) {
    const std::string s = b == std::string("crank") ? "2" : (b == std::string("coupler") ? "3" : "4");
    expect_poses(g, b, [&](std::size_t k) { return planar(at(k, "x" + s), at(k, "y" + s), at(k, "psi" + s)); });
  }
  // the crank's links run from its centre to its two pair points, ±L2/2 along x, and half their thickness (their
  // extent in z) beyond; its pins sit on those points
  const auto& crank = g.doc["meshes"][g.doc["nodes"][g.node("crank")]["mesh"].get<int>()]["primitives"];
  std::map<std::string, std::pair<nlohmann::json, nlohmann::json>> box;  // shape: (min, max)
  for (const auto& prim : crank) {
    const auto& a = g.doc["accessors"][prim["attributes"]["POSITION"].get<int>()];
    box[prim["extras"]["name"]] = {a["min"], a["max"]};
  }
  ASSERT_EQ(box.size(), 4u);
  const double half = box["O.link"].second[2].get<double>();
  EXPECT_GT(half, 0.0);
  EXPECT_FLOAT_EQ(box["O.link"].first[2].get<double>(), -half);
  EXPECT_NEAR(box["O.link"].first[0].get<double>() + half, -0.2, 1e-7);
  EXPECT_NEAR(box["A.link"].second[0].get<double>() - half, 0.2, 1e-7);
  for (const auto& [pin, x] : {std::pair<std::string, double>{"O.pin", -0.2}, {"A.pin", 0.2}})
    EXPECT_NEAR((box[pin].first[0].get<double>() + box[pin].second[0].get<double>()) / 2, x, 1e-7) << pin;
}

TEST_F(Animate, NaturalLinksFollowTheirPoints) {
  const Glb g = animate("seed/fourbar_natural.yaml", ".h5");  // the HDF5 result, read as the CSV is
  // a node per drawn part: three links (the crank's angle constraint draws the same bar as its distance)
  const phiq::Scene scene = phiq::load_scene(phiq::test::model_path("seed/fourbar_natural.yaml"));
  ASSERT_EQ(phiq::drawn_parts(scene).size(), 3u);
  EXPECT_EQ(g.doc["nodes"].size(), 3u);
  expect_times(g);
  auto link = [&](double ax, double ay, double bx, double by) {
    const double th = std::atan2(by - ay, bx - ax);
    return Pose{{ax, ay, 0.0}, {0.0, 0.0, std::sin(th / 2), std::cos(th / 2)}};
  };
  expect_poses(
      g, "crank", [&](std::size_t k) { return link(0, 0, at(k, "xA"), at(k, "yA")); }, true);
  expect_poses(
      g, "coupler", [&](std::size_t k) { return link(at(k, "xA"), at(k, "yA"), at(k, "xB"), at(k, "yB")); }, true);
  expect_poses(
      g, "rocker", [&](std::size_t k) { return link(1.0, 0, at(k, "xB"), at(k, "yB")); }, true);
  // a distance's link has a constant length: its bar is that length and its radius beyond, no scale channel
  const int n = g.node("coupler");
  EXPECT_EQ(g.channel(n, "scale").second, -1);
  const int pos = g.doc["meshes"][g.doc["nodes"][n]["mesh"].get<int>()]["primitives"][0]["attributes"]["POSITION"];
  const double radius = g.doc["accessors"][pos]["max"][1].get<double>();
  EXPECT_GT(radius, 0.0);
  EXPECT_NEAR(g.doc["accessors"][pos]["max"][0].get<double>() - radius, 1.2, 1e-6);
  // the moving end B follows its point: the coupler's origin (A) and 1.2 along its turned x
  const auto [in, out] = g.channel(n, "translation");
  const auto [rin, rout] = g.channel(n, "rotation");
  ASSERT_GE(out, 0);
  ASSERT_GE(rout, 0);
  for (std::size_t k = 0; k < table.rows.size(); k += 37) {
    const std::vector<double> t = g.floats(out, k), r = g.floats(rout, k);
    const double c = 1 - 2 * r[2] * r[2], s = 2 * r[2] * r[3];  // cos, sin of the turn about z
    EXPECT_NEAR(t[0] + 1.2 * c, at(k, "xB"), 1e-6) << k;
    EXPECT_NEAR(t[1] + 1.2 * s, at(k, "yB"), 1e-6) << k;
  }
}

TEST_F(Animate, SpatialBodiesTurnByTheirEulerParameters) {
  const Glb g = animate("spatial/rssr.yaml", ".csv");
  EXPECT_EQ(g.doc["scenes"][0]["name"], "rssr");
  expect_times(g);
  for (const std::string b : {"crank", "rocker"})
    expect_poses(g, b, [&](std::size_t k) {
      const double e0 = at(k, b + "_e0"), e1 = at(k, b + "_e1"), e2 = at(k, b + "_e2"), e3 = at(k, b + "_e3");
      return Pose{{at(k, b + "_x"), at(k, b + "_y"), at(k, b + "_z")}, {e1, e2, e3, e0}};
    });
  // the coupler: from the crank's point A = a (cos θ, sin θ, 0) to the rocker's B; its x axis along B − A
  const auto [in, out] = g.channel(g.node("coupler"), "translation");
  ASSERT_GE(out, 0);
  for (std::size_t k = 0; k < table.rows.size(); ++k) {
    const double e0 = at(k, "crank_e0"), e3 = at(k, "crank_e3");  // about z: θ/2 = atan2(e3, e0)
    const double th = 2 * std::atan2(e3, e0);
    EXPECT_NEAR(g.floats(out, k)[0], 0.2 * std::cos(th), 1e-6);
    EXPECT_NEAR(g.floats(out, k)[1], 0.2 * std::sin(th), 1e-6);
  }
}

TEST_F(Cli, AnimateRefusesAResultOfAnotherSceneInOneLine) {
  const std::string ref = phiq::test::model_path("seed/fourbar_reference_point.yaml"),
                    nat = phiq::test::model_path("seed/fourbar_natural.yaml");
  const fs::path csv = dir_ / "nat.csv", glb = dir_ / "out.glb";
  ASSERT_EQ(run("run -q " + nat + " -o " + csv.string()).code, 0);
  Result r = run("animate " + ref + " " + csv.string() + " -o " + glb.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(phiq::test::one_phiq_line(r.err));
  EXPECT_NE(r.err.find("no column 'x2'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(glb));
  // a good file already there is kept as it was
  ASSERT_EQ(run("animate " + nat + " " + csv.string() + " -o " + glb.string()).code, 0);
  const std::string good = slurp(glb);
  EXPECT_EQ(run("animate " + ref + " " + csv.string() + " -o " + glb.string()).code, 2);
  EXPECT_EQ(slurp(glb), good);
  // a coordinate that is not a number
  const fs::path bad = write("bad.csv", phiq::test::with_nan_xA(slurp(csv)));
  r = run("animate " + nat + " " + bad.string() + " -o " + (dir_ / "b.glb").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(phiq::test::one_phiq_line(r.err));
  EXPECT_NE(r.err.find("data row 2, column 'xA'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "b.glb"));
  // an output that is neither a .glb nor an .html page
  r = run("animate " + nat + " " + csv.string() + " -o " + (dir_ / "m.gltf").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(phiq::test::one_phiq_line(r.err));
  EXPECT_FALSE(fs::exists(dir_ / "m.gltf"));
}

}  // namespace
