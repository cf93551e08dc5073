// `phiq compare --json` and `--junit`: the comparison as documents CI systems read (tools/README.md), beside the
// one line on stderr that people read.
#pragma once

#include <string>

#include "phiq/csv_compare.hpp"

namespace phiq::tools {

// The two files compared and the options they were compared with.
struct CompareSubject {
  std::string a, b;
  CompareOptions options;
};

// The comparison as JSON (format kCompareJsonFormat): the verdict, the worst cell, and one entry per column.
std::string compare_json(const CompareSubject& s, const CompareResult& r);

// The comparison as JUnit XML: one test suite, one test case per column (compared, or, without --columns, found in
// one file only) and one for the row counts; a failure names the column's worst cell: line, t, both values, difference,
// tolerance.
std::string compare_junit(const CompareSubject& s, const CompareResult& r);

}  // namespace phiq::tools
