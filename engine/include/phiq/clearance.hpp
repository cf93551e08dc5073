/// @file
/// Clearance along the motion: the distance between pairs of parts (phiq/parts.hpp) at every row of a sweep, signed
/// (the penetration depth, negative, where their shapes overlap), with the witness points; each local minimum of a
/// pair's distance refined on the continuous motion to its time and distance; every interval of interference with
/// its entry and exit times; a bound from the parts' speeds that proves nothing closer happens between the rows
/// that were not refined; and the sensitivity of each minimum clearance to the scene's parameters.
///
/// Distances come from FCL 0.7 (with libccd): primitives as FCL's primitives, polygons, meshes, curves and planes
/// as BVH meshes of their triangles (shape_triangles()). The depth of an overlap is exact for the pairs FCL has a
/// closed form for (a sphere with a sphere, box, capsule or cylinder; two boxes), refined from libccd's MPR for the
/// other pairs of primitives, and the deepest contact of FCL's triangle pairs where a mesh is involved.
#pragma once

#include <Eigen/Core>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "phiq/parts.hpp"
#include "phiq/sweep.hpp"

namespace phiq {

struct Scene;

/// What the scene's `output.clearance` asks for (models/README.md): the pairs of parts measured and the threshold.
struct ClearancePlan {
  bool requested = false;  ///< the scene has `output.clearance`
  /// `pairs: all`: every pair of parts with shapes but those skipped, through a broad phase (only the pairs that
  /// come within `threshold` are reported; the others are proven farther at every time)
  bool all = false;
  std::vector<std::pair<Index, Index>> pairs;  ///< explicit pairs (indices into the parts), when not `all`
  bool skip_adjacent = false;                  ///< `skip: adjacent`: leave out parts joined by a constraint
  std::vector<std::pair<Index, Index>> skip;   ///< `skip: [[A, B], …]`
  double threshold = 0.0;                      ///< m, ≥ 0: the clearance a pair must keep
};

/// The pairs of parts joined by the model's constraints (each pair once, a < b): parts that read a coordinate in
/// common (natural coordinates: a shared point), parts whose coordinates are both read by one constraint that reads
/// no third part's, and a moving part jointed to ground with the fixed parts whose bounds hold that ground pivot.
std::vector<std::pair<Index, Index>> adjacent_parts(const Model& model, const std::vector<Part>& parts);

/// The pairs `plan` selects among `parts` (a < b, sorted), skipped pairs left out. For `all`: every pair of parts
/// with shapes whose frames are not both fixed.
std::vector<std::pair<Index, Index>> clearance_pairs(const Model& model, const std::vector<Part>& parts,
                                                     const ClearancePlan& plan);

/// The distance between two parts at one time: signed, with the witness points in world axes.
struct PairDistance {
  double distance = 0.0;  ///< m; negative: the depth of the overlap
  kin3::V3 point_a;       ///< on part A's surface (when they overlap: A's deepest point inside B along the normal)
  kin3::V3 point_b;       ///< on part B's surface (when they overlap: B's deepest point inside A, the depth away)
  /// Unit direction in which moving B away from A increases the distance (B's witness point minus A's, reversed
  /// when they overlap).
  kin3::V3 normal;
};

/// FCL's geometry of a set of parts, built once (shapes in their frames): distances at any poses. Immutable after
/// construction; distance() is thread-safe.
class ClearanceGeometry {
 public:
  /// The geometry of `parts` (those without shapes have none). Throws phiq::Error naming a shape FCL cannot take.
  explicit ClearanceGeometry(const std::vector<Part>& parts);
  ~ClearanceGeometry();                                        ///< frees the FCL objects
  ClearanceGeometry(ClearanceGeometry&&) noexcept;             ///< takes over the other's objects
  ClearanceGeometry& operator=(ClearanceGeometry&&) noexcept;  ///< see the move constructor
  /// The signed distance between parts a and b at their poses. Pre-condition: both have shapes.
  PairDistance distance(Index a, const Pose& pose_a, Index b, const Pose& pose_b) const;
  /// A radius about the part's frame origin that holds all its shapes (m).
  double bounding_radius(Index part) const;
  /// A box in world axes that holds the part's shapes at `pose` (each shape's own box, turned: not the tightest).
  std::pair<kin3::V3, kin3::V3> world_box(Index part, const Pose& pose) const;
  bool has_shapes(Index part) const;  ///< the part carries at least one shape

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A minimum of a pair's distance over the sweep.
struct ClearanceMinimum {
  double t = 0.0;        ///< s
  PairDistance at;       ///< the distance and witness points there
  bool refined = false;  ///< found between the rows (the derivative of the distance zero), not only on a row
  kin3::V3 local_a;      ///< at.point_a in part A's frame (the material point of A that is the witness there)
  kin3::V3 local_b;      ///< at.point_b in part B's frame
  /// ∂d/∂p for each of the sweep's sensitivities, in their order (every minimum of a reported pair).
  std::vector<double> sensitivities;
};

/// An interval of time where a pair's shapes overlap (distance < 0).
struct InterferenceInterval {
  double entry = 0.0;  ///< s; the sweep's first time when it starts overlapping
  double exit = 0.0;   ///< s; the sweep's last time when it ends overlapping
};

/// Everything measured about one pair.
struct PairClearance {
  Index a = -1;                                    ///< index of part A into the parts
  Index b = -1;                                    ///< index of part B into the parts
  std::vector<double> row_distance;                ///< the signed distance at each row
  std::vector<ClearanceMinimum> minima;            ///< the local minima over time, in time order
  ClearanceMinimum worst;                          ///< the smallest of them, with its sensitivities
  std::vector<InterferenceInterval> interference;  ///< in time order
  /// Intervals between rows (not refined) where the bound from the speeds could not prove that the distance stays
  /// above min(worst, threshold), even after subdividing them: 0 when the bound held.
  Index unproven_intervals = 0;
};

/// What clearance_along() measured.
struct ClearanceReport {
  std::vector<double> times;            ///< the rows' times
  std::vector<PairClearance> pairs;     ///< the pairs measured (for `all`: those that come within the threshold)
  Index pairs_selected = 0;             ///< the pairs the plan selects (for `all`, before the broad phase)
  Index pairs_measured = 0;             ///< the pairs measured at the rows (for `all`, those the broad phase keeps)
  double threshold = 0.0;               ///< the plan's
  std::vector<std::string> parameters;  ///< the sensitivities' parameters, in order
  Index positions_solved = 0;           ///< positions solved between rows (refinement and subdivision)
  bool interferes() const;              ///< some pair overlaps at some time
  bool bound_held() const;              ///< every pair's unproven_intervals is 0
};

/// The rows a clearance pass reads: t, q, q̇ and q̈ of each row of a sweep (what run_sweep's on_step delivers).
struct ClearanceRows {
  std::vector<double> t;             ///< times, increasing
  std::vector<Eigen::VectorXd> q;    ///< positions, one per row
  std::vector<Eigen::VectorXd> qd;   ///< velocities, one per row
  std::vector<Eigen::VectorXd> qdd;  ///< accelerations, one per row
};

/// The rows of a sweep of `model` with `options` (q̇ and q̈ solved whatever they say), from ws.q; the sweep's
/// outcome in *summary (the rows before a failure are kept).
ClearanceRows sweep_rows(const Model& model, SweepOptions options, Workspace& ws, SweepSummary* summary = nullptr);

/// How clearance_along() solves positions between rows and what it differentiates.
struct ClearanceOptions {
  SolverSettings solver;                         ///< for the positions between rows (a Stepper)
  std::vector<OutputSensitivity> sensitivities;  ///< parameters of the minima's sensitivities
  double time_tolerance = 1e-9;                  ///< refined times to this fraction of the step
  int max_subdivision_depth = 6;                 ///< halvings of an interval the speed bound cannot prove
};

/// Clearance of `plan`'s pairs of `parts` over `rows` of a sweep of `model` (see the file comment). Throws
/// phiq::Error for a position between rows that cannot be solved, naming its time.
ClearanceReport clearance_along(const Model& model, const std::vector<Part>& parts, const ClearancePlan& plan,
                                const ClearanceRows& rows, const ClearanceOptions& options = {});

/// Runs the scene's sweep (with q̇ and q̈) collecting its rows and measures its `output.clearance` over them, with
/// the sensitivities of its `output.sensitivities`. The sweep's outcome in *summary; on failure the report holds
/// the rows before it.
ClearanceReport scene_clearance(const Scene& scene, SweepSummary* summary = nullptr);

}  // namespace phiq
