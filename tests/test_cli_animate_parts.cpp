// The parts a drawing shows (phiq/drawn_parts.hpp) in `phiq animate`'s outputs: the Cardan joint's stated parts as
// .glb nodes (one per part, named, its mesh the shapes' triangles, its keyframes part_pose() at every row, under a
// root turning z up), and in the HTML page's JSON (each part, its shapes once per distinct mesh, its poses); the
// clearance's witness points as .glb nodes carried by their parts.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "html_clearance.hpp"
#include "phiq/drawn_parts.hpp"
#include "phiq/phiq.hpp"

#include "cli_test_support.hpp"
#include "glb_reader.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::Glb;
using phiq::test::slurp;
namespace fs = std::filesystem;

// The rotation matrix (row-major) of the unit quaternion (x, y, z, w).
std::array<double, 9> matrix_of(const std::vector<double>& q) {
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  return {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),     2 * (x * z + y * w),
          2 * (x * y + z * w),     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
          2 * (x * z - y * w),     2 * (y * z + x * w),     1 - 2 * (x * x + y * y)};
}

// The scene, its result (a CSV run here) and each row's q.
struct SceneRun {
  phiq::Scene scene;
  phiq::CsvTable table;
  std::vector<Eigen::VectorXd> q;
};

class AnimateParts : public Cli {
 protected:
  SceneRun run_scene(const std::string& model, const fs::path& csv) {
    SceneRun r{phiq::load_scene(phiq::test::model_path(model)), {}, {}};
    EXPECT_EQ(run("run -q " + phiq::test::model_path(model) + " -o " + csv.string()).code, 0);
    r.table = phiq::read_result_table(csv.string());
    const phiq::Model& m = *r.scene.model;
    for (const auto& row : r.table.rows) {
      Eigen::VectorXd q = m.initial_positions();
      for (std::size_t c = 0; c < r.table.columns.size(); ++c)
        if (const phiq::Index j = m.find_coordinate(r.table.columns[c]); j >= 0) q(j) = row[c];
      r.q.push_back(q);
    }
    return r;
  }
};

TEST_F(AnimateParts, GlbHoldsANodePerPartPosedByPartPose) {
  const fs::path csv = dir_ / "cardan.csv", glb = dir_ / "cardan.glb";
  const SceneRun r = run_scene("spatial/cardan.yaml", csv);
  const phiq::test::Result a =
      run("animate " + phiq::test::model_path("spatial/cardan.yaml") + " " + csv.string() + " -o " + glb.string());
  ASSERT_EQ(a.code, 0) << a.err;
  const Glb g = phiq::test::parse_glb(slurp(glb));
  const std::vector<phiq::Part> parts = phiq::drawn_parts(r.scene);
  ASSERT_EQ(parts.size(), 5u);  // the four stated, and the ground's derived one (the fork of its hinge)
  EXPECT_TRUE(parts[4].derived);
  EXPECT_EQ(parts[4].name, "ground");
  // a node per part, and the root that turns phiq's z up to glTF's +y (a quarter turn about x) holding them all
  ASSERT_EQ(g.doc["nodes"].size(), parts.size() + 1);
  const auto& root = g.doc["nodes"][parts.size()];
  EXPECT_EQ(g.doc["scenes"][0]["nodes"], nlohmann::json::array({parts.size()}));
  EXPECT_EQ(root["children"].size(), parts.size());
  EXPECT_NEAR(root["rotation"][0].get<double>(), -std::sqrt(0.5), 1e-7);
  EXPECT_NEAR(root["rotation"][3].get<double>(), std::sqrt(0.5), 1e-7);
  std::set<std::string> colours;
  for (const phiq::Part& part : parts) {
    const int n = g.node(part.name);
    ASSERT_GE(n, 0) << part.name;
    // its mesh: a primitive per shape, named; the shapes' triangles, each corner a vertex of shape_triangles()
    const auto& mesh = g.doc["meshes"][g.doc["nodes"][n]["mesh"].get<int>()];
    EXPECT_EQ(mesh["name"], part.name);
    ASSERT_EQ(mesh["primitives"].size(), part.shapes.size());
    for (std::size_t s = 0; s < part.shapes.size(); ++s) {
      const phiq::Shape& shape = part.shapes[s];
      const auto& prim = mesh["primitives"][s];
      EXPECT_EQ(prim["extras"]["name"], shape.name);
      const phiq::TriangleMesh tri = phiq::shape_triangles(shape, 32);
      EXPECT_EQ(g.doc["accessors"][prim["indices"].get<int>()]["count"], 3 * tri.triangles.size()) << shape.name;
      // split at the edges: a box's 8 corners are 24 vertices, a cylinder of 32 segments 4·32 + 2
      const std::size_t vertices = shape.kind == phiq::ShapeKind::kBox ? 24 : 4 * 32 + 2;
      const int pos = prim["attributes"]["POSITION"];
      ASSERT_EQ(g.doc["accessors"][pos]["count"], vertices) << shape.name;
      for (std::size_t v = 0; v < vertices; v += 7) {
        const std::vector<double> p = g.floats(pos, v);
        double nearest = INFINITY;
        for (const phiq::kin3::V3& x : tri.vertices)
          nearest = std::min(nearest, std::hypot(p[0] - x.x, p[1] - x.y, p[2] - x.z));
        EXPECT_LT(nearest, 1e-7) << shape.name << " vertex " << v;
      }
      const auto& material = g.doc["materials"][prim["material"].get<int>()];
      colours.insert(material["name"].get<std::string>());
      const double red = part.colour ? (*part.colour)[0] : 0.72;  // a derived part: light grey (shape_colour())
      EXPECT_FLOAT_EQ(material["pbrMetallicRoughness"]["baseColorFactor"][0].get<double>(), red);
    }
    // its keyframes: part_pose() at each row, float32; a fixed part none, its node posed once
    const auto [tin, tout] = g.channel(n, "translation");
    if (part.fixed) {
      EXPECT_EQ(tout, -1) << part.name;
      const phiq::Pose p = phiq::part_pose(part.frame, r.q[0].data(), r.table.rows[0][0]);
      const auto& node = g.doc["nodes"][n];
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(node["translation"][c].get<double>(), (&p.at.x)[c], 1e-7) << part.name;
      const std::array<double, 9> m = matrix_of(node["rotation"].get<std::vector<double>>());
      for (int c = 0; c < 9; ++c) EXPECT_NEAR(m[c], p.rotation[c], 1e-7) << part.name << " R" << c;
      continue;
    }
    const auto [rin, rout] = g.channel(n, "rotation");
    ASSERT_GE(tout, 0);
    ASSERT_GE(rout, 0);
    ASSERT_EQ(g.doc["accessors"][tout]["count"], r.table.rows.size());
    for (std::size_t k = 0; k < r.table.rows.size(); ++k) {
      const phiq::Pose p = phiq::part_pose(part.frame, r.q[k].data(), r.table.rows[k][0]);
      const std::vector<double> t = g.floats(tout, k);
      const double at[3] = {p.at.x, p.at.y, p.at.z};
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(t[c], at[c], 1e-6) << part.name << " row " << k << " t" << c;
      const std::array<double, 9> m = matrix_of(g.floats(rout, k));
      for (int c = 0; c < 9; ++c) ASSERT_NEAR(m[c], p.rotation[c], 1e-6) << part.name << " row " << k << " R" << c;
    }
  }
  // one material per colour: blue, orange, the cross's grey and the derived parts' light grey
  EXPECT_EQ(colours, (std::set<std::string>{"#4573b3", "#e6801a", "#555555", "#b8b8b8"}));
  EXPECT_EQ(g.doc["materials"].size(), 4u);
}

// int16 codes of base64 `b64` (the viewer's encoding, html_motion.cpp).
std::vector<int> int16_codes(const std::string& b64) {
  static const std::string a = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string bytes;
  for (std::size_t i = 0; i + 3 < b64.size(); i += 4) {
    std::uint32_t v = 0;
    int n = 0;
    for (std::size_t k = 0; k < 4; ++k) {
      const std::size_t c = a.find(b64[i + k]);
      v = (v << 6) | (c == std::string::npos ? 0u : static_cast<std::uint32_t>(c));
      n += c != std::string::npos;
    }
    for (int k = 0; k < n - 1; ++k) bytes += static_cast<char>((v >> (16 - 8 * k)) & 0xff);
  }
  std::vector<int> out;
  for (std::size_t i = 0; i + 1 < bytes.size(); i += 2)
    out.push_back(static_cast<std::int16_t>(static_cast<unsigned char>(bytes[i]) |
                                            (static_cast<unsigned char>(bytes[i + 1]) << 8)));
  return out;
}

TEST_F(AnimateParts, HtmlHoldsEachPartAndItsPoses) {
  const fs::path csv = dir_ / "cardan.csv", html = dir_ / "cardan.html";
  const SceneRun r = run_scene("spatial/cardan.yaml", csv);
  ASSERT_EQ(
      run("animate " + phiq::test::model_path("spatial/cardan.yaml") + " " + csv.string() + " -o " + html.string())
          .code,
      0);
  const std::string page = slurp(html);
  const std::size_t from = page.find('>', page.find("id=\"phiq-data\"")) + 1;
  const nlohmann::json data = nlohmann::json::parse(page.substr(from, page.find("</script>", from) - from));
  const nlohmann::json& parts = data["parts"];
  const std::vector<phiq::Part> drawn = phiq::drawn_parts(r.scene);
  ASSERT_EQ(parts["names"].size(), drawn.size());
  ASSERT_EQ(parts["geometries"].size(), drawn.size());  // four different parts: four geometries
  const std::vector<std::size_t> kept = data["kept"];
  ASSERT_EQ(kept.size(), r.table.rows.size());  // 73 rows fit the budget: every one a frame
  const std::vector<int> codes = int16_codes(parts["poses"]);
  ASSERT_EQ(codes.size(), 7 * drawn.size() * kept.size());
  const std::vector<double> lo = parts["lo"], hi = parts["hi"];
  for (std::size_t k = 0; k < drawn.size(); ++k) {
    EXPECT_EQ(parts["names"][k], drawn[k].name);
    const auto& shapes = parts["geometries"][parts["geometry"][k].get<int>()];
    ASSERT_EQ(shapes.size(), drawn[k].shapes.size());
    ASSERT_EQ(parts["shapes"][k].size(), drawn[k].shapes.size());
    for (std::size_t s = 0; s < shapes.size(); ++s) EXPECT_EQ(parts["shapes"][k][s], drawn[k].shapes[s].name);
    for (std::size_t f = 0; f < kept.size(); f += 6) {
      const phiq::Pose p = phiq::part_pose(drawn[k].frame, r.q[kept[f]].data(), r.table.rows[kept[f]][0]);
      const int* c = &codes[7 * (f * drawn.size() + k)];
      const double at[3] = {p.at.x, p.at.y, p.at.z};
      for (int i = 0; i < 3; ++i)  // within a step of the code
        EXPECT_NEAR(lo[i] + (c[i] + 32767) * (hi[i] - lo[i]) / 65534, at[i], (hi[i] - lo[i]) / 65534 + 1e-12);
      std::vector<double> q(4);
      for (int i = 0; i < 4; ++i) q[i] = -1 + (c[3 + i] + 32767) * 2.0 / 65534;
      const std::array<double, 9> m = matrix_of(q);
      for (int i = 0; i < 9; ++i) EXPECT_NEAR(m[i], p.rotation[i], 2e-4) << drawn[k].name << " frame " << f;
    }
  }
}

// `output.clearance` in the .glb: the four-bar's crank (1 rad/s about O) carries a ball of radius 0.05 centred at
// 0.4 (cos t, sin t), against a ball of radius 0.15 fixed at (0, −0.5); the worst pose is t = 3π/2. The witness on
// the crank is its material point at radius 0.45 on the line of centres there, 0.45 (cos t, sin t) at every row;
// the fixed ball's is (0, −0.35). Both balls ×2 exactly at the rows the viewer colours (viewer_near_rows()).
TEST_F(AnimateParts, GlbCarriesTheClearanceWitnessPointsWithTheirParts) {
  const std::string text = phiq::test::model_file_text("seed/fourbar_reference_point.yaml", "\ntime:") +
                           "\ntime: {start: 0, end: 2*pi, steps: 90}\n"
                           "parts:\n"
                           "  tip: {body: crank, shapes: [{type: sphere, radius: 0.05, at: [0.2, 0]}]}\n"
                           "  ball: {body: ground, shapes: [{type: sphere, radius: 0.15, at: [0, -0.5]}]}\n"
                           "output: {clearance: {pairs: [[tip, ball]], threshold: 0.01}}\n";
  const fs::path scene = write("balls.yaml", text), glb = dir_ / "balls.glb";
  const phiq::test::Result a = run("animate " + scene.string() + " -o " + glb.string());
  ASSERT_EQ(a.code, 0) << a.err;
  const phiq::Scene s = phiq::parse_scene(text, scene.string());
  const phiq::ClearanceReport r = phiq::scene_clearance(s);
  ASSERT_EQ(r.pairs.size(), 1u);
  const std::string near = phiq::tools::viewer_near_rows(r, r.pairs[0]);
  ASSERT_NE(near.find('1'), std::string::npos);
  ASSERT_NE(near.find('0'), std::string::npos);
  const Glb g = phiq::test::parse_glb(slurp(glb));
  for (const char* part : {"tip", "ball"}) {
    const int n = g.node(std::string("clearance tip / ball: witness on ") + part);
    ASSERT_GE(n, 0) << part;
    const auto& node = g.doc["nodes"][n];
    const auto& mesh = g.doc["meshes"][node["mesh"].get<int>()];
    EXPECT_EQ(g.doc["materials"][mesh["primitives"][0]["material"].get<int>()]["name"], "clearance witness");
    const auto& extras = node["extras"]["clearance"];
    EXPECT_EQ(extras["part"], part);
    EXPECT_EQ(extras["near"], near);
    EXPECT_EQ(extras["worst_t"].get<double>(), r.pairs[0].worst.t);
    EXPECT_EQ(extras["interference"].size(), 1u);
    const auto [tin, tout] = g.channel(n, "translation");
    const auto [scale_in, sout] = g.channel(n, "scale");
    ASSERT_GE(tout, 0) << part;
    ASSERT_GE(sout, 0) << part;
    ASSERT_EQ(g.doc["accessors"][tout]["count"], r.times.size());
    for (std::size_t k = 0; k < r.times.size(); ++k) {
      const double t = r.times[k];
      const bool tip = std::string(part) == "tip";
      const std::vector<double> x = g.floats(tout, k);
      EXPECT_NEAR(x[0], tip ? 0.45 * std::cos(t) : 0.0, 1e-6) << part << " row " << k;
      EXPECT_NEAR(x[1], tip ? 0.45 * std::sin(t) : -0.35, 1e-6) << part << " row " << k;
      EXPECT_EQ(g.floats(sout, k)[0], near[k] == '1' ? 2.0 : 1.0) << part << " row " << k;
    }
  }
}

}  // namespace
