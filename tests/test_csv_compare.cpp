// CSV result tables: parsing (formats phiq writes and the errors a broken file must give) and tolerance comparison.
#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "phiq/csv_compare.hpp"

namespace phiq {
namespace {

using Strings = std::vector<std::string>;
const double kInf = std::numeric_limits<double>::infinity();

CsvTable parse(const std::string& text, const std::string& path = "a.csv") { return parse_csv_table(text, path); }

// The message of the phiq::Error that f throws; fails the test (and returns "") if it throws nothing.
template <class F>
std::string refusal(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected phiq::Error";
  return "";
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// ---------------------------------------------------------------------------------------------------------------
// Parsing

TEST(CsvParse, ReadsHeaderAndRowsExactly) {
  CsvTable t = parse("t,xA,xA.v\n0,0.30000000000000004,-1.56\n0.1,1e-17,-0\n");
  EXPECT_EQ(t.path, "a.csv");
  EXPECT_EQ(t.columns, (Strings{"t", "xA", "xA.v"}));
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[0], (std::vector<double>{0.0, 0.30000000000000004, -1.56}));
  EXPECT_EQ(t.rows[1][0], 0.1);
  EXPECT_EQ(t.rows[1][1], 1e-17);
  EXPECT_TRUE(std::signbit(t.rows[1][2]));
}

TEST(CsvParse, ShortestRoundTripNumbersReadBackBitForBit) {
  std::mt19937_64 rng(42);
  std::uniform_int_distribution<int> expo(-320, 300);
  std::uniform_real_distribution<double> mant(-10.0, 10.0);
  std::string text = "t,x\n";
  std::vector<double> written;
  for (int i = 0; i < 2000; ++i) {
    const double v = mant(rng) * std::pow(10.0, expo(rng));
    written.push_back(v);
    char buf[32];
    auto [p, ec] = std::to_chars(buf, buf + sizeof buf, v);
    text += std::to_string(i) + ",";
    text.append(buf, p);
    text += '\n';
  }
  CsvTable t = parse(text);
  ASSERT_EQ(t.rows.size(), written.size());
  for (std::size_t i = 0; i < written.size(); ++i)
    ASSERT_EQ(std::memcmp(&t.rows[i][1], &written[i], sizeof(double)), 0) << "row " << i << ": " << written[i];
}

TEST(CsvParse, AcceptsNanInfAndSignedValues) {
  CsvTable t = parse("a,b,c,d,e\nnan,inf,-inf,+1.5,  2.5\t\n");
  ASSERT_EQ(t.rows.size(), 1u);
  EXPECT_TRUE(std::isnan(t.rows[0][0]));
  EXPECT_EQ(t.rows[0][1], kInf);
  EXPECT_EQ(t.rows[0][2], -kInf);
  EXPECT_EQ(t.rows[0][3], 1.5);
  EXPECT_EQ(t.rows[0][4], 2.5);
}

TEST(CsvParse, AcceptsCrlfLineEnds) {
  CsvTable t = parse("t,x\r\n0,1.5\r\n0.1,2.5\r\n");
  EXPECT_EQ(t.columns, (Strings{"t", "x"}));  // no "\r" left on the last name
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[1], (std::vector<double>{0.1, 2.5}));
}

TEST(CsvParse, AcceptsMissingFinalNewline) {
  CsvTable t = parse("t,x\n0,1.5\n0.1,2.5");
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[1], (std::vector<double>{0.1, 2.5}));
  CsvTable crlf = parse("t,x\r\n0,1.5\r\n0.1,2.5");
  EXPECT_EQ(crlf.rows, t.rows);
}

TEST(CsvParse, HeaderOnlyIsAnEmptyTable) {
  CsvTable t = parse("t,x\n");
  EXPECT_EQ(t.columns, (Strings{"t", "x"}));
  EXPECT_TRUE(t.rows.empty());
  EXPECT_EQ(parse("t,x").columns, (Strings{"t", "x"}));
}

TEST(CsvParse, TrailingBlankLinesAreIgnoredButABlankLineInsideIsAnError) {
  EXPECT_EQ(parse("t,x\n0,1\n\n\r\n").rows.size(), 1u);
  EXPECT_EQ(refusal([] { parse("t,x\n0,1\n\n0.1,2\n"); }), "a.csv:3: blank line before the last row");
}

TEST(CsvParse, WrongFieldCountGivesLineAndBothCounts) {
  EXPECT_EQ(refusal([] { parse("t,x,y\n0,1,2\n0.1,2\n"); }), "a.csv:3: 2 fields, the header has 3");
  EXPECT_EQ(refusal([] { parse("t,x,y\r\n0,1,2,3\r\n"); }), "a.csv:2: 4 fields, the header has 3");
  EXPECT_EQ(refusal([] { parse("t,x\n5\n"); }), "a.csv:2: 1 field, the header has 2");
}

TEST(CsvParse, NonNumberFieldNamesColumnAndText) {
  EXPECT_EQ(refusal([] { parse("t,xA,xB\n0,1,2\n0.1,2,abc\n", "res/B.csv"); }),
            "res/B.csv:3: column 'xB': 'abc' is not a number");
  EXPECT_EQ(refusal([] { parse("t,xA\n0,\n"); }), "a.csv:2: column 'xA': '' is not a number");
  EXPECT_EQ(refusal([] { parse("t,xA\n0,1.5x\n"); }), "a.csv:2: column 'xA': '1.5x' is not a number");
  EXPECT_EQ(refusal([] { parse("t,xA\n0,+-1\n"); }), "a.csv:2: column 'xA': '+-1' is not a number");
  EXPECT_EQ(refusal([] { parse("t,xA\n0,1e400\n"); }), "a.csv:2: column 'xA': '1e400' is out of the range of a double");
  EXPECT_EQ(parse("t,xA\n0,1e-400\n").rows[0][1], 0.0);  // underflow is still the number written
}

TEST(CsvParse, MessagesStayOneLine) {
  const std::string msg = refusal([] { parse("t,xA\n0,1\r2\n"); });
  EXPECT_EQ(msg, "a.csv:2: column 'xA': '1\\x0d2' is not a number");
  const std::string long_msg = refusal([] { parse("t,xA\n0," + std::string(5000, 'z') + "\n"); });
  EXPECT_LT(long_msg.size(), 120u);
  EXPECT_EQ(long_msg.find('\n'), std::string::npos);
}

TEST(CsvParse, DuplicateColumnNamesAreRejected) {
  EXPECT_EQ(refusal([] { parse("t,xA,yA,xA\n0,1,2,3\n"); }), "a.csv:1: duplicate column name 'xA' (columns 2 and 4)");
}

TEST(CsvParse, EmptyColumnNamesAreRejected) {
  EXPECT_EQ(refusal([] { parse("t,,yA\n0,1,2\n"); }), "a.csv:1: column 2 has an empty name");
  EXPECT_EQ(refusal([] { parse("t,xA,\n0,1,2\n"); }), "a.csv:1: column 3 has an empty name");
}

TEST(CsvParse, EmptyFileOrMissingHeaderIsRejected) {
  EXPECT_EQ(refusal([] { parse(""); }), "a.csv:1: empty file, expected a header line");
  EXPECT_EQ(refusal([] { parse("\n0,1\n"); }), "a.csv:1: missing header line (the first line is blank)");
  EXPECT_EQ(refusal([] { parse("0,1.5\n0.1,2.5\n"); }), "a.csv:1: missing header line (the first line is all numbers)");
}

TEST(CsvRead, ReadsAFile) {
  const std::string path = ::testing::TempDir() + "phiq_test_csv_compare_read.csv";
  {
    std::ofstream f(path, std::ios::binary);
    f << "t,xA\r\n0,0.30000000000000004\r\n0.1,-1.56";
  }
  CsvTable t = read_csv_table(path);
  std::remove(path.c_str());
  EXPECT_EQ(t.path, path);
  EXPECT_EQ(t.columns, (Strings{"t", "xA"}));
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[0][1], 0.30000000000000004);
  EXPECT_EQ(t.rows[1][1], -1.56);
}

TEST(CsvRead, ParseErrorsNameTheFile) {
  const std::string path = ::testing::TempDir() + "phiq_test_csv_compare_bad.csv";
  {
    std::ofstream f(path, std::ios::binary);
    f << "t,xA\n0,1\n0.1,oops\n";
  }
  const std::string msg = refusal([&] { read_csv_table(path); });
  std::remove(path.c_str());
  EXPECT_EQ(msg, path + ":3: column 'xA': 'oops' is not a number");
}

TEST(CsvRead, MissingFileThrowsWithThePath) {
  const std::string path = ::testing::TempDir() + "phiq_no_such_dir/none.csv";
  const std::string msg = refusal([&] { read_csv_table(path); });
  EXPECT_EQ(msg.rfind(path + ": cannot read: ", 0), 0u) << msg;
}

// ---------------------------------------------------------------------------------------------------------------
// Comparison

// A two-column table t,x with x = the given values and t = 0, 0.1, 0.2, ...
CsvTable tx(const std::vector<double>& xs, const std::string& path = "a.csv") {
  CsvTable t;
  t.path = path;
  t.columns = {"t", "x"};
  for (std::size_t i = 0; i < xs.size(); ++i) t.rows.push_back({0.1 * static_cast<double>(i), xs[i]});
  return t;
}

TEST(CsvCompare, IdenticalTablesAgree) {
  const std::string text = "t,xA,xB.v\n0,0.30000000000000004,-1.56\n0.1,1e-17,nan\n0.2,inf,-inf\n";
  CompareResult r = compare_csv(parse(text, "a.csv"), parse(text, "b.csv"), {});
  EXPECT_TRUE(r.equal);
  EXPECT_EQ(r.mismatches, 0u);
  EXPECT_EQ(r.compared, (Strings{"t", "xA", "xB.v"}));
  EXPECT_EQ(r.rows_a, 3u);
  EXPECT_EQ(r.rows_b, 3u);
  EXPECT_EQ(r.max_abs_diff, 0.0);
  EXPECT_EQ(r.worst_ratio, 0.0);
  EXPECT_EQ(r.worst_column, "t");  // all cells tie at 0: the first one
  EXPECT_EQ(r.summary(), "agree: 3 rows x 3 columns (identical)");
}

TEST(CsvCompare, AgreeSummaryGivesLargestDifference) {
  CompareResult r = compare_csv(tx({1.0, 2.0}), tx({1.0, 2.0000000000000004}), {});
  EXPECT_TRUE(r.equal);
  EXPECT_EQ(r.max_abs_diff, 2.0000000000000004 - 2.0);
  EXPECT_EQ(r.max_abs_diff_column, "x");
  EXPECT_EQ(r.summary(), "agree: 2 rows x 2 columns (max |diff| 4.44e-16 in x)");
}

TEST(CsvCompare, RelativeToleranceJustInsideAndJustOutside) {
  CompareOptions opt;  // rtol 1e-9 dominates at 1000: tol = 1e-12 + 1e-6
  CompareResult inside = compare_csv(tx({1000.0}), tx({1000.0000009}), opt);
  EXPECT_TRUE(inside.equal) << inside.summary();
  EXPECT_GT(inside.worst_ratio, 0.85);
  EXPECT_LT(inside.worst_ratio, 0.95);
  CompareResult outside = compare_csv(tx({1000.0}), tx({1000.0000011}), opt);
  EXPECT_FALSE(outside.equal);
  EXPECT_EQ(outside.mismatches, 1u);
  EXPECT_GT(outside.worst_ratio, 1.05);
  EXPECT_LT(outside.worst_ratio, 1.15);
  // symmetric: the larger magnitude sets the tolerance whichever side it is on
  EXPECT_TRUE(compare_csv(tx({1000.0000009}), tx({1000.0}), opt).equal);
  EXPECT_FALSE(compare_csv(tx({-1000.0000011}), tx({-1000.0}), opt).equal);
}

TEST(CsvCompare, AbsoluteToleranceJustInsideAndJustOutside) {
  CompareOptions opt;  // near 0 atol 1e-12 dominates
  EXPECT_TRUE(compare_csv(tx({0.0}), tx({0.9e-12}), opt).equal);
  EXPECT_FALSE(compare_csv(tx({0.0}), tx({1.1e-12}), opt).equal);
  EXPECT_FALSE(compare_csv(tx({-0.6e-12}), tx({0.6e-12}), opt).equal);

  opt.rtol = 0.0;
  opt.atol = 1e-3;  // options are really used
  EXPECT_TRUE(compare_csv(tx({5.0}), tx({5.0009}), opt).equal);
  EXPECT_FALSE(compare_csv(tx({5.0}), tx({5.0011}), opt).equal);

  opt.atol = 0.0;  // zero tolerance: only exactly equal values agree
  EXPECT_TRUE(compare_csv(tx({0.0, 5.0}), tx({-0.0, 5.0}), opt).equal);
  CompareResult r = compare_csv(tx({1e-300}), tx({0.0}), opt);
  EXPECT_FALSE(r.equal);
  EXPECT_EQ(r.worst_ratio, kInf);
}

TEST(CsvCompare, WorstCellIsReportedWithColumnRowTimeAndValues) {
  CsvTable a = parse("t,xA,xB.a\n0,1,1\n0.1,1,2\n0.30000000000000004,3,1.25\n", "A.csv");
  // row 1: xA off by 1e-8 (ratio ~10); row 2: xB.a off by 1e-7 (ratio ~80) -- the worst
  CsvTable b = parse("t,xA,xB.a\n0,1,1\n0.1,1.00000001,2\n0.30000000000000004,3,1.2500001\n", "B.csv");
  CompareResult r = compare_csv(a, b, {});
  EXPECT_FALSE(r.equal);
  EXPECT_EQ(r.mismatches, 2u);
  EXPECT_EQ(r.worst_column, "xB.a");
  EXPECT_EQ(r.worst_row, 2u);
  EXPECT_EQ(r.worst_t, 0.30000000000000004);
  EXPECT_EQ(r.worst_a, 1.25);
  EXPECT_EQ(r.worst_b, 1.2500001);
  EXPECT_NEAR(r.worst_ratio, (1.2500001 - 1.25) / (1e-12 + 1e-9 * 1.2500001), 1e-9);
  EXPECT_NEAR(r.worst_tol, 1e-12 + 1e-9 * 1.2500001, 1e-24);
  EXPECT_EQ(r.max_abs_diff, 1.2500001 - 1.25);
  EXPECT_EQ(r.max_abs_diff_column, "xB.a");
  EXPECT_EQ(r.summary(),
            "differ: 2 cells beyond tolerance; worst xB.a at line 4 (t = 0.30000000000000004): 1.25 vs 1.2500001 "
            "(|diff| 1e-07 > tol 1.25e-09)");

  // Without a "t" column there is no time to report.
  CsvTable a2 = parse("xB.a\n1.25\n"), b2 = parse("xB.a\n1.2500001\n");
  CompareResult r2 = compare_csv(a2, b2, {});
  EXPECT_TRUE(std::isnan(r2.worst_t));
  EXPECT_EQ(r2.summary(),
            "differ: 1 cell beyond tolerance; worst xB.a at line 2: 1.25 vs 1.2500001 "
            "(|diff| 1e-07 > tol 1.25e-09)");
}

TEST(CsvCompare, NanEqualsNanButNotANumber) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(compare_csv(tx({nan, 1.0}), tx({nan, 1.0}), {}).equal);
  EXPECT_TRUE(compare_csv(tx({nan}), tx({-nan}), {}).equal);

  CompareResult r = compare_csv(tx({1.0, 2.0, 3.0}), tx({1.0, nan, 3.0 + 1e-6}), {});
  EXPECT_FALSE(r.equal);
  EXPECT_EQ(r.mismatches, 2u);
  EXPECT_EQ(r.worst_column, "x");
  EXPECT_EQ(r.worst_row, 1u);  // the NaN beats the finite mismatch
  EXPECT_EQ(r.worst_ratio, kInf);
  EXPECT_EQ(r.worst_a, 2.0);
  EXPECT_TRUE(std::isnan(r.worst_b));
  EXPECT_TRUE(contains(r.summary(), "worst x at line 3 (t = 0.1): 2 vs nan (NaN against a number)")) << r.summary();

  EXPECT_FALSE(compare_csv(tx({nan}), tx({0.0}), {}).equal);  // in either order
}

TEST(CsvCompare, InfinitiesEqualOnlyTheSameInfinity) {
  CompareOptions loose;
  loose.rtol = 1.0;
  loose.atol = 1e300;
  EXPECT_TRUE(compare_csv(tx({kInf, -kInf}), tx({kInf, -kInf}), {}).equal);
  EXPECT_FALSE(compare_csv(tx({kInf}), tx({-kInf}), loose).equal);
  CompareResult r = compare_csv(tx({kInf}), tx({1e308}), loose);
  EXPECT_FALSE(r.equal);
  EXPECT_EQ(r.worst_ratio, kInf);
  EXPECT_EQ(r.max_abs_diff, kInf);
  EXPECT_TRUE(contains(r.summary(), "inf vs 1e+308")) << r.summary();
}

TEST(CsvCompare, RowCountMismatchIsNotEqualAndStatesBothCounts) {
  CompareResult r = compare_csv(tx({1.0, 2.0, 3.0}), tx({1.0, 2.0}), {});
  EXPECT_FALSE(r.equal);
  EXPECT_EQ(r.rows_a, 3u);
  EXPECT_EQ(r.rows_b, 2u);
  EXPECT_EQ(r.mismatches, 0u);
  EXPECT_EQ(r.summary(),
            "differ: the shared 2 rows x 2 columns agree (identical); row counts differ: A has 3 rows, B has 2");

  // The shared rows are still compared.
  CompareResult r2 = compare_csv(tx({1.0}), tx({1.5, 2.0}), {});
  EXPECT_FALSE(r2.equal);
  EXPECT_EQ(r2.mismatches, 1u);
  EXPECT_TRUE(contains(r2.summary(), "1 cell beyond tolerance")) << r2.summary();
  EXPECT_TRUE(contains(r2.summary(), "row counts differ: A has 1 row, B has 2")) << r2.summary();
}

TEST(CsvCompare, HeaderDifferencesAreNotEqualByDefault) {
  CsvTable a = parse("t,x,y\n0,1,2\n", "a.csv"), b = parse("t,z,x\n0,9,1\n", "b.csv");
  CompareResult r = compare_csv(a, b, {});
  EXPECT_FALSE(r.equal);
  EXPECT_EQ(r.mismatches, 0u);
  EXPECT_EQ(r.compared, (Strings{"t", "x"}));  // matched by name, in A's order
  EXPECT_EQ(r.only_in_a, (Strings{"y"}));
  EXPECT_EQ(r.only_in_b, (Strings{"z"}));
  EXPECT_EQ(r.summary(), "differ: the shared 1 row x 2 columns agree (identical); columns only in A: y; only in B: z");

  CompareResult sub = compare_csv(parse("t,x\n0,1\n"), parse("t,x,x.v\n0,1,0\n"), {});
  EXPECT_FALSE(sub.equal);
  EXPECT_TRUE(contains(sub.summary(), "columns only in A: (none); only in B: x.v")) << sub.summary();
}

TEST(CsvCompare, RestrictingToSharedColumnsIgnoresHeaderDifferences) {
  CsvTable a = parse("t,x,y\n0,1,2\n0.1,1,2\n"), b = parse("t,z,x\n0,9,1\n0.1,9,1\n");
  CompareOptions opt;
  opt.columns = {"x", "t", "x"};
  CompareResult r = compare_csv(a, b, opt);
  EXPECT_TRUE(r.equal) << r.summary();
  EXPECT_EQ(r.compared, (Strings{"t", "x"}));  // A's order, repeats dropped
  EXPECT_EQ(r.only_in_a, (Strings{"y"}));      // still reported
  EXPECT_TRUE(r.columns_restricted);
  EXPECT_EQ(r.summary(), "agree: 2 rows x 2 columns (identical); not compared: columns only in A: y; only in B: z");

  // and the restricted columns are still really compared
  CsvTable b2 = parse("t,z,x\n0,9,1\n0.1,9,1.5\n");
  CompareResult r2 = compare_csv(a, b2, opt);
  EXPECT_FALSE(r2.equal);
  EXPECT_EQ(r2.worst_row, 1u);
  EXPECT_EQ(r2.worst_column, "x");
}

TEST(CsvCompare, UnknownColumnInOptionsThrows) {
  CsvTable a = parse("t,x,y\n0,1,2\n", "A.csv"), b = parse("t,x,z\n0,1,2\n", "B.csv");
  CompareOptions opt;
  opt.columns = {"x", "foo"};
  EXPECT_EQ(refusal([&] { compare_csv(a, b, opt); }), "column 'foo' is not in A.csv");
  opt.columns = {"y"};
  EXPECT_EQ(refusal([&] { compare_csv(a, b, opt); }), "column 'y' is not in B.csv");
  opt.columns = {"z"};
  EXPECT_EQ(refusal([&] { compare_csv(a, b, opt); }), "column 'z' is not in A.csv");
}

TEST(CsvCompare, NegativeOrNanToleranceThrows) {
  CsvTable a = tx({1.0});
  CompareOptions opt;
  opt.rtol = -1e-9;
  EXPECT_TRUE(contains(refusal([&] { compare_csv(a, a, opt); }), "rtol")) << "negative rtol";
  opt.rtol = 1e-9;
  opt.atol = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(contains(refusal([&] { compare_csv(a, a, opt); }), "atol")) << "NaN atol";
  opt.atol = 0.0;
  opt.rtol = kInf;  // allowed: accepts any two finite numbers
  EXPECT_TRUE(compare_csv(tx({0.0, 1.0}), tx({0.0, 1e300}), opt).equal);
}

TEST(CsvCompare, EmptyTablesAgreeWhenHeadersMatch) {
  CompareResult r = compare_csv(parse("t,x\n"), parse("t,x\n"), {});
  EXPECT_TRUE(r.equal);
  EXPECT_TRUE(r.worst_column.empty());
  EXPECT_EQ(r.summary(), "agree: 0 rows x 2 columns");
}

// Each column's own worst cell, beside the overall one: row, t, both values, tolerance and ratio, counted apart.
TEST(CsvCompare, EachColumnHasItsOwnWorstCell) {
  const CsvTable a = parse("t,x,y\n0,1,5\n0.5,2,6\n1,3,7\n"),
                 b = parse("t,x,y\n0,1,5\n0.5,2.5,6\n1,3.25,7.5\n", "b.csv");
  const CompareResult r = compare_csv(a, b);
  ASSERT_EQ(r.per_column.size(), 3u);
  EXPECT_EQ(r.per_column[0].column, "t");
  EXPECT_EQ(r.per_column[0].mismatches, 0u);
  EXPECT_EQ(r.per_column[0].max_abs_diff, 0.0);
  const ColumnComparison& x = r.per_column[1];
  EXPECT_EQ(x.column, "x");
  EXPECT_EQ(x.mismatches, 2u);
  EXPECT_EQ(x.worst_row, 1u);  // 0.5 / (1e-12 + 2.5e-9) beats 0.25 / (1e-12 + 3.25e-9)
  EXPECT_EQ(x.worst_t, 0.5);
  EXPECT_EQ(x.worst_a, 2.0);
  EXPECT_EQ(x.worst_b, 2.5);
  EXPECT_EQ(x.worst_tol, 1e-12 + 1e-9 * 2.5);
  EXPECT_EQ(x.worst_ratio, 0.5 / (1e-12 + 1e-9 * 2.5));
  EXPECT_EQ(x.max_abs_diff, 0.5);
  const ColumnComparison& y = r.per_column[2];
  EXPECT_EQ(y.mismatches, 1u);
  EXPECT_EQ(y.worst_row, 2u);
  EXPECT_EQ(y.worst_t, 1.0);
  EXPECT_EQ(r.mismatches, x.mismatches + y.mismatches);
  EXPECT_EQ(r.worst_column, "x");
}

// `theta2.v` in one table, `theta2__v` in the other: the same column (the two namings of `phiq run --names`).
TEST(CsvCompare, DottedAndIdentifierNamesAreOneColumn) {
  const CsvTable a = parse("t,x,x.v,P.vx\n0,1,2,3\n"), b = parse("t,x,x__v,P__vx\n0,1,2,3.5\n", "b.csv");
  const CompareResult r = compare_csv(a, b);
  EXPECT_EQ(r.compared, (Strings{"t", "x", "x.v", "P.vx"}));
  EXPECT_TRUE(r.only_in_a.empty());
  EXPECT_TRUE(r.only_in_b.empty());
  EXPECT_FALSE(r.equal);
  EXPECT_EQ(r.worst_column, "P.vx");
  const CompareResult restricted = compare_csv(a, b, CompareOptions{1e-9, 1e-12, {"x.v"}});
  EXPECT_TRUE(restricted.equal);
  // a column matched by its own name is not matched again by its form; `x_v` is not the form of `x.v`
  const CompareResult exact = compare_csv(parse("t,x.v\n0,1\n"), parse("t,x__v,x.v\n0,2,1\n", "b.csv"));
  EXPECT_EQ(exact.compared, (Strings{"t", "x.v"}));
  EXPECT_EQ(exact.only_in_b, (Strings{"x__v"}));
  EXPECT_EQ(compare_csv(parse("t,x_v\n0,1\n"), parse("t,x.v\n0,1\n", "b.csv")).only_in_a, (Strings{"x_v"}));
}

}  // namespace
}  // namespace phiq
