// A ClearanceReport as files (phiq/clearance_files.hpp, tools/cli/clearance_report.hpp): the HDF5 file read back
// with HDF5 itself holds the CSV's values and the report's summary exactly, the same bytes on 1 and 2 threads; the
// JSON summary of two spheres on moving points has the closed-form worst pose, interval and sensitivity; the JSON
// lists the four-bar knee's every local minimum as HDF5 /minima holds it.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "clearance_report.hpp"
#include "html_clearance.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"
#include "scratch_path.hpp"

namespace phiq {
namespace {

namespace fs = std::filesystem;

// The four-bar (crank L2 = 0.4 at 1 rad/s about O) with a ball of radius 0.05 at the crank's tip, (L2/2 + 0.2)
// (cos t, sin t), and a ball of radius 0.15 fixed at (0, −0.5): d = |tip − (0, −0.5)| − 0.2, least at t = 3π/2, where
// d = 0.5 − (L2/2 + 0.2) − 0.2 = −0.1 and ∂d/∂L2 = −1/2; the balls overlap while 0.41 + 0.4 sin t < 0.04.
std::string clearance_files_scene_text() {
  return test::model_file_text("seed/fourbar_reference_point.yaml", "\ntime:") +
         "\ntime: {start: 0, end: 2*pi, steps: 90}\n"
         "parts:\n"
         "  tip: {body: crank, shapes: [{type: sphere, radius: 0.05, at: [0.2, 0]}]}\n"
         "  ball: {body: ground, shapes: [{type: sphere, radius: 0.15, at: [0, -0.5]}]}\n"
         "output: {sensitivities: [L2], clearance: {pairs: [[tip, ball]], threshold: 0.01}}\n";
}

std::vector<double> clearance_files_read(hid_t file, const char* name, std::vector<hsize_t>* dims = nullptr) {
  const hid_t d = H5Dopen2(file, name, H5P_DEFAULT);
  EXPECT_GE(d, 0) << name;
  const hid_t space = H5Dget_space(d);
  hsize_t n[2] = {0, 1};
  const int rank = H5Sget_simple_extent_dims(space, n, nullptr);
  if (dims) dims->assign(n, n + rank);
  std::vector<double> v(n[0] * (rank == 2 ? n[1] : 1));
  if (!v.empty()) H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Sclose(space);
  H5Dclose(d);
  return v;
}

long long clearance_files_integer(hid_t file, const char* name) {
  long long v = -1;
  const hid_t a = H5Aopen(file, name, H5P_DEFAULT);
  H5Aread(a, H5T_NATIVE_LLONG, &v);
  H5Aclose(a);
  return v;
}

TEST(ClearanceFiles, Hdf5HoldsTheCsvValuesAndTheSummaryExactlyOnAnyThreadCount) {
  Scene s = parse_scene(clearance_files_scene_text(), "balls.yaml");
  const ClearanceReport r = scene_clearance(s);
  ASSERT_EQ(r.pairs.size(), 1u);
  const fs::path dir = phiq::test::scratch_path("phiq_clearance_files");
  fs::create_directories(dir);
  const fs::path path = dir / "c.h5";
  ClearanceHdf5Options o;
  o.scene_path = "balls.yaml";
  o.scene_text = s.text;
  o.parameters = s.parameters;
  write_clearance_hdf5(path.string(), r, s.parts, o);

  // the CSV's text, read back: the same doubles as /t and /distance
  std::istringstream csv(clearance_csv(r, s.parts));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "t,tip.ball");
  const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  std::vector<hsize_t> dims;
  const std::vector<double> t = clearance_files_read(f, "t"), d = clearance_files_read(f, "distance", &dims);
  ASSERT_EQ(dims, (std::vector<hsize_t>{91, 1}));
  ASSERT_EQ(t.size(), 91u);
  for (std::size_t k = 0; std::getline(csv, line); ++k) {
    ASSERT_LT(k, t.size());
    const auto comma = line.find(',');
    EXPECT_EQ(std::strtod(line.substr(0, comma).c_str(), nullptr), t[k]) << k;
    EXPECT_EQ(std::strtod(line.substr(comma + 1).c_str(), nullptr), d[k]) << k;
  }
  // the summary: the report's own values
  const PairClearance& p = r.pairs[0];
  const std::vector<double> worst = clearance_files_read(f, "worst", &dims);
  ASSERT_EQ(dims, (std::vector<hsize_t>{1, 13}));
  const std::vector<double> expected{p.worst.t,
                                     p.worst.at.distance,
                                     p.worst.at.point_a.x,
                                     p.worst.at.point_a.y,
                                     p.worst.at.point_a.z,
                                     p.worst.at.point_b.x,
                                     p.worst.at.point_b.y,
                                     p.worst.at.point_b.z,
                                     p.worst.at.normal.x,
                                     p.worst.at.normal.y,
                                     p.worst.at.normal.z,
                                     1.0,
                                     0.0};
  for (std::size_t k = 0; k < expected.size(); ++k) EXPECT_EQ(worst[k], expected[k] == 0.0 ? 0.0 : expected[k]) << k;
  EXPECT_EQ(clearance_files_read(f, "sensitivities", &dims), p.worst.sensitivities);
  EXPECT_EQ(dims, (std::vector<hsize_t>{1, 1}));
  EXPECT_EQ(clearance_files_read(f, "interference", &dims),
            (std::vector<double>{0.0, p.interference[0].entry, p.interference[0].exit}));
  EXPECT_EQ(dims, (std::vector<hsize_t>{1, 3}));
  // every local minimum, in time order (the first row, where d rises, and the worst at 3π/2): pair, t, d, refined,
  // and its own ∂d/∂L2
  std::vector<double> minima;
  for (const ClearanceMinimum& m : p.minima)
    minima.insert(minima.end(), {0.0, m.t, m.at.distance, m.refined ? 1.0 : 0.0, m.sensitivities.at(0)});
  ASSERT_EQ(p.minima.size(), 2u);
  EXPECT_EQ(p.minima[0].t, 0.0);
  EXPECT_EQ(p.minima[1].t, p.worst.t);
  EXPECT_EQ(p.minima[1].sensitivities, p.worst.sensitivities);
  // at t = 0, d = √(r² + 0.25) − 0.2 with r = L2/2 + 0.2 = 0.4: ∂d/∂L2 = r / (2 √0.41)
  EXPECT_NEAR(p.minima[0].sensitivities.at(0), 0.2 / std::sqrt(0.41), 1e-9);
  EXPECT_EQ(clearance_files_read(f, "minima", &dims), minima);
  EXPECT_EQ(dims, (std::vector<hsize_t>{2, 5}));
  EXPECT_EQ(clearance_files_integer(f, "format_version"), kClearanceHdf5Format);
  EXPECT_EQ(clearance_files_integer(f, "interferes"), 1);
  EXPECT_EQ(clearance_files_integer(f, "bound_held"), 1);
  EXPECT_EQ(clearance_files_integer(f, "pairs_selected"), 1);
  EXPECT_EQ(clearance_files_integer(f, "positions_solved"), r.positions_solved);
  H5Fclose(f);

  // the sweep on two threads: the same report, the same bytes
  s.sweep.threads = 2;
  s.sweep.chunk_steps = 30;
  const fs::path other = dir / "c2.h5";
  write_clearance_hdf5(other.string(), scene_clearance(s), s.parts, o);
  EXPECT_EQ(test::file_text(path.string()), test::file_text(other.string()));
  fs::remove_all(dir);
}

TEST(ClearanceFiles, SummaryJsonOfTwoBallsIsTheClosedForm) {
  const Scene s = parse_scene(clearance_files_scene_text(), "balls.yaml");
  const ClearanceReport r = scene_clearance(s);
  const auto j = nlohmann::json::parse(tools::clearance_summary_json(s, "balls.yaml", r));
  EXPECT_EQ(j["format"], kClearanceSummaryFormat);
  EXPECT_EQ(j["scene"], "balls.yaml");
  EXPECT_EQ(j["rows"], 91);
  EXPECT_EQ(j["threshold"], 0.01);
  EXPECT_EQ(j["pairs_selected"], 1);
  EXPECT_EQ(j["pairs_measured"], 1);
  EXPECT_EQ(j["interferes"], true);
  EXPECT_EQ(j["bound_held"], true);
  ASSERT_EQ(j["pairs"].size(), 1u);
  const auto& p = j["pairs"][0];
  EXPECT_EQ(p["a"], "tip");
  EXPECT_EQ(p["b"], "ball");
  const auto& w = p["worst"];
  const double h = 2 * M_PI / 90;
  EXPECT_NEAR(w["t"].get<double>(), 1.5 * M_PI, 1e-6);
  EXPECT_NEAR(w["distance"].get<double>(), -0.1, 1e-10);
  EXPECT_EQ(w["refined"], true);  // 3π/2 is step 67.5: between rows
  EXPECT_EQ(w["below_threshold"], true);
  // the witness points on the line of centres (x = 0), each its ball's deepest point inside the other, on its own
  // surface: the tip's lowest point (0, −0.4 − 0.05), the ball's highest (0, −0.5 + 0.15); the normal −y
  EXPECT_NEAR(w["point_a"][0].get<double>(), 0.0, 1e-6);
  EXPECT_NEAR(w["point_b"][0].get<double>(), 0.0, 1e-6);
  EXPECT_NEAR(w["point_a"][1].get<double>(), -0.45, 1e-9);
  EXPECT_NEAR(w["point_b"][1].get<double>(), -0.35, 1e-9);
  EXPECT_NEAR(w["normal"][1].get<double>(), -1.0, 1e-9);
  EXPECT_NEAR(w["sensitivities"]["L2"].get<double>(), -0.5, 1e-7);
  ASSERT_EQ(p["interference"].size(), 1u);
  // |tip − C|² = 0.41 + 0.4 sin t = 0.2²: sin t = −0.925
  EXPECT_NEAR(p["interference"][0]["entry"].get<double>(), M_PI + std::asin(0.925), 1e-9 * h);
  EXPECT_NEAR(p["interference"][0]["exit"].get<double>(), 2 * M_PI - std::asin(0.925), 1e-9 * h);
  EXPECT_EQ(p["unproven_intervals"], 0);
  // the JSON's numbers are the report's, to the bit
  EXPECT_EQ(w["distance"].get<double>(), r.pairs[0].worst.at.distance);
  EXPECT_EQ(p["interference"][0]["entry"].get<double>(), r.pairs[0].interference[0].entry);
}

// models/clearance/fourbar_knee.yaml with sensitivities to L2 and L3: several pairs, some with more than one
// local minimum, two interfering. The JSON's `local_minima` of each pair are HDF5 /minima's rows of that pair, in
// order, to the bit, as many as its `minima` count, each with its own sensitivities (/minima's last columns); the
// worst's entry has /worst's witness points and /sensitivities' row.
TEST(ClearanceFiles, SummaryJsonListsEveryMinimumAsHdf5MinimaHoldsIt) {
  const Scene s = parse_scene(test::model_file_text("clearance/fourbar_knee.yaml") + "  sensitivities: [L2, L3]\n",
                              "fourbar_knee.yaml");
  const ClearanceReport r = scene_clearance(s);
  ASSERT_GE(r.pairs.size(), 2u);
  const fs::path dir = phiq::test::scratch_path("phiq_clearance_json_minima");
  fs::create_directories(dir);
  const fs::path path = dir / "knee.h5";
  write_clearance_hdf5(path.string(), r, s.parts);
  const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  std::vector<hsize_t> dims, worst_dims, sens_dims, in_dims;
  const std::vector<double> minima = clearance_files_read(f, "minima", &dims),
                            worst = clearance_files_read(f, "worst", &worst_dims),
                            sensitivities = clearance_files_read(f, "sensitivities", &sens_dims),
                            interference = clearance_files_read(f, "interference", &in_dims);
  H5Fclose(f);
  fs::remove_all(dir);
  ASSERT_EQ(dims.size(), 2u);
  ASSERT_EQ(dims[1], 6u);  // pair, t, distance, refined, d_L2, d_L3
  ASSERT_EQ(sens_dims, (std::vector<hsize_t>{r.pairs.size(), 2}));

  const auto j = nlohmann::json::parse(tools::clearance_summary_json(s, "fourbar_knee.yaml", r));
  ASSERT_EQ(j["pairs"].size(), r.pairs.size());
  std::size_t row = 0, intervals = 0, several = 0, nonzero = 0;
  for (std::size_t i = 0; i < r.pairs.size(); ++i) {
    const auto& p = j["pairs"][i];
    const auto& list = p["local_minima"];
    ASSERT_EQ(list.size(), p["minima"].get<std::size_t>()) << i;
    several += list.size() > 1;
    std::size_t worst_entries = 0;
    for (std::size_t k = 0; k < list.size(); ++k, ++row) {
      ASSERT_LT(row, dims[0]);
      const auto& m = list[k];
      const double* h = &minima[row * 6];
      EXPECT_EQ(h[0], static_cast<double>(i)) << row;
      EXPECT_EQ(m["t"].get<double>(), h[1]) << row;
      EXPECT_EQ(m["distance"].get<double>(), h[2]) << row;
      EXPECT_EQ(m["refined"].get<bool>() ? 1.0 : 0.0, h[3]) << row;
      const ClearanceMinimum& own = r.pairs[i].minima[k];
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(m["point_a"][c].get<double>(),
                  (std::array<double, 3>{own.at.point_a.x, own.at.point_a.y, own.at.point_a.z}[c]));
        EXPECT_EQ(m["point_b"][c].get<double>(),
                  (std::array<double, 3>{own.at.point_b.x, own.at.point_b.y, own.at.point_b.z}[c]));
      }
      ASSERT_TRUE(m.contains("sensitivities")) << row;
      EXPECT_EQ(m["sensitivities"]["L2"].get<double>(), h[4]) << row;
      EXPECT_EQ(m["sensitivities"]["L3"].get<double>(), h[5]) << row;
      if (m["t"].get<double>() != r.pairs[i].worst.t) continue;
      ++worst_entries;
      const double* w = &worst[i * 13];
      EXPECT_EQ(m["t"].get<double>(), w[0]);
      EXPECT_EQ(m["distance"].get<double>(), w[1]);
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(m["point_a"][c].get<double>(), w[2 + c]) << row;
        EXPECT_EQ(m["point_b"][c].get<double>(), w[5 + c]) << row;
      }
      EXPECT_EQ(m["sensitivities"]["L2"].get<double>(), sensitivities[i * 2]);
      EXPECT_EQ(m["sensitivities"]["L3"].get<double>(), sensitivities[i * 2 + 1]);
      nonzero += sensitivities[i * 2] != 0.0 || sensitivities[i * 2 + 1] != 0.0;
    }
    EXPECT_EQ(worst_entries, list.empty() ? 0u : 1u) << i;
    for (const auto& in : p["interference"]) {
      ASSERT_LT(intervals * 3 + 2, interference.size());
      EXPECT_EQ(interference[intervals * 3], static_cast<double>(i));
      EXPECT_EQ(in["entry"].get<double>(), interference[intervals * 3 + 1]);
      EXPECT_EQ(in["exit"].get<double>(), interference[intervals * 3 + 2]);
      ++intervals;
    }
  }
  EXPECT_EQ(row, dims[0]);  // every /minima row listed once
  EXPECT_GE(intervals, 2u);
  EXPECT_EQ(intervals * 3, interference.size());
  EXPECT_GE(several, 1u);
  EXPECT_GE(nonzero, 1u);
}

// The balls of clearance_files_scene_text() with the fixed one's radius 0.0504 and no threshold: they overlap only
// while 0.41 + 0.4 sin t < 0.1004², |t − 3π/2| < acos(0.9997996) ≈ 0.02, inside the half step (π/90) either side of
// 3π/2, which lies midway between rows 67 and 68: both rows are clear, yet the viewer colours the pair at both
// rows (their spans hold the interval) and at no other, and carries the interval.
TEST(ClearanceFiles, ViewerColoursPartsThatInterfereOnlyBetweenRows) {
  std::string text = clearance_files_scene_text();
  text.replace(text.find("radius: 0.15"), 12, "radius: 0.0504");
  text.replace(text.find("threshold: 0.01"), 15, "threshold: 0");
  const Scene s = parse_scene(text, "balls.yaml");
  const ClearanceReport r = scene_clearance(s);
  ASSERT_EQ(r.pairs.size(), 1u);
  const PairClearance& p = r.pairs[0];
  const double half = std::acos((0.41 - 0.1004 * 0.1004) / 0.4);
  ASSERT_EQ(p.interference.size(), 1u);
  EXPECT_NEAR(p.interference[0].entry, 1.5 * M_PI - half, 1e-9);
  EXPECT_NEAR(p.interference[0].exit, 1.5 * M_PI + half, 1e-9);
  EXPECT_GT(p.row_distance[67], 0.0);
  EXPECT_GT(p.row_distance[68], 0.0);
  const std::string near = tools::viewer_near_rows(r, p);
  ASSERT_EQ(near.size(), 91u);
  EXPECT_EQ(near, std::string(67, '0') + "11" + std::string(22, '0'));
  const nlohmann::json v = tools::viewer_clearance(s, r);
  EXPECT_EQ(v["pairs"][0]["near"], near);
  EXPECT_EQ(v["pairs"][0]["interference"],
            nlohmann::json::array({nlohmann::json::array({p.interference[0].entry, p.interference[0].exit})}));
}

}  // namespace
}  // namespace phiq
