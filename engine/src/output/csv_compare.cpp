#include "phiq/csv_compare.hpp"
#include "phiq/csv_writer.hpp"  // identifier_column_name

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string_view>
#include <unordered_map>

#include "phiq/text.hpp"

namespace phiq {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

bool is_blank(std::string_view s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; });
}

// A field or name as it appears in a message: messages are one line, and a garbage field can be a whole binary
// file without commas, so control characters are escaped and long text is cut.
std::string shown(std::string_view s) {
  constexpr std::size_t kMax = 40;
  std::string out;
  for (std::size_t i = 0; i < s.size() && i < kMax; ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  if (s.size() > kMax) out += "...";
  return out;
}

enum class NumberStatus { kOk, kNotANumber, kOverflow };

NumberStatus parse_number(std::string_view f, double& v) {
  f = trim(f);
  const char* b = f.data();
  const char* e = b + f.size();
  // from_chars rejects '+', which other tools write; "+-1" must stay an error.
  if (b != e && *b == '+' && (e - b == 1 || b[1] != '-')) ++b;
  if (b == e) return NumberStatus::kNotANumber;
  auto [p, ec] = std::from_chars(b, e, v);
  if (p != e) return NumberStatus::kNotANumber;
  if (ec == std::errc::result_out_of_range) {
    // from_chars does not say which way it is out of range; strtod does (±HUGE_VAL, or the underflowed value).
    // Rare path, so the copy does not matter.
    const std::string copy(b, e);
    const double w = std::strtod(copy.c_str(), nullptr);
    if (std::isinf(w)) return NumberStatus::kOverflow;
    v = w;
    return NumberStatus::kOk;
  }
  return ec == std::errc() ? NumberStatus::kOk : NumberStatus::kNotANumber;
}

// Splits text into lines without copying; strips "\r" of "\r\n" and counts 1-based line numbers.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    const std::size_t nl = text_.find('\n', pos_);
    const std::size_t end = nl == std::string_view::npos ? text_.size() : nl;
    line = text_.substr(pos_, end - pos_);
    pos_ = nl == std::string_view::npos ? text_.size() : nl + 1;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    ++number_;
    return true;
  }
  std::size_t number() const { return number_; }
  std::string_view rest() const { return text_.substr(pos_); }

 private:
  std::string_view text_;
  std::size_t pos_ = 0, number_ = 0;
};

std::string fmt_list(const std::vector<std::string>& names) {
  if (names.empty()) return "(none)";
  // A header can have thousands of columns; the line stays readable and the full lists are in the result.
  constexpr std::size_t kMax = 10;
  std::string s;
  for (std::size_t i = 0; i < names.size() && i < kMax; ++i) s += (i ? ", " : "") + names[i];
  if (names.size() > kMax) s += ", ... (" + std::to_string(names.size() - kMax) + " more)";
  return s;
}

std::string plural(std::size_t n, const char* word) { return std::to_string(n) + " " + word + (n == 1 ? "" : "s"); }

void check_tolerance(const char* name, double v) {
  if (!(v >= 0.0)) throw Error(std::string("compare_csv: ") + name + " must be >= 0, got " + shortest(v));
}

std::string table_name(const CsvTable& t, const char* fallback) { return t.path.empty() ? fallback : t.path; }

}  // namespace

CsvTable parse_csv_table(const std::string& text, const std::string& path) {
  CsvTable table;
  table.path = path;
  auto fail = [&](std::size_t line, const std::string& what) {
    throw Error(path + ":" + std::to_string(line) + ": " + what);
  };

  std::string_view all(text);
  if (all.substr(0, 3) == "\xEF\xBB\xBF") all.remove_prefix(3);
  LineReader lines(all);
  std::string_view line;
  if (!lines.next(line)) fail(1, "empty file, expected a header line");
  if (is_blank(line)) fail(1, "missing header line (the first line is blank)");

  std::unordered_map<std::string_view, std::size_t> seen;
  bool all_numbers = true;
  for (std::size_t start = 0;;) {
    const std::size_t comma = line.find(',', start);
    const std::string_view name = trim(line.substr(start, comma == std::string_view::npos ? comma : comma - start));
    const std::size_t col = table.columns.size() + 1;
    if (name.empty()) fail(1, "column " + std::to_string(col) + " has an empty name");
    // (a file separated by tabs or semicolons reads as one column whose name holds them: its rows are then blamed)
    if (const std::size_t sep = name.find_first_of("\t;"); sep != std::string_view::npos)
      fail(1, "the header's column '" + shown(name) + "' holds a " + (name[sep] == ';' ? "semicolon" : "tab") +
                  ": the values must be separated by commas");
    auto [it, fresh] = seen.emplace(name, col);
    if (!fresh)
      fail(1, "duplicate column name '" + shown(name) + "' (columns " + std::to_string(it->second) + " and " +
                  std::to_string(col) + ")");
    double v;
    all_numbers = all_numbers && parse_number(name, v) == NumberStatus::kOk;
    table.columns.emplace_back(name);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  // A file without its header would otherwise be read as a table whose columns are named "0", "0.3", ...
  if (all_numbers) fail(1, "missing header line (the first line is all numbers)");

  const std::size_t ncols = table.columns.size();
  table.rows.reserve(static_cast<std::size_t>(std::count(all.begin(), all.end(), '\n')));
  while (lines.next(line)) {
    if (is_blank(line)) {
      if (is_blank(lines.rest())) break;  // trailing blank lines: harmless
      fail(lines.number(), "blank line before the last row");
    }
    const std::size_t nfields = 1 + static_cast<std::size_t>(std::count(line.begin(), line.end(), ','));
    if (nfields != ncols) fail(lines.number(), plural(nfields, "field") + ", the header has " + std::to_string(ncols));
    std::vector<double> row(ncols);
    std::size_t start = 0;
    for (std::size_t j = 0; j < ncols; ++j) {
      const std::size_t comma = j + 1 < ncols ? line.find(',', start) : line.size();
      const std::string_view field = line.substr(start, comma - start);
      switch (parse_number(field, row[j])) {
        case NumberStatus::kOk:
          break;
        case NumberStatus::kNotANumber:
          fail(lines.number(), "column '" + table.columns[j] + "': '" + shown(trim(field)) + "' is not a number");
          break;
        case NumberStatus::kOverflow:
          fail(lines.number(),
               "column '" + table.columns[j] + "': '" + shown(trim(field)) + "' is out of the range of a double");
          break;
      }
      start = comma + 1;
    }
    table.rows.push_back(std::move(row));
  }
  return table;
}

CsvTable read_csv_table(const std::string& path) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) throw Error(path + ": cannot read: " + std::strerror(errno));
  std::string text;
  char buf[1 << 16];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f.get())) > 0) text.append(buf, n);
  // fopen succeeds on a directory on Linux; the error shows up here (EISDIR).
  if (std::ferror(f.get())) throw Error(path + ": cannot read: " + std::strerror(errno));
  return parse_csv_table(text, path);
}

CompareResult compare_csv(const CsvTable& a, const CsvTable& b, const CompareOptions& options) {
  check_tolerance("rtol", options.rtol);
  check_tolerance("atol", options.atol);

  std::unordered_map<std::string_view, std::size_t> index_a, index_b;
  for (std::size_t j = 0; j < a.columns.size(); ++j) index_a.emplace(a.columns[j], j);
  for (std::size_t j = 0; j < b.columns.size(); ++j) index_b.emplace(b.columns[j], j);
  // A column whose name is in one file only is matched with one of the other file that has the same identifier
  // form (`theta2.v` against `theta2__v`: the two namings of `phiq run --names`), when exactly one has it.
  {
    std::unordered_map<std::string, std::size_t> ident_b;  // identifier form -> B's column (SIZE_MAX: several)
    for (std::size_t j = 0; j < b.columns.size(); ++j)
      if (!index_a.count(b.columns[j])) {
        auto [it, fresh] = ident_b.emplace(identifier_column_name(b.columns[j]), j);
        if (!fresh) it->second = SIZE_MAX;
      }
    std::vector<std::pair<std::size_t, std::size_t>> aliases;
    std::unordered_map<std::string, std::size_t> ident_a;
    for (std::size_t j = 0; j < a.columns.size(); ++j)
      if (!index_b.count(a.columns[j])) ++ident_a[identifier_column_name(a.columns[j])];
    for (std::size_t j = 0; j < a.columns.size(); ++j) {
      if (index_b.count(a.columns[j])) continue;
      const std::string id = identifier_column_name(a.columns[j]);
      const auto it = ident_b.find(id);
      if (it != ident_b.end() && it->second != SIZE_MAX && ident_a[id] == 1) aliases.emplace_back(j, it->second);
    }
    for (const auto& [ja, jb] : aliases) index_b.emplace(a.columns[ja], jb), index_a.emplace(b.columns[jb], ja);
  }

  CompareResult r;
  r.rows_a = a.rows.size();
  r.rows_b = b.rows.size();
  r.columns_restricted = !options.columns.empty();
  for (const auto& c : a.columns)
    if (!index_b.count(c)) r.only_in_a.push_back(c);
  for (const auto& c : b.columns)
    if (!index_a.count(c)) r.only_in_b.push_back(c);

  // (index in A, index in B) of each compared column, in A's order.
  std::vector<std::pair<std::size_t, std::size_t>> cols;
  if (r.columns_restricted) {
    for (const auto& c : options.columns) {
      if (!index_a.count(c)) throw Error("column '" + c + "' is not in " + table_name(a, "A"));
      if (!index_b.count(c)) throw Error("column '" + c + "' is not in " + table_name(b, "B"));
    }
    std::vector<bool> wanted(a.columns.size(), false);
    for (const auto& c : options.columns) wanted[index_a.at(c)] = true;  // also drops repeated names
    for (std::size_t j = 0; j < a.columns.size(); ++j)
      if (wanted[j]) cols.emplace_back(j, index_b.at(a.columns[j]));
  } else {
    for (std::size_t j = 0; j < a.columns.size(); ++j) {
      auto it = index_b.find(a.columns[j]);
      if (it != index_b.end()) cols.emplace_back(j, it->second);
    }
  }
  for (const auto& [ja, jb] : cols) r.compared.push_back(a.columns[ja]);
  r.per_column.resize(cols.size());
  std::vector<double> column_worst(cols.size(), -1.0);
  for (std::size_t c = 0; c < cols.size(); ++c) r.per_column[c].column = r.compared[c];

  const auto t_it = index_a.find("t");
  const std::size_t nrows = std::min(r.rows_a, r.rows_b);
  const double inf = std::numeric_limits<double>::infinity();
  double worst = -1.0;  // below any ratio, so the first cell becomes the worst when all agree
  std::size_t worst_ja = 0, worst_jb = 0;
  std::size_t max_diff_col = a.columns.size();
  for (std::size_t i = 0; i < nrows; ++i) {
    const std::vector<double>& ra = a.rows[i];
    const std::vector<double>& rb = b.rows[i];
    for (std::size_t c = 0; c < cols.size(); ++c) {
      const auto [ja, jb] = cols[c];
      const double x = ra[ja], y = rb[jb];
      double diff, ratio, tol = 0.0;
      bool bad;
      if (x == y || (std::isnan(x) && std::isnan(y))) {
        diff = 0.0, ratio = 0.0, bad = false;  // also +inf == +inf, and 0 == -0
      } else if (std::isnan(x) || std::isnan(y) || std::isinf(x) || std::isinf(y)) {
        diff = inf, ratio = inf, bad = true;  // unequal and one of them not finite: no tolerance covers it
      } else {
        diff = std::fabs(x - y);  // may overflow to inf for ±1e308: still beyond any finite tolerance
        tol = options.atol + options.rtol * std::max(std::fabs(x), std::fabs(y));
        // Decide on diff > tol, not ratio > 1: the rounded quotient can be 1 when diff is just above tol.
        bad = diff > tol;
        ratio = tol > 0.0 ? diff / tol : inf;
      }
      if (bad) ++r.mismatches;
      if (diff > r.max_abs_diff) r.max_abs_diff = diff, max_diff_col = ja;
      ColumnComparison& col = r.per_column[c];
      col.mismatches += bad;
      col.max_abs_diff = std::max(col.max_abs_diff, diff);
      if (ratio > column_worst[c]) {
        column_worst[c] = col.worst_ratio = ratio;
        col.worst_row = i, col.worst_a = x, col.worst_b = y, col.worst_tol = tol;
        if (t_it != index_a.end()) col.worst_t = ra[t_it->second];
      }
      if (ratio > worst) {
        worst = ratio;
        r.worst_tol = tol;
        r.worst_row = i;
        worst_ja = ja, worst_jb = jb;
      }
    }
  }
  if (worst >= 0.0) {
    r.worst_column = a.columns[worst_ja];
    r.worst_a = a.rows[r.worst_row][worst_ja];
    r.worst_b = b.rows[r.worst_row][worst_jb];
    r.worst_ratio = worst;
    if (t_it != index_a.end()) r.worst_t = a.rows[r.worst_row][t_it->second];
  }
  if (max_diff_col < a.columns.size()) r.max_abs_diff_column = a.columns[max_diff_col];

  r.equal = r.mismatches == 0 && r.rows_a == r.rows_b &&
            (r.columns_restricted || (r.only_in_a.empty() && r.only_in_b.empty()));
  return r;
}

std::string CompareResult::summary() const {
  const bool header_diff = !only_in_a.empty() || !only_in_b.empty();
  const std::string headers = "columns only in A: " + fmt_list(only_in_a) + "; only in B: " + fmt_list(only_in_b);
  const std::size_t nrows = std::min(rows_a, rows_b);
  const std::string cells = plural(nrows, "row") + " x " + plural(compared.size(), "column");
  std::string detail;
  if (nrows > 0 && !compared.empty())
    detail = max_abs_diff == 0.0 ? " (identical)"
                                 : " (max |diff| " + significant(max_abs_diff, 3) + " in " + max_abs_diff_column + ")";

  if (equal) {
    std::string s = "agree: " + cells + detail;
    if (header_diff) s += "; not compared: " + headers;
    return s;
  }

  std::string s = "differ: ";
  if (mismatches > 0) {
    // the line of both files (the header is line 1), as the parse errors count
    s += plural(mismatches, "cell") + " beyond tolerance; worst " + worst_column + " at line " +
         std::to_string(worst_row + 2);
    if (!std::isnan(worst_t)) s += " (t = " + shortest(worst_t) + ")";
    s += ": " + shortest(worst_a) + " vs " + shortest(worst_b);
    if (std::isnan(worst_a) || std::isnan(worst_b)) {
      s += " (NaN against a number)";
    } else if (std::isinf(worst_a) || std::isinf(worst_b)) {
      s += " (infinity against a different value)";
    } else {
      const double diff = std::fabs(worst_a - worst_b);
      std::string d = significant(diff, 3), t = significant(worst_tol, 3);
      if (d == t) d = shortest(diff), t = shortest(worst_tol);  // 3 digits hid the difference
      s += " (|diff| " + d + " > tol " + t + ")";
    }
  } else if (compared.empty()) {
    s += "no shared columns";
  } else {
    s += "the shared " + cells + " agree" + detail;
  }
  if (rows_a != rows_b)
    s += "; row counts differ: A has " + plural(rows_a, "row") + ", B has " + std::to_string(rows_b);
  if (header_diff) s += std::string("; ") + (columns_restricted ? "not compared: " : "") + headers;
  return s;
}

}  // namespace phiq
