// `phiq clearance` (tools/README.md): the CSV of each reported pair's distance per row, the summary, the exit status
// with and without --fail-on-interference, HDF5 and --summary written together, and a bad `output.clearance` refused
// in one line with no file written and an existing one left as it was.
#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

// models/clearance/fourbar_knee.yaml: the crank and the coupler hit the second screw head, pass within the
// threshold of the first; 73 rows.
TEST_F(Cli, ClearanceWritesEachPairsDistancePerRowAndExitsFourOnInterferenceWhenAsked) {
  const std::string scene = phiq::test::model_path("clearance/fourbar_knee.yaml");
  const fs::path out = dir_ / "c.csv";
  Result r = run("clearance " + scene + " -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string csv = slurp(out);
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "t,crank.screw_1,crank.screw_2,coupler.screw_1,coupler.screw_2");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 74);
  EXPECT_NE(r.err.find("crank / screw_2: worst -"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("interferes from t = "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the speed bound held"), std::string::npos) << r.err;
  r = run("clearance " + scene + " -q --fail-on-interference -o " + out.string());
  EXPECT_EQ(r.code, 4);
  EXPECT_EQ(r.err.find("worst"), std::string::npos) << r.err;  // quiet: no summary
  EXPECT_NE(r.err.find("parts interfere"), std::string::npos) << r.err;
}

TEST_F(Cli, ClearanceOfAnUnknownPartIsBadInputWithNoFile) {
  std::string text = slurp(phiq::test::model_path("clearance/fourbar_knee.yaml"));
  text = text.substr(0, text.find("output:")) + "output: {clearance: {pairs: [[crank, screw_9]]}}\n";
  const fs::path scene = write("bad.yaml", text);
  const Result r = run("clearance " + scene.string() + " -o " + (dir_ / "c.csv").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad.yaml:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("output.clearance.pairs[0][1]: unknown part 'screw_9'"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(files(), (std::vector<std::string>{"bad.yaml", "stderr.txt", "stdout.txt"}));
}

// -o OUT.h5 and --summary: both committed (what they hold: test_clearance_files.cpp), no temporary left.
TEST_F(Cli, ClearanceWritesHdf5AndTheJsonSummaryTogether) {
  const std::string scene = phiq::test::model_path("clearance/fourbar_knee.yaml");
  const Result r =
      run("clearance " + scene + " -q -o " + (dir_ / "c.h5").string() + " --summary " + (dir_ / "s.json").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(files(), (std::vector<std::string>{"c.h5", "s.json", "stderr.txt", "stdout.txt"}));
  EXPECT_EQ(slurp(dir_ / "c.h5").substr(1, 3), "HDF");
  const std::string json = slurp(dir_ / "s.json");
  EXPECT_NE(json.find("\"format\": 1,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"b\": \"screw_2\""), std::string::npos) << json;
}

TEST_F(Cli, ClearanceThresholdBelowZeroIsBadInputAndLeavesTheOldFiles) {
  std::string text = slurp(phiq::test::model_path("clearance/fourbar_knee.yaml"));
  text = text.substr(0, text.find("output:")) + "output: {clearance: {pairs: all, threshold: -0.001}}\n";
  const fs::path scene = write("bad.yaml", text);
  write("c.h5", "an earlier result\n");
  const Result r = run("clearance " + scene.string() + " -o " + (dir_ / "c.h5").string() + " --summary " +
                       (dir_ / "s.json").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad.yaml:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("output.clearance.threshold"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(files(), (std::vector<std::string>{"bad.yaml", "c.h5", "stderr.txt", "stdout.txt"}));
  EXPECT_EQ(slurp(dir_ / "c.h5"), "an earlier result\n");
}

}  // namespace
