// `phiq compare`: its exit status, the worst cell by column, time and file line, its options named in its
// errors, and its reports for CI (--json, --junit) read back.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "phiq/phiq.hpp"
#include "phiq/text.hpp"

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

// Two small tables: x differs at line 3, y at line 4, z is in B only.
constexpr const char* kA = "t,x,y\n0,1,5\n0.5,2,6\n1,3,7\n";
constexpr const char* kB = "t,x,y,z\n0,1,5,0\n0.5,2.5,6,0\n1,3,7.5,0\n";

TEST_F(Cli, CompareJsonNamesEachColumnsWorstCell) {
  const fs::path a = write("a.csv", kA), b = write("b.csv", kB), json = dir_ / "c.json";
  Result r = run("compare --json " + a.string() + " " + b.string());  // --json alone: standard output
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(phiq::test::one_phiq_line(r.err)) << "stderr's line as without --json";
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["format"], 1);
  EXPECT_EQ(j["phiq"], phiq::kVersion);
  EXPECT_EQ(j["a"], a.string());
  EXPECT_EQ(j["b"], b.string());
  EXPECT_EQ(j["equal"], false);
  EXPECT_EQ(j["rows_a"], 3);
  EXPECT_EQ(j["rows_b"], 3);
  EXPECT_EQ(j["only_in_a"], nlohmann::json::array());
  EXPECT_EQ(j["only_in_b"], nlohmann::json::array({"z"}));
  EXPECT_EQ(j["mismatches"], 2);
  EXPECT_EQ(j["summary"].get<std::string>().rfind("differ: 2 cells beyond tolerance; worst x at line 3", 0), 0u);
  ASSERT_EQ(j["columns"].size(), 3u);
  const double tol_x = 1e-12 + 1e-9 * 2.5, tol_y = 1e-12 + 1e-9 * 7.5;
  const auto& t = j["columns"][0];
  EXPECT_EQ(t["name"], "t");
  EXPECT_EQ(t["equal"], true);
  EXPECT_EQ(t["mismatches"], 0);
  EXPECT_EQ(t["max_abs_diff"], 0.0);
  const auto& x = j["columns"][1];
  EXPECT_EQ(x["name"], "x");
  EXPECT_EQ(x["equal"], false);
  EXPECT_EQ(x["mismatches"], 1);
  EXPECT_EQ(
      x["worst"],
      nlohmann::json(
          {{"line", 3}, {"t", 0.5}, {"a", 2.0}, {"b", 2.5}, {"diff", 0.5}, {"tol", tol_x}, {"ratio", 0.5 / tol_x}}));
  const auto& y = j["columns"][2];
  EXPECT_EQ(y["worst"]["line"], 4);
  EXPECT_EQ(y["worst"]["t"], 1.0);
  EXPECT_EQ(y["worst"]["tol"], tol_y);
  // the worst cell overall: x's (the larger ratio)
  EXPECT_EQ(j["worst"]["column"], "x");
  EXPECT_EQ(j["worst"]["line"], 3);
  // --json=FILE: the same document in a file, nothing on standard output
  r = run("compare --json=" + json.string() + " " + a.string() + " " + b.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_EQ(nlohmann::json::parse(slurp(json)), j);
  // equal: exit 0, equal true, every column equal
  r = run("compare --json " + a.string() + " " + a.string());
  EXPECT_EQ(r.code, 0);
  const auto same = nlohmann::json::parse(r.out);
  EXPECT_EQ(same["equal"], true);
  EXPECT_TRUE(same["worst"].is_object());
  for (const auto& c : same["columns"]) EXPECT_EQ(c["equal"], true);
  // unreadable input: exit 2, no report
  fs::remove(json);
  r = run("compare --json=" + json.string() + " " + a.string() + " " + (dir_ / "missing.csv").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_FALSE(fs::exists(json));
}

// NaN and infinities have no JSON number: they are the strings "nan", "inf", "-inf".
TEST_F(Cli, CompareJsonWritesNonFiniteValuesAsStrings) {
  const fs::path a = write("a.csv", "t,x\n0,nan\n1,1\n"), b = write("b.csv", "t,x\n0,1\n1,-inf\n");
  Result r = run("compare --json " + a.string() + " " + b.string());
  EXPECT_EQ(r.code, 1);
  const auto x = nlohmann::json::parse(r.out)["columns"][1];
  EXPECT_EQ(x["mismatches"], 2);
  EXPECT_EQ(x["worst"]["a"], "nan");  // the first of the two infinite ratios
  EXPECT_EQ(x["worst"]["b"], 1.0);
  EXPECT_EQ(x["worst"]["diff"], "inf");
  EXPECT_EQ(x["max_abs_diff"], "inf");
}

// JUnit XML: one test case per column (and one for the row counts), a failure naming the column's worst cell;
// read back with Python's xml.etree, as CI tools parse it.
TEST_F(Cli, CompareJunitHasOneTestCasePerColumn) {
  const fs::path a = write("a.csv", kA), b = write("b.csv", kB), xml = dir_ / "c.xml";
  Result r = run("compare --junit " + xml.string() + " " + a.string() + " " + b.string());
  EXPECT_EQ(r.code, 1);
  const std::string text = slurp(xml);
  ASSERT_FALSE(text.empty());
  auto count = [&](const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("<testcase "), 5u) << text;  // t, x, y, z and the row counts
  EXPECT_EQ(count("<failure "), 3u) << text;   // x, y, z
  if (std::system("/usr/bin/python3 -c 'import xml.etree.ElementTree' 2>/dev/null") != 0)
    GTEST_SKIP() << "no /usr/bin/python3";
  const fs::path script = write("junit.py",
                                "import sys, xml.etree.ElementTree as E\n"
                                "root = E.parse(sys.argv[1]).getroot()\n"
                                "print(root.tag, root.get('tests'), root.get('failures'), root.get('errors'))\n"
                                "for s in root:\n"
                                "  print(s.tag, s.get('tests'), s.get('failures'))\n"
                                "  for c in s.findall('testcase'):\n"
                                "    f = c.find('failure')\n"
                                "    print(c.get('name'), '|', 'ok' if f is None else f.get('message'))\n");
  const fs::path out = dir_ / "py.out";
  const int st =
      std::system(("/usr/bin/python3 " + script.string() + " " + xml.string() + " >" + out.string()).c_str());
  ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << "not well-formed XML:\n" << text;
  const std::string tol_x = phiq::shortest(1e-12 + 1e-9 * 2.5), tol_y = phiq::shortest(1e-12 + 1e-9 * 7.5);
  EXPECT_EQ(slurp(out),
            "testsuites 5 3 0\n"
            "testsuite 5 3\n"
            "t | ok\n"
            "x | 1 cell beyond tolerance; worst at line 3 (t = 0.5): 2 vs 2.5 (|diff| 0.5 > tol " +
                tol_x +
                ")\n"
                "y | 1 cell beyond tolerance; worst at line 4 (t = 1): 7 vs 7.5 (|diff| 0.5 > tol " +
                tol_y +
                ")\n"
                "z | only in " +
                b.string() + " (not in " + a.string() +
                ")\n"
                "(row count) | ok\n");
  // equal files: every case passes, exit 0; with --columns only the columns chosen are cases
  r = run("compare --junit " + xml.string() + " " + a.string() + " " + a.string());
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(slurp(xml).find("<testsuites name=\"phiq compare\" tests=\"4\" failures=\"0\" errors=\"0\">"),
            std::string::npos)
      << slurp(xml);
  r = run("compare --columns t --junit " + xml.string() + " " + a.string() + " " + b.string());
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(slurp(xml).find("tests=\"2\" failures=\"0\""), std::string::npos) << slurp(xml);  // t, the rows
}

}  // namespace
