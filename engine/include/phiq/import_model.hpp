/// @file
/// Robot descriptions read as phiq scenes: URDF (through urdfdom), MJCF, MuJoCo's XML (through tinyxml2), and SDF
/// (through libsdformat), beside
/// FreeCAD's `.asmt` (phiq/import_asmt.hpp). Each file is converted to the text of a phiq scene (models/README.md),
/// which load_scene() then reads, so `phiq convert` writes the very text a direct read solves. Links and bodies
/// become bodies (Euler parameters, the model's pose as the guess) with their inertials and geometry as parts, joints
/// phiq's spatial joints, URDF mimic joints and MJCF joint equalities couplers, loop closures (URDF `closing_*`
/// joints, MJCF `connect` and `weld`) joints like the others. A robot description has no kinematic drivers: they come
/// from ImportOptions (`--drive` on the command line), or are added to the converted scene by hand.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace phiq {

/// The formats load_scene() and the command line read, by the file's extension.
enum class ModelFormat {
  kScene,  ///< a phiq scene (YAML or JSON): any other extension
  kAsmt,   ///< `.asmt`: FreeCAD Assembly / OndselSolver (phiq/import_asmt.hpp)
  kUrdf,   ///< `.urdf`
  kMjcf,   ///< `.mjcf` or `.xml` (MuJoCo's MJCF, phiq's only XML format)
  kSdf,    ///< `.sdf` (SDFormat, through libsdformat 12)
};

/// The format of the file at `path`, by its extension (any case).
ModelFormat model_format(const std::string& path);

/// What the caller adds to a description that has no drivers and no time grid.
struct ImportOptions {
  /// Joint drivers: the file's joint name and an expression of `t` (and `pi`) for its angle (revolute,
  /// continuous, hinge: rad, 0 at the model's pose) or travel (prismatic, slide: m), as `phiq convert --drive
  /// JOINT=EXPR` writes them; each joint once (SceneError for a second).
  std::vector<std::pair<std::string, std::string>> drives;
  double t_start = 0.0;  ///< the time grid's start (s), finite (else SceneError, as t_end)
  double t_end = 0.0;    ///< its end (s); with no drives and t_end == t_start: the model's pose alone
  int steps = 0;         ///< its intervals (0: one row at t_start; more need t_end ≠ t_start)
  /// The shapes are what the caller works on (`phiq clearance`): a URDF mesh whose `package://` cannot be found is
  /// refused rather than left out.
  bool need_geometry = false;
  /// Every format, `.asmt` too (`--rates`): the scene's output has `velocities: true, accelerations: true`.
  bool rates = false;
  /// Every format (`--forces`): the scene's output has `efforts: all` when it has drivers and `reactions: all` when
  /// it has joints with a reaction; a model none of whose parts has mass is refused (every force would be zero).
  bool forces = false;
  /// Every format (`--gravity X,Y,Z`): the gravity written as the scene's `loads.gravity`, in the scene's length
  /// unit per s² (m/s²; an `.asmt` file's own unit), instead of the file's (MJCF `<option gravity>`, the SDF
  /// world's `<gravity>`, `.asmt` ConstantGravity) or the default (URDF states none: 0 0 −9.81; MJCF: MuJoCo's
  /// 0 0 −9.81; SDF: the SDFormat world's 0 0 −9.8). {0, 0, 0} turns gravity off.
  std::optional<std::array<double, 3>> gravity;
};

/// What an import made of a file.
struct ModelImport {
  std::string yaml;                  ///< the phiq scene (dimension 3, lengths in metres)
  std::vector<std::string> skipped;  ///< "FILE:LINE: what (N in all): why not mapped", once per kind of element
  int bodies = 0;                    ///< moving bodies (ground not counted)
  int joints = 0;                    ///< joints, loop closures included
  int loops = 0;                     ///< joints that close a loop (URDF closing joints, MJCF connect and weld)
  int couplers = 0;                  ///< couplers between joints (URDF mimic, MJCF joint equality)
  /// The gravity the scene's `loads.gravity` holds and where it came from ("[0, 0, -9.81] m/s²: ..."), also a
  /// comment of `yaml`.
  std::string gravity;
};

/// Converts the text of a URDF file; `path` names it in messages and is the folder meshes are relative to. A mesh
/// `package://PACKAGE/FILE` is FILE in the folder PACKAGE on ROS_PACKAGE_PATH (an entry is the package or holds it),
/// else in a folder above the file named PACKAGE or holding it; one found nowhere is listed once as not mapped.
/// Joints named `closing_*` close loops: they are taken out before urdfdom reads the tree and joined like the others.
/// Throws SceneError, one line "PATH:LINE: what", for malformed XML, an unknown joint type, a joint naming a missing
/// link, a cycle or a link with two parents that no `closing_` name declares, a mimic of a missing joint, a driver of
/// an unknown joint.
ModelImport import_urdf(const std::string& text, const std::string& path, const ImportOptions& options = {});

/// Converts the text of an MJCF file (`<mujoco>`), with the files it `include`s (relative to `path`'s folder) and its
/// `frame`s. Throws SceneError "FILE:LINE: what" (FILE the included file where the fault is in it) for malformed XML,
/// an include that cannot be read or includes itself, an element that changes the kinematics and phiq cannot
/// represent exactly (a nonlinear joint equality's polycoef, a joint type, geom reference or site it does not know),
/// and as import_urdf() for drivers. A `frame`'s pose composes onto what it holds: bodies, geoms, sites, joints and
/// inertials.
ModelImport import_mjcf(const std::string& text, const std::string& path, const ImportOptions& options = {});

/// Converts the text of an SDF file: its model (or its world's first), links as bodies, joints revolute,
/// continuous, prismatic, ball, fixed and universal in any graph (loops close natively). Throws SceneError
/// "PATH:LINE: what" for what libsdformat refuses, another joint type, a static model. A nested model's links and
/// joints are named as SDF scopes them (`arm::link`), placed by the model's pose. An `<include>`'s `model://NAME` is
/// looked for as libsdformat does, then (as Gazebo's find-file callback) in the folders of SDF_PATH,
/// GZ_SIM_RESOURCE_PATH and IGN_GAZEBO_RESOURCE_PATH; found in none, the file is refused naming the URI.
ModelImport import_sdf(const std::string& text, const std::string& path, const ImportOptions& options = {});

/// import_urdf(), import_mjcf() or import_sdf() of the file at `path`, by model_format(), read as load_scene() reads a
/// scene (its size limit; FIFOs, directories and devices handled as there). Throws SceneError as they do, and for a
/// path whose format is none of them.
ModelImport import_model_file(const std::string& path, const ImportOptions& options = {});

}  // namespace phiq
