/// @file
/// FreeCAD Assembly / OndselSolver `.asmt` files read as phiq scenes. The file is converted to the text of a phiq
/// scene (models/README.md), which load_scene() then reads: one source of truth for the model, and `phiq convert`
/// writes that same text. Parts become bodies (Euler parameters), markers the sides of joints, joints phiq's
/// spatial kinds, motions joint drivers with expression laws, SimulationParameters the time grid.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "phiq/csv_compare.hpp"
#include "phiq/import_model.hpp"  // ImportOptions

namespace phiq {

/// What import_asmt() made of a file.
struct AsmtImport {
  std::string yaml;                  ///< the phiq scene (dimension 3, lengths in the file's unit: FreeCAD's mm)
  std::vector<std::string> skipped;  ///< "FILE:LINE: what: why not mapped", once each (also comments in `yaml`)
  int parts = 0;                     ///< parts read (each a body)
  int joints = 0;                    ///< joints read (each one or more constraints)
  int motions = 0;                   ///< motions read (each a driver)
  /// each part's name in the file and its body's in the scene (they differ where the name is no phiq name)
  std::vector<std::pair<std::string, std::string>> bodies;
};

/// Converts the text of an `.asmt` file; `path` names it in messages. Throws SceneError, one line "PATH:LINE: what"
/// for a file that is truncated, malformed, or holds an element phiq cannot represent exactly (a joint type with
/// no phiq kind, a marker of an unknown part, ...): never an approximation. Of `options`, only
/// `rates`, `forces` and `gravity` (in the file's length unit per s²) apply (an `.asmt` file has its motions and
/// time grid).
AsmtImport import_asmt(const std::string& text, const std::string& path, const ImportOptions& options = {});

/// import_asmt() of the file at `path`, read as load_scene() reads a scene (its size limit; FIFOs, directories and
/// devices handled as there). Throws SceneError "PATH: REASON" when it cannot be read, and as import_asmt().
AsmtImport import_asmt_file(const std::string& path, const ImportOptions& options = {});

/// True when `path` ends in `.asmt` (any case): what load_scene() and the command line convert first.
bool is_asmt_path(const std::string& path);

/// One part's stored results in an `.asmt` file's TimeSeries.
struct AsmtPartSeries {
  std::string name;                          ///< the part's name as the file writes it (`/Assembly/Part` → `Part`)
  std::vector<std::vector<double>> columns;  ///< X Y Z Bryantx Bryanty Bryantz ..., each over the output times
  std::vector<std::string> labels;           ///< the row labels, in the file's order
};

/// One joint's or motion's stored forces in an `.asmt` file's TimeSeries (`RevoluteJointSeries /Asm/NAME`, ...):
/// rows FXonI, FYonI, FZonI (the force on marker I's part) and TXonI, TYonI, TZonI (the moment about marker I's
/// origin), world components, as OndselSolver's ASMTConstraintSet::updateFromMbD() writes them.
struct AsmtItemSeries {
  std::string type;  ///< the series' word without `Series` (`RevoluteJoint`, `RotationalMotion`)
  std::string name;  ///< the joint's or motion's name (`/Assembly/NAME` → `NAME`)
  std::vector<std::vector<double>> columns;  ///< each row over the output times
  std::vector<std::string> labels;           ///< the row labels, in the file's order
};

/// The TimeSeries of an `.asmt` file: output times (the file's `Input` column dropped), each part's rows, and each
/// joint's and motion's.
struct AsmtTimeSeries {
  std::vector<double> time;           ///< the output times
  std::vector<AsmtPartSeries> parts;  ///< each part's rows, in the file's order
  std::vector<AsmtItemSeries> items;  ///< each joint's and motion's rows, in the file's order
};

/// Reads the TimeSeries after the assembly (empty when the file has none). Throws SceneError naming FILE:LINE for a
/// row whose length differs from the times'.
AsmtTimeSeries read_asmt_time_series(const std::string& text, const std::string& path);

/// A phiq result and an `.asmt` file's TimeSeries as two tables of the same columns, for compare_csv(): `t`, then
/// per part of the TimeSeries `PART.X`, `PART.Y`, `PART.Z` (its reference point), `PART.Bryantx` … `PART.Bryantz`
/// (rotation Rx·Ry·Rz), and, where the result holds velocities, `PART.VX` … `PART.OmegaZ` (Ω in the world frame),
/// where it holds accelerations `PART.AX` … `PART.AlphaZ`: the TimeSeries' own names and units. Then, where the
/// result holds a joint's reaction (`JOINT.Fx` … `JOINT.Mz`) or a motion's effort (`MOTION.effort`), `ITEM.FXonI` …
/// `ITEM.TZonI`: phiq's reaction (on side 1, about its point) turned into the force on marker I's part and the
/// moment about marker I's origin (negated when marker I is on the ground: phiq reports on the other side); a
/// RotationalMotion's effort τ as the torque −τ z_I on marker I's part (τ turns J about I's z), a
/// TranslationalMotion's as the force −τ z_I.
struct AsmtComparison {
  CsvTable result;                    ///< the phiq result's quantities, from its bodies' x, y, z, e0..e3 (and rates)
  CsvTable series;                    ///< the TimeSeries' rows (its `Input` column dropped)
  std::vector<std::string> left_out;  ///< quantities of the TimeSeries not compared, and why, one line each
};

/// The tables to compare between `result` (a `phiq run` of the file, dotted or identifier column names) and the
/// TimeSeries of the `.asmt` file at `asmt_path`. A result's Bryant angle is taken modulo 2π nearest the stored one
/// (a turn is no difference); other differences, a gear's other branch included, are kept. Throws SceneError naming
/// the file for one that cannot be imported or holds no TimeSeries, and Error "RESULT: ..." for a result that lacks
/// a part's x, y, z, e0..e3 columns.
AsmtComparison asmt_comparison(const CsvTable& result, const std::string& asmt_path);

}  // namespace phiq
