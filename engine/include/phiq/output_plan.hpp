/// @file
/// What a sweep outputs, described once: the output plan that run_sweep reads to know what to compute at every row
/// and that the writers (CsvFormat, the plots) read to lay out their columns, and the step view, the values of one
/// delivered row that the writers read. A scene's `output` section is read into one (Scene::sweep); it is separate
/// from the time grid and the solver settings so that a writer needs the plan and the model only, never the scene
/// or the sweep's other settings. It lies below the solver (sensitivity.hpp), the sweep (sweep.hpp) and the writers
/// (csv_writer.hpp, hdf5_writer.hpp), which all include it, and includes none of them.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "phiq/motion_law.hpp"
#include "phiq/output_joints.hpp"
#include "phiq/output_points.hpp"
#include "phiq/kinds/reaction_site.hpp"
#include "phiq/kinds/spatial_gear.hpp"
#include "phiq/types.hpp"

namespace phiq {

class CompiledExpression;   // expression.hpp
class Model;                // model.hpp
struct Loads;               // parts.hpp
struct NaturalJoints;       // natural_joints.hpp
struct Part;                // parts.hpp
struct ParameterReach;      // sensitivity.hpp
struct ReachedConstraints;  // sensitivity.hpp

/// How a row's sensitivities are solved: the direct form, one solve with Φq per parameter and derivative order,
/// giving every coordinate's sensitivity; or the adjoint form, per output coordinate, for every parameter at once
/// (sensitivity.hpp describes both, and effective_sensitivity_form() what kAuto stands for).
enum class SensitivityForm { kAuto, kDirect, kAdjoint };

/// "auto", "direct", "adjoint".
const char* to_string(SensitivityForm form);

/// One design parameter whose sensitivities a sweep outputs: its name and value, the difference step h and the
/// model built at p − 2h, p − h, p + h, p + 2h (in that order), each with the same coordinates, rows and Φq pattern
/// as the model swept (check_sensitivity_models()), or, once its reach is known, only the constraints the reach
/// holds of them (`reached`). A scene's `output: {sensitivities: [...]}` builds it (models/README.md); the C++ API
/// with sensitivity_along() (scene.hpp: it keeps the reached constraints, reading the models one at a time), or by
/// hand (the models; keep_reached_only() then releases them). sensitivity.hpp defines what it points to.
struct OutputSensitivity {
  std::string name;                                    ///< the parameter's name, the columns' suffix (`x.d_NAME`)
  double value = 0.0;                                  ///< p
  double step = 0.0;                                   ///< h > 0
  std::array<std::shared_ptr<const Model>, 4> models;  ///< at p − 2h, p − h, p + h, p + 2h
  /// What the parameter reaches (parameter_reach(): sensitivity_along() sets it, run_sweep() finds it once for the
  /// sweep when it is null). Null: solve_sensitivities() finds it at each call (O(constraints) comparisons, fewer
  /// operations than the evaluations of unreached constraints it spares).
  std::shared_ptr<const ParameterReach> reach;
  /// The constraints of `reach` in the four models (keep_reached_only()): when set, the derivatives along p read
  /// these, and `models` may be null. sensitivity_along() keeps these and not the models: a model along p is the
  /// whole model again (nfourbar 10⁵: 80 MB), what p reaches a fraction of it.
  std::shared_ptr<const ReachedConstraints> reached;
  /// The parts with mass and the loads of the scene at p − 2h, p − h, p + h, p + 2h (the efforts' sensitivities,
  /// phiq/effort_sensitivity.hpp: a mass, a centre of mass, a part's frame or a load may read p). A scene's
  /// sensitivities set those that differ from the scene's own, when it writes efforts; null: the efforts' own (p
  /// reaches none of them: Q is then not differenced along p).
  std::array<std::shared_ptr<const std::vector<Part>>, 4> parts_along;
  std::array<std::shared_ptr<const Loads>, 4> loads_along;  ///< see parts_along
};

/// Where the sensitivities of one row are: for parameter j (0 ≤ j < parameters), the n values of ∂q/∂p_j from
/// `data + j·3n`, then ∂q̇/∂p_j, then ∂q̈/∂p_j (n each; NaN where not computed: q̇'s without velocities, q̈'s
/// without accelerations, all at a singular position, where Φq has no inverse).
struct SensitivityLayout {
  Index coordinates = 0;  ///< n
  /// Offset of parameter j's block of `order` (0: q, 1: q̇, 2: q̈) in a row's values.
  Index offset(std::size_t j, int order) const { return (3 * static_cast<Index>(j) + order) * coordinates; }
  /// Values a row holds for `parameters` parameters.
  Index size(std::size_t parameters) const { return 3 * static_cast<Index>(parameters) * coordinates; }
};

/// A driver whose law is output: columns `NAME.f` = f(t), and `NAME.df`, `NAME.ddf` with velocities /
/// accelerations.
struct OutputDriver {
  std::string name;  ///< the driver's name
  MotionLaw law;     ///< its law (shared, cheap to copy)
};

/// A joint whose reaction a sweep writes (OutputEfforts::reactions).
struct OutputReaction {
  /// Model::constraints() index; its kind has a ReactionSite (reaction_width() > 0); −1 for a natural joint
  Index constraint = -1;
  bool spatial = false;  ///< six values (Fx, Fy, Fz, Mx, My, Mz) rather than three (Fx, Fy, Mz)
  int natural = -1;      ///< a natural joint: its index in OutputEfforts::natural's joints, else −1
};

/// A loss whose values a sweep writes (OutputEfforts::losses): a bearing's friction (TorsionalSpring::bearing) or a
/// transmission's meshing loss (GearLoss), phiq/applied_loads.hpp.
struct OutputLoss {
  std::string name;  ///< its columns' stem: the bearing's torsional spring's name, or the gear's
  /// Its index among the scene's losses: the torsional springs with a bearing in order, then the gear losses.
  std::size_t index = 0;
  bool bearing = false;  ///< two values (its moment or force, and its power) rather than one (the power)
  bool slide = false;    ///< a bearing that slides: its friction is a force (N), not a moment (N m)
};

/// A transmission in a sweep that writes reactions (OutputEfforts::meshes): a gear pair, rack and pinion or belt
/// between planar bodies, whose teeth (strands) push the bodies' reference points, about which they turn, or a
/// spatial gear pair, which pushes its shafts (add_gear_mesh_forces(), phiq/joint_reactions.hpp); or one whose push
/// cannot be placed (`unloaded`).
struct OutputMesh {
  Index constraint = -1;  ///< the gear's Model::constraints() index
  GearMesh mesh;          ///< its angles and ratio
  /// The body whose ψ is mesh.first; a rack's: the body whose x or y is its travel.
  Frame2 first;
  Frame2 second;       ///< the body whose ψ is mesh.second (gear 2, the pinion)
  int rack_axis = -1;  ///< a rack's travel: 0 its body's x, 1 its y (−1: a gear pair)
  /// A spatial gear pair (bevel, worm, spur or helical on parallel shafts), taken from its constraint's block once;
  /// mesh, first and second unused.
  std::optional<SpatialMesh> spatial;
  /// A gear held fixed (the ground's or a fixed body's angle) in an epicyclic train: 0 gear 1, 1 gear 2 (−1: none).
  /// It is coaxial with the carrier, so its frame above is the carrier's, whose reference point stands for its
  /// centre; it takes no push.
  int fixed = -1;
  /// Why its bearings carry none of its push (not empty: add_gear_mesh_forces() skips it, and a sweep warns
  /// `unloaded_bearings` with this at its first row): a belt without tension, teeth without pitch, a fixed gear
  /// without a carrier.
  std::string unloaded;
};

/// Driver efforts (inverse dynamics, phiq/inverse_dynamics.hpp) at every written row: for each listed constraint
/// that depends on time, the torque or force its motor applies (−λ of its first row, conjugate to what it drives)
/// and its power (Σ λ_i Φt_i over its rows). Solved with the row's own factorisation of Φq (one transposed solve),
/// from q̇ and q̈ (solved for them, written or not); NaN at a singular position, where they are unbounded.
struct OutputEfforts {
  std::shared_ptr<const std::vector<Part>> parts;  ///< the parts whose mass and weight act
  std::shared_ptr<const Loads> loads;              ///< gravity and the applied loads
  std::vector<Index> constraints;                  ///< drivers (Model::constraints() indices), written in this order
  bool power = false;                              ///< write each one's power too (`NAME.power`)
  /// Joints whose reactions are written (phiq/joint_reactions.hpp), in this order: `NAME.Fx`, `NAME.Fy`, `NAME.Mz`
  /// for a planar joint, `NAME.Fx` … `NAME.Mz` (six) for a spatial one; minimum-norm where indeterminate.
  std::vector<OutputReaction> reactions;
  /// The constraints' reactions along each joint's own axes (ReactionSite::axes: a pin's body's, a prismatic
  /// pair's slide, a spatial joint's frame) rather than world axes; a natural point's along the frame of the part it
  /// is reported on (natural_reaction_site(): x toward the frame's x point, along a bar and across it).
  bool reactions_in_joint_axes = false;
  /// The transmissions between bodies, whose push the written reactions carry (empty without reactions).
  std::vector<OutputMesh> meshes;
  /// The natural coordinates' bodies and joints the `natural` reactions index (null: none listed).
  std::shared_ptr<const NaturalJoints> natural;
  /// Losses written after the reactions (OutputLoss): a bearing's friction, the moment (N m) or a slide's force (N)
  /// it exerts against the motion, `NAME.friction`, and the power it dissipates, `NAME.loss` (W); a gear's
  /// `NAME.loss`. Magnitudes, both zero at rest (no stiction).
  std::vector<OutputLoss> losses;
  /// A reaction's name (its columns' stem): its constraint's, or its natural joint's point's.
  std::string reaction_name(const Model& model, const OutputReaction& r) const;
  /// Values a row holds: the efforts, then the powers (always computed: one product each), the reactions and the
  /// losses (losses_at()).
  Index size() const {
    Index n = losses_at();
    for (const OutputLoss& l : losses) n += l.bearing ? 2 : 1;
    return n;
  }
  /// Where the losses' values begin in a row: after the efforts, powers and reactions.
  Index losses_at() const {
    Index n = 2 * static_cast<Index>(constraints.size());
    for (const OutputReaction& r : reactions) n += r.spatial ? 6 : 3;
    return n;
  }
  /// Whether anything is computed: efforts, reactions or losses.
  bool active() const { return !constraints.empty() || !reactions.empty() || !losses.empty(); }
};

/// A limit the sweep checks at every time point (an effort's at the written rows, where it is computed): a
/// measure's value, or its rate, against a range [lo, hi]. Where the measure is outside it, the summary warns
/// `limit` once per stretch of rows outside it, with the stretch and its worst value; nothing else changes (a
/// sweep may pass its limits, as a mechanism does when its joints have no stops). Scene: `limits`.
struct OutputLimit {
  std::string name;  ///< the scene's (or what it measures)
  std::string what;  ///< what it measures, for the warning: "'xB'", "the angle of joint 'elbow'"
  /// The measure: an expression of q and t (its rate ∇e · q̇ + ∂e/∂t), or, when null, `joint`'s angle (unwrapped
  /// over turns, as OutputPlan::joints) or distance, or component `axis` of `point`'s position (its velocity's), or,
  /// with none, effort `effort` of OutputEfforts::constraints. Checked by run_sweep (a Stepper has none).
  std::shared_ptr<const CompiledExpression> of;
  std::optional<OutputJoint> joint;  ///< see `of`
  std::optional<OutputPoint> point;  ///< see `of`
  int axis = 0;                      ///< `point`'s component: 0 x, 1 y, 2 z
  Index effort = -1;                 ///< see `of`
  bool rate = false;                 ///< the measure's rate is limited, not its value (needs q̇; not an effort's)
  double lo = 0.0;                   ///< the range's lower end (lo < hi)
  double hi = 0.0;                   ///< its upper end
};

/// Values a row's StepView::efforts holds for `plan`: OutputEfforts::size(), then, with sensitivities, each effort's
/// ∂τ/∂p and each power's ∂P/∂p (EffortSensitivityLayout of phiq/effort_sensitivity.hpp: parameter by parameter,
/// efforts in order; the powers' computed whether written or not, as the powers are).
Index effort_values(const OutputEfforts& efforts, std::size_t parameters);

/// The outputs of a sweep beyond q (models/README.md, `output`). The sweep computes only what the plan lists; the
/// writers lay out their columns from the same plan, so that what is computed and what is written cannot disagree.
struct OutputPlan {
  // What the sweep computes and delivers in each StepView.

  bool velocities = true;     ///< solve and deliver q̇ at every time point
  bool accelerations = true;  ///< solve and deliver q̈ (q̇ is then solved too, but delivered only if asked)
  /// Points whose motion is evaluated at every delivered row (StepView::points): position always, velocity when
  /// q̇ is solved, acceleration when q̈ is. Nothing is evaluated for points not listed.
  std::vector<OutputPoint> points;
  /// Spatial joints whose angle or distance is output (StepView::joints): evaluated at every time point, written
  /// or not, so that angles are unwrapped over turns from row to row (a few dot products a joint).
  std::vector<OutputJoint> joints;
  /// Bodies whose orientation is output (StepView::orientations), written as `orientation_form`, with ω and α when
  /// q̇ and q̈ are solved; evaluated at written rows only.
  std::vector<OutputOrientation> orientations;
  OrientationForm orientation_form;  ///< how `orientations` are written
  /// Design parameters whose sensitivities ∂q/∂p (and ∂q̇/∂p, ∂q̈/∂p with velocities, accelerations) are delivered
  /// at every written row (StepView::sensitivities), solved with the row's own factorisation of Φq
  /// (sensitivity.hpp); written for the coordinate columns, as `x.d_P`, `x.v.d_P`, `x.a.d_P`.
  std::vector<OutputSensitivity> sensitivities;
  /// How the sensitivities are solved: kAuto takes the adjoint form where it costs less than the direct one for
  /// the coordinates whose columns are written (effective_sensitivity_form()), and the direct form, every
  /// coordinate's, when no column is written (a caller reading StepView::sensitivities); SweepSummary says which.
  SensitivityForm sensitivity_form = SensitivityForm::kAuto;
  /// Driver efforts and powers at every written row (StepView::efforts), written as `NAME.effort`, `NAME.power`;
  /// empty `constraints`: none computed. With `sensitivities`, each effort's sensitivity to each parameter too,
  /// `NAME.effort.d_P`, and each power's, `NAME.power.d_P` when the powers are written (phiq/effort_sensitivity.hpp),
  /// which read every coordinate's sensitivities: the sweep then solves them in the direct form, whatever
  /// `sensitivity_form` says (SweepSummary says so).
  OutputEfforts efforts;
  /// Limits checked along the sweep (OutputLimit), warned as `limit` in the summary.
  std::vector<OutputLimit> limits;
  /// Whether the sweep solves q̈: asked for, or needed by the efforts. Solved is not delivered: StepView::qdd is set
  /// as `accelerations` says.
  bool solves_accelerations() const { return accelerations || efforts.active(); }
  /// Whether the sweep solves q̇: asked for, or needed by q̈ (see solves_accelerations()).
  bool solves_velocities() const { return velocities || solves_accelerations(); }
  /// The coordinates the adjoint form solves for: those whose q, q̇ or q̈ columns are written, ascending.
  std::vector<Index> sensitivity_outputs() const;
  /// Deliver Φ(q, t) at every row (StepView::phi). Free: Newton's convergence test has just evaluated it.
  bool residuals = false;
  /// Deliver the reciprocal condition estimate of the last factorisation of Φq (StepView::rcond). Free with KLU
  /// and UMFPACK (the pivot ratio is computed with every factorisation). It is of Φq at the delivered q when
  /// velocities or accelerations are solved; in a positions-only sweep it is of the factorisation modified Newton
  /// last made (at this step or a few before; at the first rows of a parallel chunk possibly one its pooled
  /// workspace made for another chunk), which is what the positions were solved with.
  bool condition = false;

  // What the writers write from the delivered rows (derived from them, nothing more is computed).

  /// Coordinate indices whose columns are written, in order (a scene's default: all coordinates).
  std::vector<Index> coordinate_columns;
  /// Coordinate indices whose q̇ (`.v`) / q̈ (`.a`) columns are written, in order, when `velocities` /
  /// `accelerations`; unset: coordinate_columns. (q̇ and q̈ are solved whole whatever is written: one linear solve.)
  std::optional<std::vector<Index>> velocity_columns;
  std::optional<std::vector<Index>> acceleration_columns;  ///< see velocity_columns
  /// The rows delivered (StepView) and written: time points k = 0, every, 2·every, … (every ≥ 1) with
  /// window_begin ≤ t_k ≤ window_end. Every time point is still solved (the predictor extrapolates from each), so
  /// a written row is the same bits as in a sweep that writes all; the rows not written evaluate no points, no
  /// rcond and reach no callback.
  Index every = 1;
  double window_begin = -std::numeric_limits<double>::infinity();  ///< (s) see `every`
  double window_end = std::numeric_limits<double>::infinity();     ///< (s) see `every`
  /// Whether time point k at t is a row delivered and written (see `every`).
  bool writes_row(Index k, double t) const { return k % every == 0 && t >= window_begin && t <= window_end; }
  /// The q̇ / q̈ columns written: velocity_columns / acceleration_columns, else coordinate_columns; empty when
  /// velocities / accelerations are not asked for.
  const std::vector<Index>& written_velocities() const {
    return !velocities ? no_columns() : velocity_columns ? *velocity_columns : coordinate_columns;
  }
  /// See written_velocities().
  const std::vector<Index>& written_accelerations() const {
    return !accelerations ? no_columns() : acceleration_columns ? *acceleration_columns : coordinate_columns;
  }
  /// An empty list of columns.
  static const std::vector<Index>& no_columns() {
    static const std::vector<Index> none;
    return none;
  }
  /// Drivers whose f(t) (and derivatives, with velocities / accelerations) are written.
  std::vector<OutputDriver> driver_columns;
  /// Constraints (indices into Model::constraints()) whose residual is written; needs `residuals`.
  std::vector<Index> residual_columns;
  /// Write the largest scaled residual of all rows (column `residual`); needs `residuals`.
  bool max_residual_column = false;
};

/// What the step callback sees. qd / qdd are null when not computed.
struct StepView {
  Index step;                  ///< k, from 0
  double t;                    ///< t_k
  const Eigen::VectorXd& q;    ///< positions (valid during the callback only)
  const Eigen::VectorXd* qd;   ///< velocities, or null when not asked for
  const Eigen::VectorXd* qdd;  ///< accelerations, or null when not asked for
  /// Motions of OutputPlan::points, in that order (null when none are listed); velocity / acceleration
  /// components are filled when q̇ / q̈ are solved.
  const PointMotion* points = nullptr;
  const Eigen::VectorXd* phi = nullptr;  ///< Φ(q, t) when OutputPlan::residuals, else null
  double rcond = 0.0;                    ///< when OutputPlan::condition (see there), else 0
  /// Measures of OutputPlan::joints, in that order (null when none): angles unwrapped over the sweep's turns.
  const JointMotion* joints = nullptr;
  /// Orientations of OutputPlan::orientations, in that order (null when none).
  const OrientationMotion* orientations = nullptr;
  /// Sensitivities to OutputPlan::sensitivities laid out as SensitivityLayout says (null when none are listed):
  /// ∂q/∂p always, ∂q̇/∂p and ∂q̈/∂p when velocities / accelerations are delivered; NaN at a singular position.
  const double* sensitivities = nullptr;
  /// Efforts then powers, reactions and losses of OutputPlan::efforts (OutputEfforts::size() values), then the efforts'
  /// sensitivities with OutputPlan::sensitivities (effort_values() in all; null when none are listed); NaN at a
  /// singular position.
  const double* efforts = nullptr;
};

}  // namespace phiq
