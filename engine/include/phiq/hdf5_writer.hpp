/// @file
/// Results as HDF5 (format version kHdf5Format; layout in tools/README.md, "HDF5 results"): the columns a CSV of
/// the same output plan has (CsvFormat), as one chunked, extendible dataset per group — /t, /q, /qd, /qdd,
/// /points, /drivers, /residuals, /rcond — holding the very doubles the CSV's text reads back to. Rows are
/// buffered and written a block at a time as the sweep delivers them, so that memory stays bounded at any length.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "phiq/csv_writer.hpp"
#include "phiq/output_plan.hpp"  // OutputPlan, StepView

namespace phiq {

class Model;  // model.hpp: read in the writer's source

/// HDF5 results format version: the root attribute `format_version` (tools/README.md, "HDF5 results").
inline constexpr int kHdf5Format = 1;

/// What an Hdf5Writer writes besides the rows, and how.
struct Hdf5Options {
  std::string scene_path;  ///< root attribute `scene_path` (where the scene was read from)
  std::string scene_text;  ///< root attribute `scene`: the scene's text, so that the file says how it was made
  /// Root attributes `parameter_names` and `parameter_values`: the scene's parameters with the values the run used
  /// (Scene::parameters: the caller's overrides, `phiq run --set`, applied), which the text alone does not say.
  /// None are written when it is empty.
  std::vector<std::pair<std::string, double>> parameters;
  /// The path errors name, when the file is written under another (the CLI's temporary); empty: the path.
  std::string shown_path;
  /// gzip (deflate) level 1–9 applied to every dataset, 0 for none. Off by default: on kinematic doubles it saves
  /// little and costs more time than the sweep (bench/README.md, "HDF5 results").
  int deflate = 0;
  bool shuffle = false;  ///< byte-shuffle before deflating (only with deflate > 0)
  /// The names in each dataset's `columns` attribute, as a CSV of this naming has them (`phiq run --names`):
  /// kIdentifiers so that the names h5py and pandas code reads are those of the CSV it was compared with.
  /// Throws what CsvFormat::set_naming() throws.
  ColumnNaming naming = ColumnNaming::kDotted;
  /// Rows the writer will be given (a sweep's steps + 1), or 0 if unknown: chunks are then sized so that the
  /// last one is not mostly empty (an uncompressed chunk takes its whole size on disk).
  std::size_t expected_rows = 0;
  /// Memory for the rows held between writes (at least one row is always held): the writer's memory, which
  /// does not grow with the number of rows.
  std::size_t buffer_bytes = std::size_t{16} << 20;
  /// A batch's file (`phiq batch -o OUT.h5`, layout version kHdf5BatchFormat): a first dataset /case (float64, one
  /// value per row: the row's case), and the root attribute `batch_format_version`. Rows are then given by
  /// append_values(), whose first value is the case.
  bool case_column = false;
  /// Opens the file at `path`, results of this layout written earlier (an interrupted batch's, copied: `phiq batch
  /// --resume`), and appends rows after its own, instead of creating it; its root attributes are kept. Each of
  /// the plan's datasets must be there with its columns and all with as many rows, else phiq::Error "PATH: cannot
  /// write: not results of this layout: …". The file's bytes then depend on how it was written, not its values.
  bool append = false;
  /// With `append`: the file's rows kept, those after them cut (a batch's last case, cut inside it, run again).
  std::size_t append_after_rows = static_cast<std::size_t>(-1);
};

/// Version of the batch layout (Hdf5Options::case_column): the run layout with a /case dataset first.
inline constexpr int kHdf5BatchFormat = 1;

/// Writes a sweep's rows to an HDF5 file as they are delivered. Not thread-safe: call append_row() from one
/// thread at a time (run_sweep's callback is). HDF5 errors are reported as phiq::Error; HDF5's own printing of
/// its error stack is silenced while the writer works.
class Hdf5Writer {
 public:
  /// Creates (or truncates) the file at `path` with the datasets of `plan` (CsvFormat's columns), the root
  /// attributes and each dataset's `columns` and `units`. The model and the plan must outlive the writer.
  /// Throws phiq::Error "PATH: cannot write: REASON" (an index out of range as CsvFormat does).
  Hdf5Writer(const std::string& path, const Model& model, const OutputPlan& plan, const Hdf5Options& options = {});
  /// Gives the file up if close() did not close it (not called, or failed): it is left incomplete, for the caller
  /// to remove, and errors are ignored.
  ~Hdf5Writer();
  Hdf5Writer(const Hdf5Writer&) = delete;
  Hdf5Writer& operator=(const Hdf5Writer&) = delete;

  /// Adds one row (pre-conditions as CsvFormat::append_row()). −0 is stored as 0, as the CSV writes it.
  /// Throws phiq::Error on a write error, after close(), or for a batch's file (Hdf5Options::case_column).
  void append_row(const StepView& step);
  /// Adds one row given as its values in column order: the case (with Hdf5Options::case_column), then what
  /// CsvFormat::append_row() writes (t, q, q̇, q̈, then CsvFormat::append_output_values()). For rows buffered
  /// before they are written (a batch's cases, written in case order). −0 is stored as 0. Throws phiq::Error as
  /// append_row() does.
  void append_values(const double* row);
  /// Adds the rows packed one after another in `packed`, each as append_values() takes it (row_values() doubles,
  /// native byte order, −0 written as 0 already, as CsvFormat::append_values() writes it): rows encoded on other
  /// threads (RowWriter) and written here in order. Throws phiq::Error as append_values() does, and when `packed`
  /// does not hold whole rows.
  void append_packed_rows(const std::string& packed);
  /// Values per row that append_values() takes.
  std::size_t row_values() const;
  /// Writes the rows still held and closes the file. Throws phiq::Error "PATH: cannot write: REASON".
  void close();
  /// Rows given so far.
  std::size_t rows() const;
  /// Rows written per block (the chunks' row count): what the writer holds in memory between writes.
  std::size_t block_rows() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace phiq
