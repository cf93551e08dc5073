/// @file
/// Sensitivities of the motion to design parameters: ∂q/∂p, ∂q̇/∂p and ∂q̈/∂p at a converged position, from the
/// position, velocity and acceleration equations differentiated with respect to p:
///
///   Φq s  = −Φp                                         s  = ∂q/∂p
///   Φq ṡ  = −(∂/∂p [Φq q̇ + Φt])  along (q, p) ← (s, 1)    ṡ  = ∂q̇/∂p
///   Φq s̈  = −(∂/∂p [Φq q̈ − γ])   along (q, q̇, p) ← (s, ṡ, 1), q̈ held    s̈ = ∂q̈/∂p
///
/// Each right-hand side is the total derivative, with respect to p, of the equation's residual while q (and q̇)
/// move along the sensitivities already known; each is solved with the factorisation of Φq the row was solved
/// with (one triangular solve a parameter and derivative order, no new factorisation).
///
/// How the parameter enters: through the model itself. A parameter of a scene can reach any number of a
/// constraint's data (a length, an offset, a local point, an axis, a law coefficient, an equation's constant),
/// through the scene's arithmetic, and another parameter defined from it moves with it. So the derivative along p
/// is taken of the models built at p − 2h, p − h, p + h and p + 2h (same structure: only values differ), by the
/// fourth-order central difference
///
///   D f = [f(−2h) − 8 f(−h) + 8 f(h) − f(2h)] / (12 h),
///
/// of functions evaluated exactly by each model (Φ, Φq q̇ + Φt, Φq q̈ − γ), at fixed (q, q̇, q̈) and over the
/// constraints whose data the models change (ParameterReach). D is exact, up to rounding, for every dependence of
/// degree ≤ 4 in p: local coordinates and offsets (linear), the law coefficients of polynomial drivers. For a bar's
/// length L, Φ = (|d|² − L²)/(2L) is rational in L: the error is 2(h/L)⁴ of ∂Φ/∂L, 2·10⁻¹² at the default
/// h = 10⁻³ |p|; for a parameter inside a sine or cosine (an angle), h⁴/30 of the fifth derivative: 3·10⁻¹⁴
/// relative. Rounding adds about ε |Φ's terms| / h.
///
/// A kind that differentiates its own data (DataDifferentiable: the planar distance, pin, prismatic pair, point on a
/// line, constant and segment angles, polar vector, loop closure and coupler, most rows of the large linkages; the
/// point on a curve and the flat follower along all but their curve's shape; the
/// drivers through their laws, MotionLaw::rate_along(); equations along the parameters their texts read, exactly
/// (CompiledExpression::along_constants(): ∂g/∂p compiled as g is), and their laws; the spatial distance and dot
/// product, the nine spatial joints, the joint drivers, the screw, the spatial gear and the mixed polar and angle
/// coordinates through their attachments; the gear, rack and belt) gives its equations' derivatives itself, exactly
/// and in one evaluation: D is then applied to its data alone (a datum's rate: exact for the scene's arithmetic of
/// degree ≤ 4 in p, a length L itself among it; a harmonic law's frequency enters f through the chain rule, not D)
/// and the kind's data_derivative() chains it (DistanceSpec::data_derivative(); ReachedConstraints::rates).
///
/// The higher orders' derivatives along the motion's own sensitivities, (q, q̇) ← (s, ṡ), are taken apart from p,
/// with the swept model. The velocity's is exact: with B = ∂(Φq q̇ + Φt)/∂q, γ = −(Φq q̇)q q̇ − 2 Φqt q̇ − Φtt is a
/// quadratic in q̇ whose derivative along s is −2 B s, so that
///
///   B s = [γ(q, q̇ − αs) − γ(q, q̇ + αs)] / (4α)   for every α,
///
/// two evaluations of γ at q itself (α makes αs as fast as q̇). The acceleration's, ∂(Φq q̈ − γ)/∂q s − ∂γ/∂q̇ ṡ,
/// holds Φ's third derivatives: a fourth-order difference whose step moves the coordinate s moves most by 10⁻³ of
/// its scale (s grows along a sweep, ∂θ/∂ω = t for a crank at θ = ωt, and a step tied to h would grow with it).
///
/// A coordinate that a constraint adds and measures along its data (a curve's parameter s, PointOnCurveSpec) means
/// another point when p changes the curve: at fixed s, a cam's circle of radius R turns under the contact by
/// s h / R² for a step h, so that ten turns of a cam put ∂y/∂R off by 7·10⁻⁶. Such a coordinate co-moves with p
/// (ParameterReach::comotion: q̂ = s (∂ℓ/∂p)/ℓ, ℓ the curve's length): the differences along p are taken along
/// (q, p) ← (q̂, 1), where the models see one contact, and solve for s − q̂:
///
///   Φq (s − q̂) = −(Φp + Φq q̂),   and ṡ, s̈ with (s − q̂) in the part along the motion,
///
/// the same equations rearranged. The tests compare with closed forms to 1e-9 (that cam over ten turns among
/// them) and with re-solved sweeps (models/README.md).
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "phiq/kinematics.hpp"
#include "phiq/output_plan.hpp"  // OutputSensitivity, SensitivityForm, SensitivityLayout

namespace phiq {

/// The constraints a parameter reaches: those whose data differ between the swept model and a model along the
/// parameter (ConstraintBlock::same_data(): the kind's value equality, laws and expressions included). Only their rows
/// of ∂Φ/∂p, ∂(Φq q̇ + Φt)/∂p and ∂(Φq q̈ − γ)/∂p can be non-zero, so only they are evaluated along p: a link's
/// length costs its one constraint, not the four models' every row, and the other rows' derivatives are exactly 0.
struct ParameterReach {
  /// Constraints [begin, end) of block `block` (Model::blocks()), for each run of consecutive reached ones.
  struct Span {
    std::size_t block = 0;  ///< index into Model::blocks()
    std::size_t begin = 0;  ///< first reached constraint of the run
    std::size_t end = 0;    ///< one past its last
  };
  std::vector<Span> spans;  ///< in block order
  std::vector<Index> rows;  ///< the rows of Φ the spans own, ascending
  /// True when the models' blocks could not be matched one to one (another order or size): then every constraint
  /// of the model is in `spans`.
  bool everything = false;
  /// A coordinate that a reached constraint adds (a curve's parameter s) and how it moves along the parameter at the
  /// same contact: q_c · rate per unit of p, with rate = (∂ℓ/∂p) / ℓ and ℓ its scale (PointOnCurveSpec::added_scale():
  /// the curve's length). Differenced at fixed s, a curve whose radius is the parameter turns under the contact by
  /// s / ℓ times the relative step (10 turns of a cam: ∂y/∂R off by 7·10⁻⁶); moved so, the four models see one
  /// contact: the derivatives along p are taken along (q, p) ← (q̂, 1) and the sensitivities solved for s − q̂
  /// (the file's description).
  struct Comotion {
    Index coordinate = 0;  ///< the added coordinate's index
    double rate = 0.0;     ///< (∂ℓ/∂p) / ℓ, 1/(the parameter's unit)
  };
  /// The added coordinates of reached constraints whose scale the parameter changes; every constraint that reads
  /// one of them is in `spans`. Empty when `everything` is set.
  std::vector<Comotion> comotion;
};

/// The constraints of a ParameterReach as each model along the parameter holds them: for model k (at p − 2h, p − h,
/// p + h, p + 2h), one block per span of the reach, holding copies of the span's constraints with their rows. All
/// that the derivatives along p read once the reach is known (keep_reached_only()).
///
/// Where the span's kind differentiates its own data (DataDifferentiable, above), `rates`
/// holds its data's rates along p (ConstraintBlock::data_rates()), and the derivatives there are the kind's, exact
/// and in one evaluation instead of four (a bar's length: the differences' 2(h/L)⁴ gone). Not with co-moving
/// coordinates (ParameterReach::comotion: the models move q there), where every span is differenced.
struct ReachedConstraints {
  std::shared_ptr<const ParameterReach> reach;  ///< the reach they were kept for
  /// per model, per span of the reach (empty where `rates` holds the span's: what is read of it then)
  std::array<std::vector<std::unique_ptr<ConstraintBlock>>, 4> along;
  std::vector<std::unique_ptr<ConstraintBlock>> rates;  ///< per span of the reach: its data's rates, or null
  /// The swept model's n when they were kept: check_sensitivity_models() refuses them for another model (and spans
  /// outside its blocks, or of other kinds), whose constraints they do not stand for.
  Index coordinates = 0;
  Index equations = 0;  ///< the swept model's m when they were kept (see coordinates)
  Index nonzeros = 0;   ///< the nonzeros of its Φq (see coordinates)
};

/// Keeps of `s`'s models only the constraints its reach holds (ReachedConstraints), finding the reach first when
/// `s.reach` is null, and releases the models: the sweep's results are the same bits. A reach of everything
/// (models whose blocks do not match the model's) keeps the models. Pre-condition: check_sensitivity_models() passed.
void keep_reached_only(const Model& model, OutputSensitivity& s);

/// The constraints `s`'s models change against `model` (ParameterReach); with the models released
/// (keep_reached_only()), `s.reach`. Pre-condition: check_sensitivity_models() passed. O(constraints): a comparison
/// of each constraint's data in the five models. Thread-safe.
ParameterReach parameter_reach(const Model& model, const OutputSensitivity& s);

/// The reach of every constraint of `model` (ParameterReach::everything set): what parameter_reach() gives for models
/// whose blocks do not match, and the whole-model evaluation along a parameter, for comparisons. Thread-safe.
ParameterReach whole_model_reach(const Model& model);

/// The default difference step for a parameter of value p: 10⁻³ |p|, or 10⁻³ for p = 0.
double default_sensitivity_step(double p);

/// Builds the mechanism with one design parameter at `value`, everything else as in the swept model: the same
/// coordinates, constraints and rows, only data differing. `share`, when not null, is the swept model: build with
/// ModelBuilder::share_analysis_with(*share), so that the model shares its pattern and symbolic analysis.
using ModelAtParameter = std::function<Model(double value, const Model* share)>;

/// The sensitivity along the parameter `name` of a model built in code (a scene's parameters have
/// sensitivity_along() of scene.hpp, which reads the scene again): `model` is build(value, nullptr) or the same
/// mechanism, and the models at value − 2h, − h, + h, + 2h are built by `build`, one at a time, of which only the
/// constraints the parameter reaches are kept (ReachedConstraints; all four models when `keep_models`); h = `step`,
/// or default_sensitivity_step(value) for step ≤ 0. The result goes into SweepOptions::sensitivities or
/// solve_sensitivities() with `model`. Throws phiq::Error with check_sensitivity_models()' line when a model along
/// p has another structure, and what `build` throws.
OutputSensitivity sensitivity_along(const Model& model, const std::string& name, double value,
                                    const ModelAtParameter& build, double step = 0.0, bool keep_models = false);

/// How a row's sensitivities are solved (SensitivityForm, output_plan.hpp).
///
/// Direct: one solve with Φq per parameter and derivative order, giving every coordinate's sensitivity (above).
///
/// Adjoint: per output coordinate i, Φqᵀ λ = e_i, and then ∂q_i/∂p_j = −λᵀ Φp_j for every parameter at once;
/// likewise for q̇ and q̈, whose right-hand sides are linear in the lower sensitivities: with a_j = ∂Φ/∂p_j,
/// b_j = ∂(Φq q̇ + Φt)/∂p_j and c_j = ∂(Φq q̈ − γ)/∂p_j at fixed (q, q̇), and B = ∂(Φq q̇ + Φt)/∂q,
///
///   ∂q_i/∂p_j = −λᵀ a_j,   ∂q̇_i/∂p_j = μᵀ a_j − λᵀ b_j,   ∂q̈_i/∂p_j = (ν − 2τ)ᵀ a_j + 2 μᵀ b_j − λᵀ c_j,
///
///   Φqᵀ μ = Bᵀ λ,   Φqᵀ τ = Bᵀ μ,   Φqᵀ ν = ∂(Φq q̈ − γ)/∂qᵀ λ     (∂γ/∂q̇ = −2B).
///
/// The transposed products are directional derivatives of Φqᵀv: Bᵀv = d/dε Φq(q + εq̇, t + ε)ᵀv and
/// ∂(Φq q̈ − γ)/∂qᵀ v = d/dε Φq(q + εq̈, t)ᵀv + d²/dε² Φq(q + εq̇, t + ε)ᵀv (−γ is the second derivative of Φ along
/// the motion), by central differences of fourth order (sixth for the second derivative; exact up to rounding
/// where Φq is polynomial of low degree in q, as for lengths). So an output costs 1, 2 or 4 solves with Φqᵀ (for
/// q, q̇, q̈) whatever the number of parameters, and a row 15 more evaluations of Φq; the direct form costs 1, 2
/// or 3 solves per parameter and, with q̇, 2 evaluations of γ (with q̈, and 4 of Φq and 4 of γ) along its
/// sensitivities. Both
/// evaluate each parameter's reach alike. The second derivative along the motion is that of a smooth Φq: where the
/// seven points straddle a place where Φq is not smooth (a spline's knot, where its third derivative jumps, as a pin in
/// a curved slot passes one), it would be off by percents, so a row whose sixth- and fourth-order second differences
/// disagree (by more than 10⁻⁴ of the largest entry) is solved in the direct form instead, whose differences along
/// the motion are first differences only: WorkCounters::sensitivity_direct_rows counts them.
///
/// The form kAuto stands for at derivative order `order` (0: q, 1: and q̇, 2: and q̈): kAdjoint when it costs
/// less, counting solves with Φq and evaluations of Φq or γ as half a solve (measured on nfourbar 10³: 0.4–0.6),
/// else kDirect: direct P·((order + 1) solves and (0, 2, 8) evaluations) against adjoint O·(1, 2, 4) solves and
/// (0, 4, 15) evaluations, for P parameters and O output coordinates (their reaches cost both forms alike). At
/// order 0 that is the adjoint when the parameters outnumber the outputs; with q̇ or q̈ and one output, from 2
/// parameters (bench/README.md, "Sensitivities": 1.4 of the direct form's time at 1, 0.91 at 2). With no output
/// coordinate (a caller reading every coordinate's, StepView::sensitivities, a Stepper), kDirect. Any other form
/// as given.
SensitivityForm effective_sensitivity_form(SensitivityForm form, std::size_t parameters, std::size_t outputs,
                                           int order);

/// "" when the four models of `s` can stand for `model` moved along the parameter (same number of coordinates and
/// of rows, the same Φq pattern, a finite positive step), or, with the models released, when `s.reached` was kept
/// for `s.reach`; else one line naming the parameter and what differs (a parameter that
/// sets a family's size or a count changes the structure: it has no derivative).
std::string check_sensitivity_models(const Model& model, const OutputSensitivity& s);

/// The sensitivities of the state in `ws` to each parameter of `parameters`, into `out` (SensitivityLayout): ∂q/∂p
/// always, ∂q̇/∂p for order ≥ 1 and ∂q̈/∂p for order 2 (NaN otherwise). Pre-conditions: ws.q solves the position
/// problem at t, ws.qd the velocity (order ≥ 1) and ws.qdd the acceleration (order 2), as after solve_position,
/// solve_velocity and solve_acceleration; each parameter passes check_sensitivity_models(); `out` holds
/// SensitivityLayout{n}.size(parameters.size()) values. Factorises Φq at ws.q unless the workspace's factors are
/// there already. Returns kSuccess, or kSingularJacobian at a singular position (Φq has no inverse there: the
/// sensitivities are not defined, `out` is NaN) and the failures of a factorisation. Throws phiq::Error for
/// violated pre-conditions (sizes, order outside 0 … 2, a parameter whose models do not match). Thread-safe for
/// distinct workspaces.
SolveStatus solve_sensitivities(const Model& model, const std::vector<OutputSensitivity>& parameters, double t,
                                int order, Workspace& ws, double* out, LinearSummary* summary = nullptr);

/// solve_sensitivities() in the adjoint form (SensitivityForm) for the coordinates `outputs` only (indices, each
/// 0 ≤ i < n, without repeats): their entries of `out` are written, every other entry is NaN. Same pre-conditions,
/// statuses and throws as solve_sensitivities(); `outputs` out of range or repeated throws phiq::Error.
SolveStatus solve_sensitivities_adjoint(const Model& model, const std::vector<OutputSensitivity>& parameters,
                                        const std::vector<Index>& outputs, double t, int order, Workspace& ws,
                                        double* out, LinearSummary* summary = nullptr);

}  // namespace phiq
