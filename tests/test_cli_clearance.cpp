// `phiq clearance` (tools/README.md): the CSV of each reported pair's distance per row, the summary, the exit status
// with and without --fail-on-interference, and a bad `output.clearance` refused in one line with no file written.
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

}  // namespace
