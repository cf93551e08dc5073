// `phiq compare`: its exit status, the worst cell by column, time and file line, and its options named in its
// errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

TEST_F(Cli, CompareExitStatusAndWorstCell) {
  const std::string ref = phiq::test::model_path("seed/reference/crank_slider_mixed.csv");
  const fs::path out = dir_ / "cs.csv";
  ASSERT_EQ(run("run -q " + phiq::test::model_path("seed/crank_slider_mixed.yaml") + " -o " + out.string()).code, 0);
  Result same = run("compare " + ref + " " + out.string());
  EXPECT_EQ(same.code, 0) << same.err;
  // perturb one acceleration cell by 1e-6 relative
  std::string text = slurp(out);
  const std::size_t row = text.find("\n0.5061454830783556,");
  ASSERT_NE(row, std::string::npos);
  const std::size_t last = text.find('\n', row + 1), comma = text.rfind(',', last);
  const double v = std::stod(text.substr(comma + 1, last - comma - 1));
  std::ostringstream nv;
  nv.precision(17);
  nv << v * (1 + 1e-6);
  text.replace(comma + 1, last - comma - 1, nv.str());
  fs::path bad = write("bad.csv", text);
  Result diff = run("compare " + ref + " " + bad.string());
  EXPECT_EQ(diff.code, 1);
  EXPECT_NE(diff.err.find("xB.a"), std::string::npos) << diff.err;
  EXPECT_NE(diff.err.find("0.5061454830783556"), std::string::npos) << diff.err;  // the time of the worst row
  EXPECT_EQ(run("compare --rtol 1e-5 " + ref + " " + bad.string()).code, 0);
  EXPECT_EQ(run("compare " + ref + " /nonexistent.csv").code, 2);
  Result missing = run("compare --columns t,nope " + ref + " " + out.string());
  EXPECT_EQ(missing.code, 2);
  // one line naming the command and the option, as every command-line error does
  EXPECT_EQ(missing.err, "phiq: compare: --columns: column 'nope' is not in " + ref + "\n");
}

// compare names its options, and its worst cell's line is the file's line (as its parse errors count them).
TEST_F(Cli, CompareCountsFileLinesAndNamesItsOptions) {
  const fs::path a = write("a.csv", "t,x\n0,1\n0.5,2\n1,3\n"), b = write("b.csv", "t,x\n0,1\n0.5,2.5\n1,3\n");
  Result r = run("compare " + a.string() + " " + b.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("worst x at line 3 (t = 0.5): 2 vs 2.5"), std::string::npos) << r.err;
  const fs::path bad = write("bad.csv", "t,x\n0,1\n0.5,abc\n");
  r = run("compare " + a.string() + " " + bad.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad.csv:3: "), std::string::npos) << r.err;
  r = run("compare " + a.string() + " " + b.string() + " --rtol nan");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.find("compare_csv"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--rtol"), std::string::npos) << r.err;
}

}  // namespace
