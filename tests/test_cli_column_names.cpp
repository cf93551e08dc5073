// `phiq run --names identifiers`: column names that numpy.genfromtxt(names=True) and pandas attribute access keep
// as they are (checked with /usr/bin/python3 and numpy), refused when two would collide, and compared with the
// dotted names of CSV format 1 by `phiq compare`.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "phiq/csv_compare.hpp"
#include "phiq/csv_writer.hpp"

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::one_phiq_line;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

TEST(ColumnNames, IdentifierForms) {
  EXPECT_EQ(phiq::identifier_column_name("theta2.v"), "theta2__v");
  EXPECT_EQ(phiq::identifier_column_name("B.vx"), "B__vx");
  EXPECT_EQ(phiq::identifier_column_name("motor.ddf"), "motor__ddf");
  EXPECT_EQ(phiq::identifier_column_name("t"), "t");
  EXPECT_EQ(phiq::identifier_column_name("loop 2[1].residual"), "loop_2_1___residual");
  EXPECT_EQ(phiq::identifier_column_name("2a"), "_2a");
}

TEST_F(Cli, IdentifierNamesAreTheDottedOnesSpelledForPython) {
  const fs::path scene = write("f.yaml", phiq::test::kFourbarOutputs);
  Result dotted = run("run -q " + scene.string());
  Result ident = run("run -q --names identifiers " + scene.string());
  ASSERT_EQ(dotted.code, 0) << dotted.err;
  ASSERT_EQ(ident.code, 0) << ident.err;
  EXPECT_EQ(first_line(ident.out),
            "t,theta2,xA,yA,x3,y3,psi3,xB,yB,theta2__v,xA__v,yA__v,x3__v,y3__v,psi3__v,xB__v,yB__v,B__x,B__y,B__vx,"
            "B__vy,P__x,P__y,P__vx,P__vy,motor__f,motor__df,rocker__residual,residual,rcond");
  // the same numbers: only the header differs
  EXPECT_EQ(ident.out.substr(ident.out.find('\n')), dotted.out.substr(dotted.out.find('\n')));
}

// A coordinate named as another column's identifier form would be: refused, both named, before anything is solved.
TEST_F(Cli, IdentifierNamesThatWouldCollideAreRefused) {
  std::string text = phiq::test::kFourbarOutputs;
  text.replace(text.find("yB: 1.0}"), 8, "yB: 1.0, theta2__v: 0}");
  text.replace(text.find("constraints:\n"), 13,
               "constraints:\n  - {name: spare, type: equation, expr: \"theta2__v\"}\n");
  const fs::path scene = write("c.yaml", text), csv = dir_ / "c.csv";
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + csv.string()).code, 0) << "dotted names do not collide";
  fs::remove(csv);
  Result r = run("run -q --names identifiers " + scene.string() + " -o " + csv.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "phiq: " + scene.string() +
                       ": --names identifiers: columns 'theta2__v' and 'theta2.v' would both be named 'theta2__v': "
                       "rename one in the scene\n");
  EXPECT_FALSE(fs::exists(csv));
}

// numpy.genfromtxt(names=True) keeps every identifier name as written, where it drops the dots of format 1
// (`theta2.v` → `theta2v`, which then collides with a coordinate `theta2v`, renamed `theta2v_1` silently).
TEST_F(Cli, NumpyKeepsTheIdentifierNames) {
  if (std::system("/usr/bin/python3 -c 'import numpy' 2>/dev/null") != 0)
    GTEST_SKIP() << "no /usr/bin/python3 with numpy";
  std::string text = phiq::test::kFourbarOutputs;
  text.replace(text.find("yB: 1.0}"), 8, "yB: 1.0, theta2v: 0}");
  text.replace(text.find("constraints:\n"), 13, "constraints:\n  - {name: spare, type: equation, expr: \"theta2v\"}\n");
  const fs::path scene = write("n.yaml", text), dotted = dir_ / "d.csv", ident = dir_ / "i.csv";
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + dotted.string()).code, 0);
  ASSERT_EQ(run("run -q --names identifiers " + scene.string() + " -o " + ident.string()).code, 0);
  // the names numpy gives, one per line, and theta2's velocity at the last row read by attribute
  const fs::path script = write("names.py",
                                "import sys, numpy\n"
                                "a = numpy.genfromtxt(sys.argv[1], delimiter=',', names=True)\n"
                                "print('\\n'.join(a.dtype.names))\n"
                                "print(repr(float(a[-1]['theta2__v' if sys.argv[2] == 'i' else 'theta2v'])))\n"
                                "if sys.argv[2] == 'i':\n"
                                "  r = a.view(numpy.recarray)\n"  // attribute access, as pandas' df.theta2__v
                                "  print(repr(float(r.theta2__v[-1])), repr(float(r.B__vx[0])))\n");
  auto numpy_names = [&](const fs::path& csv, const char* kind) {
    const fs::path out = dir_ / "py.out", err = dir_ / "py.err";
    const int st = std::system(("/usr/bin/python3 " + script.string() + " " + csv.string() + " " + kind + " >" +
                                out.string() + " 2>" + err.string())
                                   .c_str());
    return Result{WIFEXITED(st) ? WEXITSTATUS(st) : -1, slurp(out), slurp(err)};
  };
  Result i = numpy_names(ident, "i");
  ASSERT_EQ(i.code, 0) << i.err;
  std::string expected;
  const std::string header = first_line(slurp(ident));
  for (char c : header) expected += c == ',' ? '\n' : c;
  EXPECT_EQ(i.out.substr(0, expected.size() + 1), expected + "\n") << "numpy renamed some: " << i.out;
  // theta2' = 1 (the motor's rate), read by name and as an attribute; B's x-velocity at the first row by attribute
  const phiq::CsvTable t = phiq::read_csv_table(ident.string());
  const auto col = std::find(t.columns.begin(), t.columns.end(), "B__vx") - t.columns.begin();
  ASSERT_LT(static_cast<std::size_t>(col), t.columns.size());
  std::istringstream values(i.out.substr(expected.size() + 1));
  double by_name = 0, by_attribute = 0, vx = 0;
  values >> by_name >> by_attribute >> vx;
  EXPECT_EQ(by_name, 1.0) << i.out;
  EXPECT_EQ(by_attribute, 1.0) << i.out;
  EXPECT_EQ(vx, t.rows[0][col]) << i.out;  // repr() is the shortest round trip: the same double
  Result d = numpy_names(dotted, "d");
  ASSERT_EQ(d.code, 0) << d.err;
  EXPECT_NE(d.out.find("\ntheta2v_1\n"), std::string::npos) << "format 1's collision, as the issue says: " << d.out;
}

// compare matches `theta2.v` with `theta2__v`: a format 1 reference against a run with identifier names.
TEST_F(Cli, CompareReadsBothNamings) {
  const fs::path scene = write("f.yaml", phiq::test::kFourbarOutputs), dotted = dir_ / "d.csv", ident = dir_ / "i.csv";
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + dotted.string()).code, 0);
  ASSERT_EQ(run("run -q --names identifiers " + scene.string() + " -o " + ident.string()).code, 0);
  Result r = run("compare " + dotted.string() + " " + ident.string());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("agree: 73 rows x 30 columns (identical)"), std::string::npos) << r.err;
  const phiq::CompareResult c =
      phiq::compare_csv(phiq::read_csv_table(dotted.string()), phiq::read_csv_table(ident.string()));
  EXPECT_TRUE(c.only_in_a.empty());
  EXPECT_TRUE(c.only_in_b.empty());
  EXPECT_EQ(c.compared[9], "theta2.v") << "A's names";
  // a real difference is still one
  std::string text = slurp(ident);
  text.replace(text.rfind(",1,"), 3, ",1.5,");
  const fs::path bad = write("bad.csv", text);
  EXPECT_EQ(run("compare " + dotted.string() + " " + bad.string()).code, 1);
}

// batch --names identifiers: every case file has the header run writes with the option, the same rows.
TEST_F(Cli, BatchWritesIdentifierNamesToo) {
  const std::string scene = phiq::test::model_path("seed/crank_slider_mixed.yaml");
  const fs::path cases = write("cases.csv", "L2\n0.3\n"), out = dir_ / "out";
  ASSERT_EQ(run("batch -q --names identifiers " + scene + " " + cases.string() + " -o " + out.string()).code, 0);
  Result single = run("run -q --names identifiers " + scene);
  ASSERT_EQ(single.code, 0) << single.err;
  EXPECT_EQ(first_line(single.out), "t,theta2,xA,yA,xB,theta2__v,xA__v,yA__v,xB__v,theta2__a,xA__a,yA__a,xB__a");
  EXPECT_EQ(slurp(out / "case0.csv"), single.out) << "L2 = 0.3 is the scene's own";
}

}  // namespace
