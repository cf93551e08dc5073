// `phiq batch -o OUT.csv|OUT.h5`: one file for every case. The CSV is the cases' own `phiq run` outputs with the
// case column first, the same bytes on any thread count; the HDF5 file reads back as the CSV; failing cases are
// named and left out; an unwritable output fails at once; an interrupted batch publishes whole cases, in order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "phiq/csv_compare.hpp"
#include "phiq/hdf5_reader.hpp"

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::one_phiq_line;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

// The seed's crank-slider with these parameter values written into its text, as the batch overrides them.
std::string with_parameters(std::string scene, const std::string& l2, const std::string& l3) {
  for (const auto& [line, value] :
       {std::pair<std::string, std::string>{"  L2: 0.3     # m", l2}, {"  L3: 1.0     # m", l3}}) {
    const std::size_t at = scene.find(line);
    EXPECT_NE(at, std::string::npos) << line;
    if (at != std::string::npos) scene.replace(at, line.size(), line.substr(0, 6) + value);
  }
  return scene;
}

// Each data line of `csv` (after its header) with "k," in front.
std::string with_case(const std::string& csv, std::size_t k) {
  std::string out;
  for (std::size_t at = csv.find('\n') + 1; at < csv.size();) {
    const std::size_t end = csv.find('\n', at);
    out += std::to_string(k) + "," + csv.substr(at, end + 1 - at);
    at = end + 1;
  }
  return out;
}

// The one CSV is the concatenation of `phiq run` of each case (its parameters written into the scene), the case
// column prepended, in case order; the cases that fail (L2 > L3 breaks the rod at θ2 = asin(L3/L2); L3 < 0 is no
// rod) are named and left out, and `phiq run` of their scenes fails too. The same bytes on 1 and 2 threads; the
// HDF5 file reads back as the CSV, number for number.
TEST_F(Cli, BatchOneCsvIsTheRunsOfItsCases) {
  const std::string scene_text = slurp(phiq::test::model_path("seed/crank_slider_mixed.yaml"));
  const fs::path scene = write("cs.yaml", scene_text);
  const std::vector<std::pair<std::string, std::string>> params = {{"0.2", "1.0"}, {"0.3", "1.0"},  {"1.5", "1.0"},
                                                                   {"0.4", "1.2"}, {"0.3", "-1.0"}, {"0.25", "0.9"}};
  std::string cases = "L2,L3\n";
  for (const auto& [l2, l3] : params) cases += l2 + "," + l3 + "\n";
  const fs::path list = write("cases.csv", cases);
  const auto batch = [&](const std::string& out, int threads) {
    return run("batch " + scene.string() + " " + list.string() + " -o " + (dir_ / out).string() + " --threads " +
               std::to_string(threads));
  };
  Result r = batch("two.csv", 2);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("case 2: step "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("case 4: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("must be positive, got L3 = -1 (line 6 of "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("left out of " + (dir_ / "two.csv").string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("4 of 6 cases in "), std::string::npos) << r.err;

  std::string expected;
  for (std::size_t k = 0; k < params.size(); ++k) {
    const fs::path one =
        write("case" + std::to_string(k) + ".yaml", with_parameters(scene_text, params[k].first, params[k].second));
    const fs::path csv = dir_ / ("run" + std::to_string(k) + ".csv");
    const Result rr = run("run -q " + one.string() + " -o " + csv.string());
    if (k == 2 || k == 4) {  // the failing cases fail alone too
      EXPECT_EQ(rr.code, k == 2 ? 1 : 2) << rr.err;
      continue;
    }
    ASSERT_EQ(rr.code, 0) << rr.err;
    const std::string text = slurp(csv);
    if (expected.empty()) expected = "case," + text.substr(0, text.find('\n') + 1);
    expected += with_case(text, k);
  }
  const std::string two = slurp(dir_ / "two.csv");
  EXPECT_EQ(two, expected);
  EXPECT_EQ(std::count(two.begin(), two.end(), '\n'), 1 + 4 * 181);

  r = batch("one.csv", 1);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(slurp(dir_ / "one.csv"), two) << "the bytes do not depend on the thread count";

  r = batch("all.h5", 2);
  EXPECT_EQ(r.code, 1) << r.err;
  const phiq::CsvTable h5 = phiq::read_result_table((dir_ / "all.h5").string());
  const phiq::CsvTable csv = phiq::read_csv_table((dir_ / "two.csv").string());
  EXPECT_EQ(h5.columns, csv.columns);
  ASSERT_EQ(h5.rows.size(), csv.rows.size());
  for (std::size_t i = 0; i < csv.rows.size(); ++i) ASSERT_EQ(h5.rows[i], csv.rows[i]) << "row " << i;

  // an existing directory named like a file, and a path ending in '/', are directories of case files, as before
  // (whose cases stop the batch at load when their parameters make the scene invalid: the first four cases here)
  const fs::path first4 = write("first4.csv", "L2,L3\n0.2,1.0\n0.3,1.0\n1.5,1.0\n0.4,1.2\n");
  fs::create_directories(dir_ / "d.csv");
  for (const char* out : {"d.csv", "e.csv/"}) {
    r = run("batch " + scene.string() + " " + first4.string() + " -o " + (dir_ / out).string());
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_EQ(slurp(dir_ / std::string(out).substr(0, 5) / "case0.csv"), slurp(dir_ / "run0.csv")) << out;
    EXPECT_EQ(slurp(dir_ / std::string(out).substr(0, 5) / "case3.csv"), slurp(dir_ / "run3.csv")) << out;
  }
}

// A case its parameters make impossible to assemble (the crank starting upright, longer than the rod reaches) is
// named and left out; the others are written, each at its closed form x_B = L2 cos θ + √(L3² − L2² sin² θ).
TEST_F(Cli, BatchOneFileLeavesOutACaseThatCannotAssemble) {
  std::string text = slurp(phiq::test::model_path("seed/crank_slider_mixed.yaml"));
  const std::string law = "initial: 0,";
  ASSERT_NE(text.find(law), std::string::npos);
  text.replace(text.find(law), law.size(), "initial: 1.5707963267948966,");
  const fs::path scene = write("upright.yaml", text);
  const fs::path list = write("cases.csv", "L2,L3\n0.3,1.0\n1.5,1.0\n0.4,1.1\n");
  const fs::path out = dir_ / "all.csv";
  const Result r = run("batch " + scene.string() + " " + list.string() + " -o " + out.string());  // all cores
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("upright.yaml: case 1: "), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("case 0: t ="), std::string::npos) << r.err;
  const phiq::CsvTable t = phiq::read_csv_table(out.string());
  ASSERT_EQ(t.rows.size(), 2u * 181);
  ASSERT_EQ(t.columns[0], "case");
  ASSERT_EQ(t.columns[2], "theta2");
  ASSERT_EQ(t.columns[5], "xB");
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const auto& row = t.rows[i];
    const double want_case = i < 181 ? 0 : 2, l2 = i < 181 ? 0.3 : 0.4, l3 = i < 181 ? 1.0 : 1.1;
    ASSERT_EQ(row[0], want_case) << i;
    const double th = row[2], s = std::sin(th);
    EXPECT_NEAR(row[5], l2 * std::cos(th) + std::sqrt(l3 * l3 - l2 * l2 * s * s), 1e-9) << i;
  }
}

// An output that cannot be created fails before any case runs: one line, exit 3, no file (CSV and HDF5).
TEST_F(Cli, BatchOneFileUnwritableOutputFailsAtOnce) {
  const fs::path list = write("cases.csv", "L2\n0.2\n0.3\n");
  for (const char* name : {"all.csv", "all.h5"}) {
    const Result r = run("batch " + phiq::test::model_path("seed/crank_slider_mixed.yaml") + " " + list.string() +
                         " -o " + (dir_ / "nodir" / name).string());
    EXPECT_EQ(r.code, 3) << r.err;
    EXPECT_TRUE(one_phiq_line(r.err));
    EXPECT_NE(r.err.find(std::string("nodir/") + name + ": cannot write: No such file or directory"), std::string::npos)
        << r.err;
    EXPECT_EQ(files(), (std::vector<std::string>{"cases.csv", "stderr.txt", "stdout.txt"}));
  }
}

// Interrupted (SIGINT after 0.5 s of a batch of minutes), the file published holds the cases committed by then:
// cases 0 … K−1, each whole (all of its rows), and the message says K.
TEST_F(Cli, BatchOneFileInterruptedKeepsWholeCasesInOrder) {
  std::string text = slurp(phiq::test::model_path("seed/crank_slider_mixed.yaml"));
  text.replace(text.find("steps: 180"), 10, "steps: 2000");
  const fs::path scene = write("cs.yaml", text);
  std::string cases = "L2\n";
  for (int k = 0; k < 20000; ++k) cases += std::to_string(0.2 + 1e-5 * k) + "\n";
  const fs::path list = write("cases.csv", cases);
  const fs::path out = dir_ / "all.csv";
  // The signal must come after the set-up (parsing 20 000 cases takes a while under a sanitizer on a busy
  // machine): an earlier one stops the batch before its file exists, with "no output written" (or before phiq's
  // handler is installed, silently), which is checked too; the signal then comes later the next time.
  Result r;
  for (const char* delay : {"0.5", "1", "2", "4", "8", "16"}) {
    r = run_prefixed(std::string("timeout --preserve-status -s INT ") + delay + " ",
                     "batch -q " + scene.string() + " " + list.string() + " -o " + out.string() + " --threads 2" +
                         " --summary " + (dir_ / "s.json").string());
    ASSERT_EQ(r.code, 130) << r.err;
    if (fs::exists(out)) break;
    EXPECT_TRUE(r.err.empty() || (one_phiq_line(r.err) && r.err.find("; no output written") != std::string::npos))
        << r.err;
    EXPECT_EQ(files(), (std::vector<std::string>{"cases.csv", "cs.yaml", "stderr.txt", "stdout.txt"})) << delay;
  }
  EXPECT_TRUE(one_phiq_line(r.err)) << r.err;
  const phiq::CsvTable t = phiq::read_csv_table(out.string());
  ASSERT_EQ(t.rows.size() % 2001, 0u);
  const std::size_t k_written = t.rows.size() / 2001;
  EXPECT_NE(r.err.find("interrupted (SIGINT); " + std::to_string(k_written) + " of 20000 cases written to "),
            std::string::npos)
      << r.err;
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    ASSERT_EQ(t.rows[i][0], static_cast<double>(i / 2001)) << i;
    if (i % 2001 == 0) {
      ASSERT_EQ(t.rows[i][1], 0.0) << i;  // each case from t = 0 …
    } else if (i % 2001 == 2000) {
      ASSERT_NEAR(t.rows[i][1], M_PI, 1e-12) << i;  // … to its end, t = π
    }
  }
  // the summary too: the signal, and every case not in the file "missing" (what --resume runs)
  const std::string summary = slurp(dir_ / "s.json");
  EXPECT_NE(summary.find("\"interrupted\": \"SIGINT\""), std::string::npos) << summary.substr(0, 600);
  EXPECT_NE(summary.find("\"written\": " + std::to_string(k_written) + ","), std::string::npos);
  EXPECT_EQ(phiq::test::count(summary, "\"status\": \"missing\""), 20000 - k_written);
  EXPECT_EQ(phiq::test::count(summary, "\"file\": \"" + out.string() + "\""), k_written);
  EXPECT_EQ(files(),
            (std::vector<std::string>{"all.csv", "cases.csv", "cs.yaml", "s.json", "stderr.txt", "stdout.txt"}));
}

}  // namespace

namespace {

// `phiq batch --sensitivity NAME`: every case delivers the sensitivities the scene's output.sensitivities would,
// each at its own parameters (∂x_B/∂L3 = L3 / √(L3² − L2² sin² θ) of the case's L2, L3), one file or a directory
// of cases alike, the same bytes as the scene listing them; a name that is no parameter fails at once in one line
// with no output.
TEST_F(Cli, BatchSensitivityOptionGivesEachCaseItsOwn) {
  const std::string text = slurp(phiq::test::model_path("seed/crank_slider_mixed.yaml"));
  const fs::path scene = write("cs.yaml", text);
  const fs::path listed = write(
      "listed.yaml", phiq::test::replace_first(text, "output: {velocities: true, accelerations: true}",
                                               "output: {velocities: true, accelerations: true, sensitivities: [L3]}"));
  const fs::path list = write("cases.csv", "L2,L3\n0.2,1.0\n0.35,1.1\n");
  const auto batch = [&](const fs::path& s, const std::string& out, const std::string& more) {
    return run("batch -q " + s.string() + " " + list.string() + " -o " + (dir_ / out).string() + more);
  };
  ASSERT_EQ(batch(listed, "listed.csv", "").code, 0);
  const Result r = batch(scene, "option.csv", " --sensitivity L3");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(slurp(dir_ / "option.csv"), slurp(dir_ / "listed.csv"));
  ASSERT_EQ(batch(listed, "listed_dir", "").code, 0);
  ASSERT_EQ(batch(scene, "option_dir", " --sensitivity L3").code, 0);
  for (const char* k : {"case0.csv", "case1.csv"})
    EXPECT_EQ(slurp(dir_ / "option_dir" / k), slurp(dir_ / "listed_dir" / k)) << k;
  const phiq::CsvTable t = phiq::read_csv_table((dir_ / "option.csv").string());
  const auto col = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(t.columns.begin(), t.columns.end(), name) - t.columns.begin());
  };
  ASSERT_EQ(t.rows.size(), 2u * 181u);
  for (const auto& row : t.rows) {
    const double l2 = row[col("case")] == 0.0 ? 0.2 : 0.35, l3 = row[col("case")] == 0.0 ? 1.0 : 1.1;
    const double s = std::sin(row[col("theta2")]);
    EXPECT_NEAR(row[col("xB.d_L3")], l3 / std::sqrt(l3 * l3 - l2 * l2 * s * s), 1e-9) << "case " << row[col("case")];
  }
  for (const std::string out : {"bad.csv", "bad_dir"}) {
    const Result bad = batch(scene, out, " --sensitivity L9");
    EXPECT_EQ(bad.code, 2) << out;
    EXPECT_NE(bad.err.find("--sensitivity: 'L9' is not a parameter of " + scene.string() + " (its parameters: L2, L3)"),
              std::string::npos)
        << bad.err;
    EXPECT_TRUE(one_phiq_line(bad.err)) << bad.err;
    EXPECT_FALSE(fs::exists(dir_ / out)) << out;
  }
}

}  // namespace
