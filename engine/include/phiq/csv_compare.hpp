/// @file
/// Reading result CSVs back and comparing two of them cell by cell with tolerances (regression suites).
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "phiq/types.hpp"

namespace phiq {

/// A CSV of numbers as phiq writes it (see csv_writer.hpp): one header line of column names, then one row of
/// numbers per time step.
struct CsvTable {
  std::string path;                       ///< Where the table came from; used in messages only.
  std::vector<std::string> columns;       ///< Column names from the header, in file order; unique and non-empty.
  std::vector<std::vector<double>> rows;  ///< Data rows in file order; each has columns.size() values.
};

/// Parses CSV text: a header line of column names, then rows of numbers.
///
/// Format: fields are separated by ',' (no quoting: phiq never writes commas inside names); spaces and tabs
/// around a field are ignored; lines end with "\n" or "\r\n" and the last one may lack its line end; a leading
/// UTF-8 byte order mark and blank lines at the end of the text are ignored (editors add them), a blank line
/// before the last row is an error. Numbers are anything std::from_chars reads as a double (plus an optional
/// leading '+'), so `nan`, `inf`, `-inf` and the shortest round-trip forms phiq writes are read exactly.
/// Values that underflow (`1e-400`) read as 0; values that overflow (`1e400`) are errors, since an infinity
/// nobody wrote would compare equal to a real one.
///
/// @param text               The whole CSV.
/// @param path_for_messages  Names the source in error messages and is stored in CsvTable::path.
/// @return The table; its rows all have columns.size() values.
/// @throws phiq::Error with a one-line message "PATH:LINE: what is wrong" (LINE is 1-based, the header is line 1)
///         for an empty text or a missing header line, an empty or duplicate column name, a row with the wrong
///         number of fields ("PATH:LINE: 12 fields, the header has 13"), or a field that is not a number
///         ("PATH:LINE: column 'xB': 'abc' is not a number").
/// @note Pure function: thread-safe.
CsvTable parse_csv_table(const std::string& text, const std::string& path_for_messages);

/// Reads the file at `path` and parses it with parse_csv_table().
///
/// @param path  File to read; it is read whole into memory.
/// @return The table, with CsvTable::path = `path`.
/// @throws phiq::Error "PATH: cannot read: REASON" if the file cannot be opened or read, and everything that
///         parse_csv_table() throws.
/// @note Thread-safe (it only reads the file).
CsvTable read_csv_table(const std::string& path);

/// Tolerances and column selection for compare_csv().
struct CompareOptions {
  double rtol = 1e-9;   ///< Relative tolerance; must be >= 0 (not NaN). +inf accepts any two numbers.
  double atol = 1e-12;  ///< Absolute tolerance; must be >= 0 (not NaN). Keeps values near 0 from failing on noise.
  /// Columns to compare. Empty: every column present in both tables, and the two headers must then have the same
  /// set of columns for the tables to be equal. Non-empty: exactly these columns (each must be in both tables),
  /// and other header differences are reported but do not make the tables unequal.
  std::vector<std::string> columns;
};

/// One compared column's comparison (CompareResult::per_column): its own worst cell, for reports that judge
/// column by column (JUnit test cases, `phiq compare --json`).
struct ColumnComparison {
  std::string column;          ///< Its name.
  std::size_t mismatches = 0;  ///< Its cells beyond tolerance.
  /// Its cell with the largest ratio |a-b| / tol (the first such row on ties); the fields below are valid when
  /// both tables have rows.
  std::size_t worst_row = 0;
  double worst_t = std::numeric_limits<double>::quiet_NaN();  ///< Column "t" of A at worst_row, NaN without one.
  double worst_a = 0;                                         ///< Value in A at its worst cell.
  double worst_b = 0;                                         ///< Value in B at its worst cell.
  double worst_tol = 0;     ///< Tolerance there, atol + rtol*max(|a|,|b|) (0 for NaN or inf against another value).
  double worst_ratio = 0;   ///< |a-b| / worst_tol there (inf for NaN or inf against another value).
  double max_abs_diff = 0;  ///< Largest |a-b| over its cells, counted as CompareResult::max_abs_diff.
};

/// What compare_csv() found. The "worst" fields describe the cell with the largest ratio
/// |a-b| / (atol + rtol*max(|a|,|b|)); they are valid when `compared` is non-empty and both tables have rows
/// (otherwise worst_column is empty). Ties go to the first such cell, rows first, then columns in A's order.
struct CompareResult {
  /// Every compared column agrees at every shared row, the row counts are equal, and (when CompareOptions::columns
  /// is empty) both headers have the same set of columns.
  bool equal = true;
  std::vector<std::string> compared;   ///< Columns compared, in A's order.
  std::vector<std::string> only_in_a;  ///< Columns of A missing from B, in A's order.
  std::vector<std::string> only_in_b;  ///< Columns of B missing from A, in B's order.
  /// CompareOptions::columns was given, so only_in_a / only_in_b do not affect `equal`.
  bool columns_restricted = false;
  std::size_t rows_a = 0;  ///< Data rows in A.
  std::size_t rows_b = 0;  ///< Data rows in B.

  std::string worst_column;   ///< Column of the worst cell.
  std::size_t worst_row = 0;  ///< 0-based data row of the worst cell (file line worst_row + 2).
  /// Value of column "t" in A at worst_row, NaN if A has no column "t".
  double worst_t = std::numeric_limits<double>::quiet_NaN();
  double worst_a = 0;      ///< Value in A at the worst cell.
  double worst_b = 0;      ///< Value in B at the worst cell.
  double worst_tol = 0;    ///< Tolerance at the worst cell, atol + rtol*max(|a|,|b|).
  double worst_ratio = 0;  ///< |a-b| / worst_tol; > 1 means beyond tolerance, inf for NaN vs number.
  /// Largest |a-b| over all compared cells (NaN vs NaN counts 0, NaN vs number and inf vs anything else count inf).
  double max_abs_diff = 0;
  std::string max_abs_diff_column;  ///< Column where max_abs_diff occurs (empty if max_abs_diff is 0).
  std::size_t mismatches = 0;       ///< Number of compared cells beyond tolerance.
  /// Each compared column's own comparison, in the order of `compared`.
  std::vector<ColumnComparison> per_column;

  /// One line for logs and test failures, e.g.
  /// "differ: 3 cells beyond tolerance; worst xB.a at line 19 (t = 0.29670597283903605): 1.25 vs 1.2500001
  /// (|diff| 1e-07 > tol 1.25e-09); row counts differ: A has 181 rows, B has 180; columns only in A: xB.a; only in
  /// B: (none)" or "agree: 181 rows x 13 columns (max |diff| 2.2e-16 in xA)". The worst cell's line is the line of
  /// both files (worst_row + 2: the header is line 1), as parse_csv_table()'s errors count them. Values a, b and t
  /// are printed exactly (shortest round-trip), so they can be searched for in the files.
  std::string summary() const;
};

/// Compares the shared columns of two tables row by row, over min(rows_a, rows_b) rows.
///
/// Columns are matched by name; a name found in one table only is matched with the other's column of the same
/// identifier_column_name() when each table has exactly one such unmatched column, so that a CSV with dotted names
/// (`theta2.v`) compares with one of `phiq run --names identifiers` (`theta2__v`). Results name A's columns.
///
/// A cell agrees when |a-b| <= atol + rtol*max(|a|,|b|). NaN agrees with NaN; NaN against a number is a mismatch
/// with an infinite ratio; an infinity agrees only with the same infinity.
///
/// @param a, b     The tables; `a` is the reference ("A") and fixes the column order of the result.
/// @param options  Tolerances and the columns to compare.
/// @return The comparison; see CompareResult::equal for what "equal" means.
/// @throws phiq::Error if rtol or atol is negative or NaN, or if options.columns names a column missing from
///         either table ("column 'foo' is not in B.csv", naming CsvTable::path).
/// @note Pure function: thread-safe.
CompareResult compare_csv(const CsvTable& a, const CsvTable& b, const CompareOptions& options = {});

}  // namespace phiq
