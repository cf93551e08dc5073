/// @file
/// Scene files: a mechanism, its drivers, the time sweep and the outputs, in YAML (format: models/README.md).
#pragma once

#include <array>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "phiq/clearance.hpp"
#include "phiq/model.hpp"
#include "phiq/parts.hpp"
#include "phiq/sweep.hpp"

namespace phiq {

/// A scene that cannot be used. what() is one line: "FILE:LINE:COL: FIELD.PATH: message".
class SceneError : public std::runtime_error {
 public:
  /// The message is made one line whatever user text it quotes (single_line()).
  explicit SceneError(const std::string& message) : std::runtime_error(single_line(message)) {}
};

/// Limits that refuse huge or hostile scenes with a clear error before memory or stack is exhausted. The node
/// count bounds the memory of the YAML tree (about 0.5 KiB a node in yaml-cpp 0.7, see models/README.md).
struct SceneLimits {
  std::size_t max_file_bytes = std::size_t{128} << 20;  ///< 128 MiB
  int max_depth = 32;                                   ///< nesting of maps and lists
  /// Scalars + maps + lists. yaml-cpp's tree costs about 470 bytes a value, so this bounds the loader's memory
  /// (10^6 values: 0.48 GB); larger models are written with families (`for i in A..B`), which cost no values
  /// (one converted from a URDF, MJCF, SDF or .asmt file, about 30 000 links, cannot be: it is refused).
  std::size_t max_nodes = 1'000'000;
  std::size_t max_scalar_bytes = 16384;  ///< one value (expressions are shorter still, see expression.hpp)
  /// Entries (coordinates, points, bodies, constraints, drivers) that indexed families (`for i in A..B`) may make
  /// in all; a nested family counts as one entry of its parent per member, plus what it makes.
  std::size_t max_family_instances = 50'000'000;
  int max_family_depth = 8;  ///< families nested in families
};

/// Where a joint angle driver measures its joint's angle from: the reference directions x_a, x_b of the joint's
/// two sides, in their bodies' frames, as the scene states them or as phiq chose them (a default: x, or y for an
/// axis within 25° of x). phiq check lists them, so that the zero of a driven angle is never chosen silently.
struct JointAngleReference {
  std::string driver;             ///< the driver's name
  std::string joint;              ///< the joint it drives
  std::array<double, 3> ref_a{};  ///< x_a in side a's body frame (its part perpendicular to the axis is used)
  std::array<double, 3> ref_b{};  ///< x_b in side b's body frame
  bool stated_a = false;          ///< x_a is the scene's `ref` (else the default)
  bool stated_b = false;          ///< x_b is the scene's `ref` (else the default)
};

/// A loaded scene: the model, the sweep and what to output.
struct Scene {
  std::string path;  ///< the file it was read from (or the name given to parse_scene)
  std::string name;  ///< the scene's `name` field (may be empty)
  std::string text;  ///< the text it was parsed from (written into HDF5 results: how they were made)
  /// The scene's `parameters` in file order, with their values (the caller's overrides applied): what
  /// SceneOverrides, `phiq batch` and `output.sensitivities` may name.
  std::vector<std::pair<std::string, double>> parameters;
  /// The values the caller's overrides gave (SceneOverrides::parameters), as given: what reading the scene again as
  /// this one repeats (sensitivity_along() takes them in its `overrides`; a parameter defined from another is not
  /// among them, and moves with it).
  std::vector<std::pair<std::string, double>> overridden;
  int dimension = 2;  ///< the scene's `dimension` (2: planar, 3: spatial)
  /// The frame of each moving body, in the order of Model::body_names() (planar scenes fill planar_bodies,
  /// spatial ones spatial_bodies): where `phiq animate` reads a body's pose from q.
  std::vector<Frame2> planar_bodies;
  std::vector<Frame3> spatial_bodies;             ///< see planar_bodies
  std::vector<JointAngleReference> joint_angles;  ///< the reference directions of the joint angle drivers
  /// The scene's `parts`, in file order: shapes and mass on its bodies (phiq/parts.hpp). Bodies without one get
  /// derived parts where a drawing asks for them (drawn_parts()), not here.
  std::vector<Part> parts;
  Loads loads;                   ///< the scene's `loads` (gravity), for inverse dynamics (phiq/inverse_dynamics.hpp)
  std::unique_ptr<Model> model;  ///< the mechanism (held by pointer: a CsvFormat keeps its address)
  /// Time grid, solver settings and the output plan (its OutputPlan part: what the sweep computes and the columns
  /// written, coordinates defaulting to all).
  SweepOptions sweep;
  /// The scene's `output.clearance`: the pairs of parts whose distance `phiq clearance` measures (clearance.hpp).
  ClearancePlan clearance;
};

/// A parameter whose sensitivities a caller asks for beside the scene's text (`phiq run --sensitivity`, Python's
/// run_sweep(sensitivities=...)), as an entry of its `output.sensitivities` would.
struct SensitivityRequest {
  std::string name;   ///< a parameter of the scene
  double step = 0.0;  ///< the difference step of the data's rates; 0: default_sensitivity_step() of its value
};

/// Changes to a scene made by the caller rather than the file (batch mode, `phiq batch`).
struct SceneOverrides {
  /// Parameter values replacing the file's, by name; each must be a parameter of the scene (else SceneError). A
  /// replaced parameter is seen by every parameter, number and family after it, as if the file had said so.
  std::vector<std::pair<std::string, double>> parameters;
  /// Where the names of `parameters` were given, for the message about one that names no parameter ("cases.csv:1",
  /// the header of `phiq batch`): "cases.csv:1: 'foo' is not a parameter of scene.yaml (its parameters: ...)".
  /// Empty: the message points into the scene and says "(given for this run)".
  std::string parameters_source;
  /// If set, the model shares this model's pattern and symbolic analysis when its structure is the same
  /// (ModelBuilder::share_analysis_with()); it must outlive the call.
  const Model* share_analysis_with = nullptr;
  /// Build the models along each parameter of `output.sensitivities` (OutputSensitivity::models: the scene again
  /// with the parameter moved by −2h, −h, h, 2h). False lists the sensitivities without models: the scenes built
  /// along a parameter are read so, and so is a scene only checked, not swept.
  bool sensitivity_models = true;
  /// Keep the four models along each parameter (OutputSensitivity::models). False, the default, keeps only the
  /// constraints each parameter reaches in them (keep_reached_only()): the same results, a fraction of the memory.
  /// True serves a comparison with another reach (every constraint's, whole_model_reach()).
  bool keep_sensitivity_models = false;
  /// Parameters whose sensitivities the caller asks for (`phiq batch --sensitivity`, Python's run_batch): they
  /// replace the scene's `output.sensitivities`, made as sensitivities_of() makes them (their models only with
  /// `sensitivity_models`). Empty: the scene's own.
  std::vector<SensitivityRequest> sensitivities;
  /// What sensitivities' errors start with: where the caller's requests came from ("--sensitivity").
  std::string sensitivities_source = "sensitivities";
};

/// The sensitivity along the scene parameter `name` at `value`: its models at value − 2h, − h, + h, + 2h
/// (OutputSensitivity::models), the scene's text read again with the parameter moved (and `overrides`' others),
/// sharing scene.model's symbolic analysis (then released but for the constraints p reaches, unless
/// `overrides.keep_sensitivity_models`); h = `step`, or default_sensitivity_step(value) for step ≤ 0. What a
/// scene's `output.sensitivities` (parse_scene()) and `phiq tolerance` build. `scene` must have been read with
/// `overrides` (its model is the nominal one). Throws SceneError "with NAME = V (the difference step H from P)
/// the scene cannot be read: WHY", or check_sensitivity_models()' line when a moved model has another structure.
OutputSensitivity sensitivity_along(const Scene& scene, const std::string& name, double value, double step = 0.0,
                                    const SceneLimits& limits = {}, const SceneOverrides& overrides = {});

/// The sensitivities of `scene` to `requests`, for SweepOptions::sensitivities (in their order): each parameter's
/// models read from the scene's text as `scene` was read (its Scene::overridden values), by sensitivity_along().
/// Throws SceneError, one line starting with `source` (the option or argument they came from), for a name that is
/// no parameter of the scene (the message lists them), a name asked for twice, a step that is not 0 or a positive
/// finite number, and what sensitivity_along() throws.
std::vector<OutputSensitivity> sensitivities_of(const Scene& scene, const std::vector<SensitivityRequest>& requests,
                                                const std::string& source = "sensitivities",
                                                const SceneLimits& limits = {});

/// Loads and validates a scene file. Throws SceneError (never crashes) for unreadable files, YAML syntax errors,
/// unknown or duplicate fields and names, wrong types, NaN or infinite numbers and impossible values.
Scene load_scene(const std::string& path, const SceneLimits& limits = {});
/// load_scene() with the caller's overrides (batch mode), as parse_scene() with overrides.
Scene load_scene(const std::string& path, const SceneLimits& limits, const SceneOverrides& overrides);
/// The same from text; `path` is used in messages only.
Scene parse_scene(const std::string& text, const std::string& path, const SceneLimits& limits = {});
/// parse_scene() with the caller's overrides (batch mode). Throws SceneError as parse_scene() does, and for an
/// override naming no parameter of the scene.
Scene parse_scene(const std::string& text, const std::string& path, const SceneLimits& limits,
                  const SceneOverrides& overrides);

}  // namespace phiq
