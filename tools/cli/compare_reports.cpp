// The reports of `phiq compare` for programs (compare_reports.hpp).
#include "compare_reports.hpp"

#include <cmath>

#include <nlohmann/json.hpp>

#include "command_support.hpp"
#include "phiq/phiq.hpp"
#include "phiq/text.hpp"

namespace phiq::tools {

namespace {

using Json = nlohmann::ordered_json;

// JSON has no NaN or infinity: those are written as the strings "nan", "inf", "-inf", so that a reader tells a
// NaN cell from a missing one (nlohmann would write null).
Json number(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return v;
}

// |a − b| as compare_csv() counts it: 0 for NaN against NaN, inf for a non-finite value against another value.
double difference(double a, double b) {
  if (a == b || (std::isnan(a) && std::isnan(b))) return 0.0;
  if (!std::isfinite(a) || !std::isfinite(b)) return INFINITY;
  return std::fabs(a - b);
}

// The worst cell of a column: its file line (the header is line 1), t, both values, difference, tolerance, ratio.
Json cell(std::size_t row, double t, double a, double b, double tol, double ratio) {
  return Json{{"line", row + 2},
              {"t", std::isnan(t) ? Json(nullptr) : number(t)},
              {"a", number(a)},
              {"b", number(b)},
              {"diff", number(difference(a, b))},
              {"tol", number(tol)},
              {"ratio", number(ratio)}};
}

bool have_cells(const CompareResult& r) { return std::min(r.rows_a, r.rows_b) > 0; }

// One line: "3 cells beyond tolerance; worst at line 19 (t = 0.29): 1.25 vs 1.2500001 (|diff| 1e-07 > tol 1.25e-09)".
std::string column_failure(const ColumnComparison& c) {
  std::string s = std::to_string(c.mismatches) + (c.mismatches == 1 ? " cell" : " cells") +
                  " beyond tolerance; worst at line " + std::to_string(c.worst_row + 2);
  if (!std::isnan(c.worst_t)) s += " (t = " + shortest(c.worst_t) + ")";
  s += ": " + shortest(c.worst_a) + " vs " + shortest(c.worst_b) + " (|diff| " +
       shortest(difference(c.worst_a, c.worst_b)) + " > tol " + shortest(c.worst_tol) + ")";
  return s;
}

// Text for an XML attribute or element: one printable line (control characters and bytes that are not UTF-8
// written \xNN, as stderr gets them), with the five characters XML reserves escaped.
std::string xml(const std::string& text) {
  std::string out;
  for (char c : printable(text)) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace

std::string compare_json(const CompareSubject& s, const CompareResult& r) {
  Json j;
  j["format"] = kCompareJsonFormat;
  j["phiq"] = version();
  j["a"] = s.a;
  j["b"] = s.b;
  j["rtol"] = number(s.options.rtol);
  j["atol"] = number(s.options.atol);
  j["equal"] = r.equal;
  j["summary"] = r.summary();
  j["rows_a"] = r.rows_a;
  j["rows_b"] = r.rows_b;
  j["columns_restricted"] = r.columns_restricted;
  j["only_in_a"] = r.only_in_a;
  j["only_in_b"] = r.only_in_b;
  j["mismatches"] = r.mismatches;
  j["max_abs_diff"] = number(r.max_abs_diff);
  j["worst"] = nullptr;
  if (!r.worst_column.empty()) {
    j["worst"] = cell(r.worst_row, r.worst_t, r.worst_a, r.worst_b, r.worst_tol, r.worst_ratio);
    j["worst"]["column"] = r.worst_column;
  }
  j["columns"] = Json::array();
  for (const ColumnComparison& c : r.per_column) {
    Json o{{"name", c.column},
           {"equal", c.mismatches == 0},
           {"mismatches", c.mismatches},
           {"max_abs_diff", number(c.max_abs_diff)}};
    o["worst"] =
        have_cells(r) ? cell(c.worst_row, c.worst_t, c.worst_a, c.worst_b, c.worst_tol, c.worst_ratio) : Json(nullptr);
    j["columns"].push_back(o);
  }
  return json_text(j, 2) + "\n";
}

std::string compare_junit(const CompareSubject& s, const CompareResult& r) {
  struct Case {
    std::string name, failure;  // failure: empty when it passed
  };
  std::vector<Case> cases;
  for (const ColumnComparison& c : r.per_column)
    cases.push_back({c.column, c.mismatches == 0 ? "" : column_failure(c)});
  // a column in one file only fails, unless --columns chose the columns: then only those are cases
  if (!r.columns_restricted) {
    for (const std::string& c : r.only_in_a) cases.push_back({c, "only in " + s.a + " (not in " + s.b + ")"});
    for (const std::string& c : r.only_in_b) cases.push_back({c, "only in " + s.b + " (not in " + s.a + ")"});
  }
  cases.push_back({"(row count)", r.rows_a == r.rows_b ? ""
                                                       : s.a + " has " + std::to_string(r.rows_a) + " rows, " + s.b +
                                                             " has " + std::to_string(r.rows_b)});
  std::size_t failures = 0;
  for (const Case& c : cases) failures += !c.failure.empty();
  const std::string counts =
      " tests=\"" + std::to_string(cases.size()) + "\" failures=\"" + std::to_string(failures) + "\" errors=\"0\"";
  std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x += "<testsuites name=\"phiq compare\"" + counts + ">\n";
  x += "  <testsuite name=\"" + xml(s.a + " vs " + s.b) + "\"" + counts + " skipped=\"0\">\n";
  x += "    <properties>\n      <property name=\"rtol\" value=\"" + shortest(s.options.rtol) +
       "\"/>\n      <property name=\"atol\" value=\"" + shortest(s.options.atol) + "\"/>\n    </properties>\n";
  for (const Case& c : cases) {
    x += "    <testcase classname=\"" + xml(s.b) + "\" name=\"" + xml(c.name) + "\"";
    if (c.failure.empty()) {
      x += "/>\n";
    } else {
      x += ">\n      <failure type=\"mismatch\" message=\"" + xml(c.failure) + "\">" + xml(c.failure) +
           "</failure>\n    </testcase>\n";
    }
  }
  x += "  </testsuite>\n</testsuites>\n";
  return x;
}

}  // namespace phiq::tools
