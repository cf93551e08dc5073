/// @file
/// A ClearanceReport (phiq/clearance.hpp) as files: the CSV of each pair's distance per row and the HDF5 file of
/// `phiq clearance -o OUT.h5` (layout in tools/README.md, "phiq clearance"), which holds the same columns as the
/// very doubles the CSV's text reads back to, and the summary: each pair's worst pose with its witness points and
/// sensitivities, the interference intervals, and whether the bound between rows held.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "phiq/clearance.hpp"

namespace phiq {

/// Clearance HDF5 format version: the root attribute `format_version` of a file whose `format` is
/// "phiq clearance" (tools/README.md).
inline constexpr int kClearanceHdf5Format = 3;  // 3: /minima holds each minimum's sensitivities

/// `phiq clearance --summary` JSON format version (the `format` field; tools/README.md).
inline constexpr int kClearanceSummaryFormat = 1;

/// Each reported pair's name, `A.B` (the parts' names), in the report's order: the CSV's and HDF5's columns.
/// Pre-condition: the report was measured on `parts`.
std::vector<std::string> clearance_pair_names(const ClearanceReport& report, const std::vector<Part>& parts);

/// The CSV text: `t`, then each pair's signed distance (m), one line per row, numbers as phiq::shortest() writes
/// them (they read back to the same doubles).
std::string clearance_csv(const ClearanceReport& report, const std::vector<Part>& parts);

/// What write_clearance_hdf5() records besides the report.
struct ClearanceHdf5Options {
  std::string scene_path;  ///< root attribute `scene_path`
  std::string scene_text;  ///< root attribute `scene`: the scene's text
  /// Root attributes `parameter_names` and `parameter_values` (none when empty), as Hdf5Options has them.
  std::vector<std::pair<std::string, double>> parameters;
  /// The path errors name, when the file is written under another (the CLI's temporary); empty: the path.
  std::string shown_path;
};

/// Writes `report` (measured on `parts`) as an HDF5 file at `path` (created or truncated): no creation times, so
/// that the same report writes the same bytes. Throws phiq::Error "PATH: cannot write: REASON".
void write_clearance_hdf5(const std::string& path, const ClearanceReport& report, const std::vector<Part>& parts,
                          const ClearanceHdf5Options& options = {});

}  // namespace phiq
