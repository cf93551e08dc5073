/// @file
/// Results as CSV: header `t, <coordinate>..., <coordinate>.v..., <coordinate>.a...`, then the other outputs an output
/// plan lists (points, drivers, residuals, rcond; tools/README.md), one row per time point.
/// Numbers are written in the shortest form that reads back to the same double (std::to_chars), so a CSV compares
/// exactly with the run that wrote it.
#pragma once

#include <string>
#include <vector>

#include "phiq/output_plan.hpp"  // OutputPlan, StepView

namespace phiq {

class Model;  // model.hpp: CsvFormat keeps a reference, its source reads it

/// How the columns of a result CSV are named (tools/README.md, `phiq run --names`).
enum class ColumnNaming {
  /// `theta2.v`, `B.x`, `motor.f`: the scene's names with the quantity after a dot (CSV format 1's default).
  kDotted,
  /// Python identifiers that numpy.genfromtxt(names=True) and pandas attribute access keep as they are:
  /// identifier_column_name() of the dotted name (`theta2__v`, `B__x`, `motor__f`).
  kIdentifiers,
};

/// The identifier form of a dotted column name: each '.' written "__", any other character that is not an ASCII
/// letter, digit or '_' written '_', and a leading digit preceded by '_' (`theta2.v` → `theta2__v`). Not
/// one-to-one by itself: CsvFormat::set_naming() refuses the columns whose forms collide.
std::string identifier_column_name(const std::string& dotted);

/// The columns of a result CSV (format version kCsvFormat) and the formatting of its rows. Thread-safe (const).
class CsvFormat {
 public:
  /// `columns`: coordinate indices to write, in order; `velocities` / `accelerations`: add the `.v` / `.a` groups.
  /// Throws phiq::Error for an index out of range. The model must outlive the CsvFormat and not move (it keeps the
  /// model's address, unlike a Workspace).
  CsvFormat(const Model& model, std::vector<Index> columns, bool velocities, bool accelerations);
  /// Every column the output plan lists, in the order of tools/README.md: t; coordinates, `.v`, `.a`; per point
  /// `P.x, P.y` (`P.vx, P.vy`, `P.ax, P.ay`); per driver `D.f` (`D.df`, `D.ddf`); per constraint `C.residual`;
  /// `residual`; `rcond`. Throws phiq::Error for an index out of range. The model and the plan must outlive the
  /// CsvFormat.
  CsvFormat(const Model& model, const OutputPlan& plan);
  /// Names the columns so (ColumnNaming::kDotted unless set). Throws phiq::Error, leaving the naming unchanged,
  /// for kIdentifiers when two columns would get the same name (a coordinate `theta2__v` beside the velocity of
  /// `theta2`), or a column's would be a Python keyword or one genfromtxt renames (`return`, `file`, `print`): the
  /// message names the columns.
  void set_naming(ColumnNaming naming);
  /// The column names, "t" first.
  std::vector<std::string> column_names() const;
  /// The header line, with '\\n'.
  std::string header() const;
  /// Appends one line (with '\n') for this step. Pre-condition: the step carries qd / qdd when they are columns
  /// (throws phiq::Error otherwise, or when its vectors are not the model's size). A wide row (more than 1 024
  /// coordinate values) is formatted in parallel by the current task arena's threads: `phiq run --threads 1` is one.
  void append_row(const StepView& step, std::string& out) const;
  /// At most how many characters append_row() appends (every value at its longest shortest round-trip text).
  std::size_t max_row_chars() const;
  /// The number of columns after the coordinates' (points, drivers, residuals, rcond): 0 without an output plan.
  std::size_t num_output_values() const;
  /// Writes those columns' values for this step to out[0 .. num_output_values()), as append_row() formats them
  /// (the HDF5 writer's row: the same doubles as the CSV's). Throws phiq::Error as append_row() does.
  void append_output_values(const StepView& step, double* out) const;
  /// The same values, −0 as 0 (stored_value()), straight into `count` consecutive slices: the next sizes[i] of them
  /// to out[i] (the HDF5 writer's datasets' rows, with no row in between). Pre-condition: the sizes add up to
  /// num_output_values(). Throws phiq::Error as append_row() does.
  void append_output_values(const StepView& step, double* const* out, const std::size_t* sizes,
                            std::size_t count) const;
  /// The number of columns of a row, t's included: column_names().size().
  std::size_t num_values() const;
  /// Writes the whole row's values for this step to out[0 .. num_values()): t, the coordinates' columns, then
  /// append_output_values()' — the doubles append_row() formats, −0 written as 0 as it writes it (what a result
  /// held in memory keeps: Python's run_sweep table, a batch's HDF5 rows). Throws phiq::Error as append_row() does.
  void append_values(const StepView& step, double* out) const;

 private:
  const Model& model_;
  std::vector<Index> columns_, v_columns_, a_columns_;  // the q, q̇ and q̈ columns
  bool velocities_, accelerations_;   // q̇ / q̈ are delivered: the points' and drivers' derivative columns too
  const OutputPlan* plan_ = nullptr;  // the other outputs, when made from an output plan
  ColumnNaming naming_ = ColumnNaming::kDotted;
  std::vector<std::string> dotted_names() const;       // the names of format 1
  void check_coordinates(const StepView& step) const;  // throws unless the step carries the columns' vectors
  void append_coordinates(const StepView& step, std::string& out) const;  // the q, q̇, q̈ columns
  void append_outputs(const StepView& step, std::string& out) const;      // the columns after the coordinates
  // their values, in column order: emit(v) each, or emit(values, count) for a run of them where Emit takes one
  // (a copy rather than a text: the efforts and reactions, 3·10⁴ a row at nfourbar 10⁴)
  template <class Emit>
  void for_each_output(const StepView& step, Emit&& emit) const;
};

/// `v` as the result files hold it: −0 as 0 (the CSV's text), every other double unchanged. (v + 0 is exactly that,
/// one addition, which a loop over a row vectorises.)
inline double stored_value(double v) { return v + 0.0; }

}  // namespace phiq
