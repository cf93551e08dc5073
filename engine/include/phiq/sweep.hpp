/// @file
/// A whole drive sweep: the initial position problem (assembly from the rough placement) at the first time, then
/// successive positions, each started from a prediction of the previous solution, with velocities and
/// accelerations when asked for.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "phiq/kinematics.hpp"
#include "phiq/output_plan.hpp"  // OutputPlan, StepView
#include "phiq/sensitivity.hpp"  // SweepSummary::sensitivity_form, the plan's sensitivities

namespace phiq {

/// How successive positions are started: an extrapolation of the solutions already found, of the order the
/// computed quantities allow. Its error is what Newton has to correct: O(h) from the previous position, O(h²)
/// (secant, linear), O(h³) (parabolic, quadratic), O(h⁴) (cubic, hermite), so that a better predictor needs fewer
/// Newton iterations per step, down to none once its error is within the tolerance (bench/README.md).
enum class Predictor {
  /// The best the computed quantities allow: cubic with q̇ and q̈, hermite with q̇ only, parabolic with positions
  /// only.
  kAuto,
  kPrevious,   ///< the previous solution, as in the notes
  kSecant,     ///< linear extrapolation from the two previous solutions (free: needs no velocity)
  kLinear,     ///< q + h q̇            (needs velocities)
  kQuadratic,  ///< q + h q̇ + h²/2 q̈   (needs accelerations)
  /// q + h q̇ + h²/2 q̈ + h³/6 q⃛, with q⃛ the difference quotient of the last two q̈ (needs accelerations; free:
  /// the previous q̈ is kept, not recomputed). The quadratic predictor until two rows are known.
  kCubic,
  /// The parabola through the last three solutions, evaluated at the new time (free: needs no velocity; any
  /// spacing of the three times, sub-steps included). The secant until three rows are known.
  kParabolic,
  /// The cubic through the last three solutions and tangent to the current row's q̇ (Hermite interpolation:
  /// q and q̇ at the current row, q at the two before), evaluated at the new time (needs velocities, not
  /// accelerations; free: the previous positions are kept). Secant, then parabola, until three rows are known.
  kHermite,
};
/// "auto", "previous", "secant", "linear", "quadratic", "cubic", "parabolic" or "hermite".
const char* to_string(Predictor p);
/// The predictor named `name` (to_string()'s words); false, leaving `*p` unchanged, for any other text.
bool predictor_from_string(const std::string& name, Predictor* p);
/// Every predictor, Predictor::kAuto first, in the order predictor_names() lists them.
const std::vector<Predictor>& all_predictors();
/// The names predictor_from_string() takes, for messages: "auto, previous, secant, parabolic, linear, hermite,
/// quadratic or cubic".
const char* predictor_names();
/// The predictor a sweep runs with: `p` itself, or for Predictor::kAuto the best for what the sweep computes
/// (velocities: q̇ is solved, also when only accelerations are asked for; accelerations: q̈ is solved).
Predictor effective_predictor(Predictor p, bool velocities, bool accelerations);
/// Whether `p` extrapolates with q̇ (linear) or q̈ (quadratic, cubic): a sweep must compute them to use it.
bool predictor_needs_velocities(Predictor p);
/// Whether `p` extrapolates with q̈ (quadratic, cubic).
bool predictor_needs_accelerations(Predictor p);

/// The time points of a sweep.
struct TimeGrid {
  double t_begin = 0.0;  ///< first time point (s)
  /// last time point (s); may be below t_begin. With steps > 0 every step must move time: t_end ≠ t_begin and
  /// |t_end − t_begin| / steps above 8 ulps of the larger of |t_begin|, |t_end| (else run_sweep throws phiq::Error)
  double t_end = 1.0;
  Index steps = 100;  ///< intervals: steps + 1 time points, t_k = t_begin + k (t_end − t_begin) / steps
  /// t_k, computed from k, not accumulated, so that the last point is t_end exactly (steps = 0: t_begin).
  double time_of(Index k) const {
    if (steps == 0) return t_begin;
    if (k == steps) return t_end;
    return t_begin + static_cast<double>(k) * ((t_end - t_begin) / static_cast<double>(steps));
  }
};

/// How each position of a sweep is solved.
struct SolverSettings {
  Predictor predictor = Predictor::kAuto;  ///< start of each successive position
  /// Successive positions: modified Newton, reusing the factorisation made for the previous step's velocity and
  /// acceleration (or the previous position) while it contracts well — one factorisation per drive step instead
  /// of three (bench/README.md).
  NewtonOptions newton{1e-10, 20, true, 12, JacobianUpdate::kWhenSlow};
  NewtonOptions assembly{1e-10, 100, true, 30};  ///< initial position from the rough placement
  int max_subdivisions = 8;  ///< a failed step is retried as 2, 4, … sub-steps, down to h / 2^max_subdivisions
};

/// How the drive steps of a sweep are spread over threads, and the memory they may take.
struct ParallelSettings {
  /// Threads for the drive steps; 0 uses all cores. The steps run in chunks of chunk_steps steps, cut alike for
  /// every thread count, and the rows, the summary's counts and its warnings are the same bits on every thread
  /// count and every run: N threads run N chunks at once, one thread runs the same chunks one after the other.
  /// Each chunk starts from a seed found by a sequential pass over the chunk starts (positions only, every
  /// chunk_steps-th time point, a row later where the seed is at or next to a singular position; a body's Euler
  /// parameters turned to the sign its motion continues with), and is accepted only if the sweep, continued one
  /// step past the previous chunk (that seam step solves its position only), reaches the same position there to
  /// within 100 × the tolerance (10 × the rounding level where Newton stopped there, if larger): otherwise the rest
  /// of the sweep runs in order (warning "parallel_fallback"). Rows are delivered in time order, and equal the
  /// sweep in order's (chunk_steps ≥ steps) to the solver tolerance; on_step is called on the calling thread.
  /// Everything the sweep runs stays on these threads, the model's own parallel evaluation of large models
  /// (ModelBuilder, 65536 constraints and more) included: 1 is one thread. The threads solve in the caller's
  /// workspace and one more per extra thread (each with its own LU of Φq), which the seeding pass shares. With 0,
  /// fewer than all cores when those extra workspaces (measured on the first factorisation) and the rows held for
  /// delivery would not fit in memory_budget: warning "threads_reduced".
  int threads = 1;
  /// Bytes the whole process may reach when threads = 0 picks the threads (what it holds already, the model and
  /// the caller's workspace among it, counts); 0: the threads' workspaces must fit in the memory the system
  /// reports available (MemAvailable of /proc/meminfo), no limit where it reports none. An explicit thread count
  /// is never reduced.
  std::size_t memory_budget = 0;
  /// Steps per chunk; ≥ steps runs the sweep in order, as one chunk. 0 picks 64, fewer (down to 16) so that there
  /// are 16 chunks (the seed of a chunk is one step over its span, expensive on large models when long), and no
  /// more than the rows row_buffer_bytes holds (q, q̇, q̈ and the outputs of a row), none below 8, which cost more in
  /// seeds than a thread gains: one chunk then. It depends on the scene and these options only, never on the
  /// threads or the machine. Threads beyond those with room for a chunk's rows each are not used (warning
  /// "threads_reduced"). A sweep with no on_step holds two rows per chunk, whatever their width.
  Index chunk_steps = 0;
  /// Bytes of rows a sweep in chunks may hold before it delivers them in order (> 0; see chunk_steps).
  std::size_t row_buffer_bytes = std::size_t{512} * 1024 * 1024;
};

/// What run_sweep computes and how: its parts can be set and passed on their own.
struct SweepOptions : TimeGrid, OutputPlan, SolverSettings, ParallelSettings {};

/// The rows a sweep with these options delivers when it succeeds: the time points OutputPlan::writes_row selects.
Index rows_written(const SweepOptions& o);

/// Something the caller should know about a delivered row (the row itself is within tolerance).
struct SweepWarning {
  double t;  ///< time of the row concerned
  /// "slow_convergence": Newton converged only linearly (singular position nearby), or stopped at the rounding
  /// level of Φ above the tolerance (a long chain; the message says how well q is known; once per stretch of
  /// rows, up to two rows without it apart, the message says how long and how many); "ill_conditioned": Φq is
  /// near-singular (rcond below 1e-7; once per stretch of such rows); "bifurcation": Φq is singular at this row,
  /// the velocity is not unique and the branch's own is reported; "parallel_fallback": a parallel chunk starting
  /// at t did not continue the sweep in order, and the remaining steps ran in order (the rows are the same), the
  /// message saying which cause: its first row did not converge from its seed (the solver's reason), the chunk
  /// before it did not reach its first time point, its first row has the other sign of a body's Euler parameters
  /// (e and −e: one orientation), or its first row is another branch, named at the coordinate farthest from
  /// where the sweep in order arrives, with that distance and how closely two rows of one branch agree there,
  /// both in the coordinate's unit (m, rad; no unit for a dimensionless one, such as an Euler parameter);
  /// "threads_reduced": fewer threads ran than asked (ParallelSettings::threads = 0 and memory_budget, or rows
  /// too wide for every thread to hold a chunk); "no_dependence": a parameter of OutputPlan::sensitivities
  /// changes no constraint or driver (its ParameterReach is empty: its sensitivities are exactly zero; at the
  /// first row); "indeterminate": written joint reactions (OutputEfforts::reactions) that redundant constraints
  /// leave undetermined, named at the first row (their minimum-norm values are written), and gear meshes whose
  /// share of the load they leave undetermined; "gear_centres": a gear's teeth (a belt's strands) push its bodies in
  /// a way its row does not hold (add_gear_mesh_forces(): their push does work in the motion; once per stretch of
  /// rows), so its bearings' written loads are not its teeth's; "unloaded_bearings": a gear or belt between bodies
  /// whose push its written bearing loads lack (OutputMesh::unloaded: a belt without tension, teeth without a pitch, a
  /// fixed gear without a carrier; at the first row); "belt_slack": a belt's slack strand would need a negative tension
  /// at this row (once per stretch of rows); "limit": a measure of OutputPlan::limits outside its range over a stretch
  /// of rows, said at the stretch's first row with its last and its worst value (after every other warning)
  std::string kind;

  std::string message;  ///< one line
};

/// How well the positions of one class of delivered rows are known (SweepAccuracy).
struct RowClassAccuracy {
  Index rows = 0;  ///< delivered rows of this class
  /// The largest estimated error of q over those rows whose error a solve estimated, in units of the tolerance
  /// test: max_j |δq_j| / (tol · scale_j + floor_j), so that ≤ 1 is within the tolerance
  /// (PositionSummary::error_estimate: Newton's last step and its contraction, the rounding level at a stop there,
  /// the predictor's error budget for a prediction taken without a step); 0 when no row has one.
  double worst_error = 0.0;
  double worst_time = 0.0;  ///< the first row where worst_error is reached
  /// The coordinate where worst_error is reached (PositionSummary::error_coordinate), empty when no solve said:
  /// the estimate in the coordinate's own unit is worst_known_to, in worst_unit (known_to_text()).
  std::string worst_coordinate;
  double worst_known_to = 0.0;    ///< |δq| at worst_coordinate, in its unit (PositionSummary::error_size); 0 if none
  Unit worst_unit = Unit::kNone;  ///< worst_coordinate's unit (Model::coordinate_unit())
  /// Rows whose error no solve estimated: a position taken on its residual alone, or interpolated between the two
  /// sides of a singular position.
  Index unestimated = 0;
};

/// How well q is known on the delivered rows, per class of row: each row is in exactly one class, so the three
/// counts add up to SweepSummary::steps_completed. The same on every thread count (rows and summary alike).
struct SweepAccuracy {
  /// Rows whose Newton ended within the tolerance test (or whose prediction was taken within it), or stopped at a
  /// rounding level within 2 tolerances (PositionSummary::rounding_level): q within the tolerance, worst_error ≤ 2.
  RowClassAccuracy converged;
  /// Rows known to more than 2 tolerances because Φ's rounding, amplified by Φq⁻¹, is larger than the tolerance
  /// (a long chain, a badly scaled model): Newton stopped at that level (each stretch of such rows has its
  /// slow_convergence warning), or was accepted within the level the rows before it measured
  /// (NewtonOptions::known_to). q is known to worst_error tolerances, not to the tolerance.
  RowClassAccuracy rounding_level;
  /// Rows at or next to a singular position: Newton converged only linearly there (q known to about √tol, its
  /// estimate from the contraction), or the row lies on the singular position itself (a bifurcation; q̇ and q̈ are
  /// the branch's extrapolated limits, with their warning).
  RowClassAccuracy singular;
};

/// What run_sweep did (Ceres-style summary).
struct SweepSummary {
  SolveStatus status = SolveStatus::kSuccess;  ///< the outcome; kSuccess when every time point was delivered
  std::string message;  ///< one line naming the step, time, cause and constraints; empty on success
  /// Time points solved, in order from the first: all of them delivered to the callback, save those the output
  /// plan does not write (OutputPlan::writes_row: `every`, the time window)
  Index steps_completed = 0;
  Index failed_step = -1;    ///< k of the step that failed, or -1
  double failed_time = 0.0;  ///< t_k of the step that failed
  /// At a failed position (initial assembly, drive step): the worst rows of the last position tried, (row of the
  /// model swept, |Φ_i| / scale_i), largest first, at most 3, as `message` names them (Model::row_name()); empty
  /// on success, or when the failure is not a position's (a derivative, the time domain, a redundancy conflict).
  std::vector<std::pair<Index, double>> worst_rows;
  PositionSummary assembly;            ///< the initial position problem
  WorkCounters counters;               ///< work done by this sweep
  Index subdivisions = 0;              ///< sub-steps inserted after Newton failures
  Index singular_positions = 0;        ///< rows at singular positions (bifurcations) passed, each with a warning
  double min_rcond = 0.0;              ///< smallest reciprocal condition estimate seen (0 if none)
  double min_rcond_time = 0.0;         ///< where min_rcond was seen
  std::vector<SweepWarning> warnings;  ///< in time order
  double solve_seconds = 0.0;          ///< wall time of the sweep, the callback's own work included
  int threads = 1;                     ///< threads the drive steps ran on
  Index parallel_chunks = 0;           ///< chunks run from their seeds and accepted (0 for a sweep in order)
  double seed_seconds = 0.0;           ///< wall time of the sequential seeding pass of a sweep in chunks
  SweepAccuracy accuracy;              ///< how well q is known on the delivered rows, per class of row
  /// How the sensitivities were solved (kDirect or kAdjoint: OutputPlan::sensitivity_form resolved by
  /// effective_sensitivity_form()); kAuto when none were asked for.
  SensitivityForm sensitivity_form = SensitivityForm::kAuto;
  /// One line: status, steps, iterations, factorisations, solves, point evaluations, subdivisions, warnings, time,
  /// message.
  std::string BriefReport() const;
};

/// Runs the sweep from ws.q (the rough placement; the model's initial positions for a fresh workspace), calling
/// on_step once per time point, in order; on_step returns false to stop (status kCancelled). On failure nothing
/// more is delivered and the summary says where and why. Pre-condition: ws made for model. Throws phiq::Error,
/// before anything is solved, for settings no sweep can honour (negative counts, non-finite times, `newton` or
/// `assembly` settings solve_position refuses, a predictor whose derivatives are not computed).
SolveStatus run_sweep(const Model& model, const SweepOptions& options, Workspace& ws,
                      const std::function<bool(const StepView&)>& on_step, SweepSummary* summary);

/// Where the rows of a sweep go when they are encoded (CSV text, packed doubles) by the threads that compute them
/// and written in order by the calling thread: run_sweep's overload below. A sweep in parallel chunks encodes each
/// chunk's rows as it computes them and hands the chunk's bytes to write() once every row before them is written,
/// so that neither the encoding nor the copies of the rows it reads wait on the calling thread.
class RowWriter {
 public:
  virtual ~RowWriter() = default;
  /// Appends the encoding of `step`, a row the output plan writes, to `out`. Called on any of the sweep's threads,
  /// several at once: it must change nothing shared. Throws phiq::Error to stop the sweep (rethrown by run_sweep).
  virtual void encode(const StepView& step, std::string& out) const = 0;
  /// At most how many bytes encode() appends for one row: what the rows a chunk holds until written take.
  virtual std::size_t max_row_bytes() const = 0;
  /// Takes the encodings of `rows` written rows in time order, the last of them time point `last_step`, on the
  /// calling thread; every written row comes through here exactly once, in order. False stops the sweep (status
  /// kCancelled) after them.
  virtual bool write(const std::string& encoded, Index rows, Index last_step) = 0;
  /// Writes one row computed on the calling thread, in its turn (the rows a sweep delivers as it computes them,
  /// with no other thread to encode them): encode(), then write(), unless a writer has a shorter way. False stops
  /// the sweep (status kCancelled).
  virtual bool write_row(const StepView& step) {
    std::string encoded;
    encode(step, encoded);
    return write(encoded, 1, step.step);
  }
};

/// run_sweep with its rows encoded and written by `writer` instead of handed to a step callback: the same rows, the
/// same summary, and the same bytes for every thread count. With OutputPlan::joints that measure angles (each
/// unwrapped from the row before it) the rows are encoded in order on the calling thread, as a step callback reads
/// them.
SolveStatus run_sweep(const Model& model, const SweepOptions& options, Workspace& ws, RowWriter& writer,
                      SweepSummary* summary);

}  // namespace phiq
