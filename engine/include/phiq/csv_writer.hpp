/// @file
/// Results as CSV: header `t, <coordinate>..., <coordinate>.v..., <coordinate>.a...`, one row per time point.
/// Numbers are written in the shortest form that reads back to the same double (std::to_chars), so a CSV compares
/// exactly with the run that wrote it.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "phiq/sweep.hpp"

namespace phiq {

/// The columns of a result CSV (format version kCsvFormat) and the formatting of its rows. Thread-safe (const).
class CsvFormat {
 public:
  /// `columns`: coordinate indices to write, in order; `velocities` / `accelerations`: add the `.v` / `.a` groups.
  /// Throws phiq::Error for an index out of range. The model must outlive the CsvFormat.
  CsvFormat(const Model& model, std::vector<Index> columns, bool velocities, bool accelerations);
  /// The header line, with '\\n'.
  std::string header() const;
  /// Appends one line (with '\n') for this step. Pre-condition: the step carries qd / qdd when they are columns.
  void append_row(const StepView& step, std::string& out) const;

 private:
  const Model& model_;
  std::vector<Index> columns_;
  bool velocities_, accelerations_;
};

/// An output file that appears only when complete: written under a temporary name in the same directory and
/// renamed onto `path` by commit(). If it is destroyed without commit() (failure, exception), the temporary is
/// removed and an existing file at `path` is left untouched.
class AtomicOutputFile {
 public:
  explicit AtomicOutputFile(std::string path);  ///< throws phiq::Error if the temporary cannot be created
  ~AtomicOutputFile();
  AtomicOutputFile(const AtomicOutputFile&) = delete;
  AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;

  void write(const std::string& data);  ///< throws phiq::Error on an I/O error
  void commit();                        ///< throws phiq::Error on an I/O error

 private:
  std::string path_, tmp_;
  std::FILE* f_ = nullptr;
  bool committed_ = false;
};

}  // namespace phiq
