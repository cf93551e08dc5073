/// @file
/// Reading HDF5 results (hdf5_writer.hpp) back as the table their CSV would parse to, so that `phiq compare`
/// and compare_csv() take either format on either side.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "phiq/csv_compare.hpp"

namespace phiq {

/// True when `path` ends in `.h5` or `.hdf5`, in any case: the names phiq reads and writes as HDF5.
bool has_hdf5_extension(const std::string& path);

/// True when the file at `path` begins with the HDF5 signature (\\x89 H D F \\r \\n \\x1a \\n). False for a file that
/// cannot be read or is shorter.
bool is_hdf5_file(const std::string& path);

/// Reads HDF5 results of format version kHdf5Format: the datasets /case (a batch's file), /t, /q, /qd, /qdd, /points,
/// /drivers, /residuals, /rcond that are present, in that order, their columns named by each dataset's `columns`
/// attribute.
/// @return The table, columns and rows in the order of the CSV of the same run, with CsvTable::path = `path`.
/// @throws phiq::Error with one line "PATH: what is wrong" for a file that is not HDF5 or cannot be opened
///         ("PATH: not a readable HDF5 file: REASON"), another format or version, a missing or malformed `columns`
///         attribute, a dataset that is not floating point, of rank above 2, or whose row count differs from /t's,
///         or a duplicate column name.
CsvTable read_hdf5_table(const std::string& path);

/// How an HDF5 result was made: the root attributes its writer records (hdf5_writer.hpp).
struct Hdf5Provenance {
  std::string scene_path;  ///< `scene_path`: the scene as the run named it
  std::string scene_text;  ///< `scene`: the scene's text
  /// `parameter_names` and `parameter_values`: the values the run used (its --set applied); empty when absent
  std::vector<std::pair<std::string, double>> parameters;
};

/// The provenance of the HDF5 results at `path`. Throws phiq::Error as read_hdf5_table() does for a file that is
/// not phiq's results, and "PATH: attribute 'NAME' is missing" (or of another type) for one without them.
Hdf5Provenance read_hdf5_provenance(const std::string& path);

/// read_hdf5_table() for a file with the HDF5 signature or a name ending in .h5 / .hdf5, read_csv_table()
/// otherwise; throws what they throw.
CsvTable read_result_table(const std::string& path);

/// Turns HDF5's own printing of errors off for the rest of the process. phiq reports HDF5's errors as lines of its
/// own (HDF5 is silenced while phiq reads and writes), but HDF5 1.10 also prints when the process exits: "HDF5:
/// infinite loop closing library" and a dump, after a corrupt file's metadata failed to load (it keeps blocks it
/// cannot release). A program whose errors are phiq's lines (the `phiq` command) calls this first; one that uses
/// HDF5 itself keeps HDF5's printing.
void silence_hdf5_errors();

/// True when an HDF5 file phiq wrote could not be closed (its last flush failed: a full disk, a file-size limit).
/// HDF5 1.10 then crashes closing it again when the process exits; a program that has reported the error and
/// committed its other outputs ends with std::_Exit instead (the `phiq` command does).
bool hdf5_file_left_open();

}  // namespace phiq
