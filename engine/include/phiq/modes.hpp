/// @file
/// Every assembly mode of a mechanism: all the solutions of its constraint equations Φ(q, T) = 0 at one time T, by
/// polynomial homotopy continuation. Newton from a rough placement finds one assembly; this finds all of them and
/// says which one the placement assembles into.
///
/// The method. Each row of Φ is recovered as a polynomial in the coordinates it reads (find_polynomial_system():
/// the coefficients of every monomial up to degree 4 (each coordinate within its own degree in the row, when the
/// monomials are many) fitted by least squares to evaluations of the row, and checked
/// on fresh points), angle coordinates entering through (c, s) = (cos θ, sin θ) with c² + s² = 1; a row no
/// polynomial reproduces (a cam, a spline, exp) is refused with its constraint named. Rows affine in what they
/// read are eliminated first: those that fix one coordinate (drivers, a polar's arm at a driven angle), then sets
/// of them solved together (gears and belts among driven angles: linear in the angles, polynomial in no (c, s)).
/// A spatial joint-angle driver is read as s cos f − c sin f (c, s: the joint frames' axes' products). The square
/// polynomial system is then solved by solve_polynomial_system(): its degrees first lowered where rows share their
/// highest forms (ModesOptions::lower_degrees), then the start system with the fewest paths, the total-degree
/// x_i^{d_i} = 1 or a multi-homogeneous linear product (StartSystemChoice), and the
/// homotopy H(x, t) = (1 − t) F(x) + γ t G(x) with a random complex γ (the "γ trick": no path meets a singularity for t
/// > 0), tracked in projective coordinates on a random affine patch (paths that diverge in affine space end at points
/// with x₀ → 0, at infinity, instead of running away) by an adaptive RK4 predictor and Newton corrector. Every
/// endpoint is refined by Newton on the original equations and classified: real, complex, singular (condition
/// number above ModesOptions::singular_condition, or reached by several paths with a condition above
/// ModesOptions::multiple_root_condition) or at infinity. find_assembly_modes() solves a block-triangular system
/// block by block where that is safe (ModesMethod). Paths run in parallel
/// (TBB); each path's arithmetic is independent of the others and the endpoints are merged in path order and
/// sorted, so the result is the same, to the bit, on any number of threads.
#pragma once

#include <complex>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "phiq/model.hpp"

namespace phiq {

/// One term of a polynomial: coefficient · Π_v x_v^{exponent[v]}.
struct PolynomialTerm {
  std::complex<double> coefficient;  ///< its coefficient
  std::vector<int> exponent;         ///< one power per variable of the system (all ≥ 0)
};

/// A polynomial in the variables of its system: a sum of terms (no two with the same exponents).
struct Polynomial {
  std::vector<PolynomialTerm> terms;  ///< the terms, in any order
  /// The total degree: the largest sum of exponents over the terms (0 for a constant or empty polynomial).
  int degree() const;
};

/// A system of polynomial equations F(x) = 0 in `variables` complex unknowns.
struct PolynomialSystem {
  int variables = 0;                  ///< number of unknowns
  std::vector<std::string> names;     ///< their names (for messages and phc_input_text()); may be empty
  std::vector<Polynomial> equations;  ///< the equations; square systems have as many as unknowns
  /// Evaluates every equation at x (variables entries) into f (equations.size() entries).
  void evaluate(const std::complex<double>* x, std::complex<double>* f) const;
  /// The Bézout number Π deg F_i: the paths of the total-degree homotopy of a square system (saturated at 2⁶²).
  std::int64_t total_degree() const;
};

/// Which start system solve_polynomial_system() tracks its paths from (ModesOptions::start_system).
enum class StartSystemChoice {
  kFewestPaths,  ///< total degree or multi-homogeneous, equations lowered or not: whichever has the fewest paths
  kTotalDegree,  ///< x_i^{d_i} = 1 (the equations lowered when ModesOptions::lower_degrees and that cuts paths)
  /// the linear-product start system of the candidate grouping of two or more groups with the fewest paths (the
  /// total degree when there is none: a system in one variable)
  kMultiHomogeneous,
};

/// Settings of solve_polynomial_system() and find_assembly_modes().
struct ModesOptions {
  double time = 0.0;  ///< T, the time at which the drivers are evaluated (find_assembly_modes()): finite
  /// Refuse (ModesStatus::kTooManyPaths) rather than track more paths than this; 1 or more (else phiq::Error).
  std::int64_t max_paths = 100000;
  /// Worker threads for the paths; 0: TBB's default; at most 1000000 (else phiq::Error).
  int threads = 0;
  std::uint64_t seed = 20261202;  ///< seed of γ, the affine patch and the fitting points: a run is reproducible
  /// An endpoint whose Jacobian's condition number (2-norm, the equations at their coefficients' scale and the
  /// variables at the solution's: max(σ_max, 1) / σ_min) is above this is singular.
  /// (Several paths at one regular point are counted in ModesSummary::duplicate_paths, not made singular.)
  double singular_condition = 1e9;
  /// An endpoint is real when every |Im x_v| ≤ this · (1 + |x|∞).
  double real_tolerance = 1e-8;
  /// Endpoints closer than this · (1 + |x|∞) are one solution, reached by several paths (Endpoint::multiplicity).
  double duplicate_tolerance = 1e-6;
  int max_fit_degree = 4;  ///< the highest degree a row is fitted with (find_polynomial_system())
  /// An endpoint that several paths reach (after the careful second pass) is singular when its condition is above
  /// this: a multiple root, which double precision places only to about √ε, so that its condition stays near 1e8
  /// (a regular solution is the end of one path only; one that two paths reach is well conditioned).
  double multiple_root_condition = 1e5;
  /// find_assembly_modes(): solve a block-triangular system block by block where that is safe (ModesMethod), else
  /// (false, or not safe) the whole system at once.
  bool block_solve = true;
  /// The start system: by default whichever start system has the fewest paths (StartSystemChoice).
  StartSystemChoice start_system = StartSystemChoice::kFewestPaths;
  /// Lower the equations' degrees first where that cuts the paths: each equation plus polynomial multiples of the
  /// lower-degree ones before it, so that its highest-degree form cancels (the same ideal: the same finite
  /// solutions, with their multiplicities); a Stewart–Gough platform's 8192 total-degree paths become 432.
  bool lower_degrees = true;
  /// More candidate groupings of the variables for the multi-homogeneous start system (each group_of[v] per
  /// variable, as multihomogeneous_bezout_number() takes it; one of another size is ignored), besides those the
  /// system suggests (each rotation's c, s or Euler parameters, found by their normalisations, apart from the other
  /// variables; every variable alone).
  std::vector<std::vector<int>> groupings;
  /// The most turns round t = 0 Cauchy's end game takes to find a path's winding number (the number of paths that
  /// meet at its end). A path whose step collapses near t = 0 and that has not closed up after this many turns (nor
  /// after as many as the start system has paths) is failed, named in ModesSummary::failures.
  int max_winding = 32;
};

/// How find_assembly_modes() solved its system (ModesSummary::method).
enum class ModesMethod {
  kWholeSystem,  ///< one homotopy of the whole system
  /// Block by block: the Dulmage–Mendelsohn blocks in order, each for every real solution of those before it, the
  /// results refined and classified on the whole system. Used only when every solution carried from one block to
  /// the next is regular and well conditioned and no path failed (a singular one, known only to √ε, would perturb
  /// the blocks after it: a double root splits into two real or two complex ones); otherwise the whole system.
  kBlocks,
};

/// "whole system", "block by block".
const char* modes_method_name(ModesMethod method);

/// How a call of solve_polynomial_system() or find_assembly_modes() ended.
enum class ModesStatus {
  kSuccess,        ///< every path tracked (some may have failed: ModesSummary::failed_paths)
  kNotPolynomial,  ///< a constraint is not polynomial in its coordinates (the message names it)
  kTooManyPaths,   ///< the start system's paths are above ModesOptions::max_paths (the message says it)
  kNotSquare,      ///< fewer equations than unknowns: the assemblies form a continuum (the message says it)
};

/// What kind of point a path ended at.
enum class EndpointKind {
  kReal,      ///< a regular real solution
  kComplex,   ///< a regular solution with an imaginary part
  kSingular,  ///< a solution whose Jacobian is singular (condition above ModesOptions::singular_condition)
  /// The path diverged: the homogenising coordinate of its end on the projective patch (placed by the end game
  /// where its step collapsed) is zero to the end's accuracy.
  kAtInfinity,
  kFailed,  ///< the path could not be tracked to its end (step below the minimum away from t = 0)
};

/// "real", "complex", "singular", "at infinity", "failed".
const char* endpoint_kind_name(EndpointKind kind);

/// One distinct endpoint of the homotopy (duplicates merged).
struct Endpoint {
  EndpointKind kind = EndpointKind::kFailed;  ///< its class
  Eigen::VectorXcd x;  ///< the solution in the system's variables (for kAtInfinity: the direction, unit norm)
  /// max_i |F_i(x)| / (largest |coefficient| of F_i), after Newton's refinement; at infinity, of the homogenised
  /// (and degree-lowered) equations at the end on the patch
  double residual = 0.0;
  /// condition number of the Jacobian at x (variables scaled by 1 + |x|∞); at infinity, of the homogenised
  /// equations' Jacobian with the patch's rows there
  double condition = 0.0;
  int multiplicity = 1;  ///< how many paths ended here
};

/// What solve_polynomial_system() did.
struct ModesSummary {
  ModesStatus status = ModesStatus::kSuccess;  ///< see ModesStatus
  std::string message;                         ///< one line when status is not kSuccess
  std::int64_t paths = 0;                      ///< paths tracked (the start system's; block by block, all blocks')
  int real = 0;                                ///< distinct real regular endpoints
  int complex = 0;       ///< distinct complex regular endpoints (block by block: the blocks', not carried forward)
  int singular = 0;      ///< distinct singular endpoints
  int at_infinity = 0;   ///< distinct endpoints at infinity
  int failed_paths = 0;  ///< paths that could not be tracked to t = 0, or whose end solves none of the equations
  /// Paths that ended at a regular endpoint another path had reached: a path jumped onto another's on the way (a
  /// regular solution is the end of one path only), so that some solution may be missing. 0 when all went well.
  int duplicate_paths = 0;
  /// Paths tracked a second time, with shorter steps, because the first attempt failed or ended at another path's
  /// regular endpoint (the counts above are those after the second attempt).
  int retracked_paths = 0;
  /// Paths whose end Cauchy's end game found (their step collapsed near t = 0: a singular endpoint or one at
  /// infinity, reached by circling t = 0 until the path closes up, and the mean of its points there).
  int end_game_paths = 0;
  double seconds = 0.0;                            ///< wall time of the tracking
  ModesMethod method = ModesMethod::kWholeSystem;  ///< how the system was solved
  int blocks = 1;                                  ///< the blocks solved in turn (1: the whole system)
  /// The start system the paths were tracked from: "total degree", "total degree, degrees lowered" or
  /// "multi-homogeneous {x y} {cos(a) sin(a)}" (its groups; ", degrees lowered" when they were). Block by block: the
  /// last block's.
  std::string start_system;
  /// The total degree of the (squared-up) system as given, before any lowering: `paths` against this is what the
  /// start system saved.
  std::int64_t total_degree = 0;
  /// Why the whole system was solved where the block solve was tried and found unsafe (empty otherwise): one line
  /// naming the block and what it found there.
  std::string method_note;
  /// The distinct endpoints: real first, then complex, singular, at infinity, failed; within a kind in a fixed
  /// order (lexicographic in the real, then imaginary parts).
  std::vector<Endpoint> endpoints;
  /// Each failed path named (failed_paths of them, in path order): its number in the start system's order (from 0;
  /// block by block, the blocks' numbers are their own) and why it failed, in one line.
  std::vector<std::pair<std::int64_t, std::string>> failures;
};

/// Solves a square polynomial system (or an overdetermined one: its equations are first combined at random into as
/// many as unknowns, and the endpoints are refined and checked on all of them; a non-solution of the original
/// system is classified kFailed) by homotopy continuation (the file's comment). Refuses with
/// kTooManyPaths (nothing tracked) when the start system's paths are above options.max_paths, with kNotSquare when
/// there are fewer equations than unknowns. The result does not depend on options.threads. Throws phiq::Error for a
/// system whose terms do not have `variables` exponents.
ModesSummary solve_polynomial_system(const PolynomialSystem& system, const ModesOptions& options);

/// The multi-homogeneous Bézout number of a square system for a grouping of its variables (group_of[v]: the group
/// of variable v, 0 … groups − 1, every group used): the coefficient of Π_j α_j^{n_j} (n_j the variables of group j)
/// in Π_i Σ_j d_ij α_j (d_ij: equation i's degree in group j's variables), the number of paths of the
/// multi-homogeneous start system. One group: the total degree. Saturated at 2⁶².
std::int64_t multihomogeneous_bezout_number(const PolynomialSystem& system, const std::vector<int>& group_of);

/// The text of `system` in PHCpack's input format (`phc -b in out`): the number of equations and unknowns, then
/// each equation ended by ';', coefficients in full precision, variable v as x(v + 1): x1, x2, …
std::string phc_input_text(const PolynomialSystem& system);

/// A row that relates free angles linearly with rational ratios (a gear or a belt between angles a linkage turns):
/// Σ_k n_k θ_k = phase with integers n_k, solved modulo 2π as the complex polynomial
/// Π_{n_k > 0} (c_k + i s_k)^{n_k} − e^{i·phase} Π_{n_k < 0} (c_k − i s_k)^{−n_k} = 0 (Chebyshev's multiple angles).
struct AngleRelation {
  Index row = -1;              ///< its row of Φ
  std::vector<Index> angles;   ///< the angle coordinates it reads
  std::vector<int> multiples;  ///< n_k, one per angle, their greatest common divisor 1
  double phase = 0.0;          ///< the right-hand side (rad)
};

/// A model's equations at time T as polynomials (find_polynomial_system()).
struct ModelPolynomials {
  ModesStatus status = ModesStatus::kSuccess;  ///< kNotPolynomial (nothing else set) or kSuccess
  std::string message;                         ///< names the constraint when kNotPolynomial
  /// The system in scaled variables: a length or unitless coordinate j is q_j = q0_j + scale_j · x_v; an angle
  /// coordinate is the pair (c, s) = (cos q_j, sin q_j), with its equation c² + s² − 1 = 0 among the equations.
  PolynomialSystem system;
  /// For each coordinate of the model: −1 when eliminated (fixed), else its variable (the c of an angle, s is next).
  std::vector<int> variable_of;
  std::vector<double> fixed;                   ///< the value of every eliminated coordinate (NaN for the others)
  Eigen::VectorXd origin;                      ///< q0, the placement the scaled variables are measured from
  Eigen::VectorXd scale;                       ///< the scale of each coordinate's variable (1 for angles)
  std::vector<Index> eliminated_rows;          ///< the rows of Φ that fixed a coordinate, ascending
  std::vector<AngleRelation> angle_relations;  ///< the rows solved modulo 2π, in row order
  /// q of a real solution x of `system`: angles as atan2(s, c) on the 2π branch nearest the placement, then turned
  /// by whole turns where an angle relation needs it to hold exactly (the relations in order; one may undo an
  /// earlier one's that shares its angles, and find_assembly_modes() then rejects the point).
  Eigen::VectorXd coordinates(const Eigen::VectorXcd& x) const;
};

/// Recovers each row of Φ(·, options.time) as a polynomial (the file's comment): rows that read one coordinate and
/// are affine in it fix it, then sets of rows affine in all they read fix what they determine (eliminated,
/// repeatedly, as fixed coordinates make more rows affine), and every other
/// row is fitted, degree 1 to options.max_fit_degree, in its coordinates' scaled variables. kNotPolynomial names
/// the first constraint no polynomial reproduces ("constraint 'cam': is not polynomial in its coordinates …").
/// Thread-safe.
ModelPolynomials find_polynomial_system(const Model& model, const ModesOptions& options);

/// One real assembly mode of a model.
struct AssemblyMode {
  Eigen::VectorXd q;       ///< its coordinates (angles on the branch nearest the placement)
  double residual = 0.0;   ///< max_i |Φ_i(q, T)| / row scale_i, Φ evaluated by the model itself
  double condition = 0.0;  ///< of the polynomial system's Jacobian there (Endpoint::condition)
  bool singular = false;   ///< a real singular solution (two modes meet: a singular position)
};

/// Every real assembly mode of a model at one time.
struct AssemblyModes {
  ModesSummary summary;             ///< the homotopy's (status, message, counts, endpoints in the system's variables)
  ModelPolynomials polynomials;     ///< the system solved
  std::vector<AssemblyMode> modes;  ///< the real solutions, regular and singular, in the summary's order
  /// Real solutions of the system that are no assembly: the model's own Φ is not zero there (a spatial joint-angle
  /// driver's polynomial form also holds at the driven angle + π).
  int rejected = 0;
  /// Real solutions that are another's placement again: a body's Euler parameters −e for e (each mode keeps the
  /// sign nearest the placement's).
  int merged = 0;
};

/// find_polynomial_system() then solve_polynomial_system(): every real assembly of `model` at options.time, each
/// checked on the model's own equations (AssemblyModes::rejected) and placements found twice merged
/// (AssemblyModes::merged). The status and message are those of the first step that refused. Thread-safe.
AssemblyModes find_assembly_modes(const Model& model, const ModesOptions& options);

/// The distance between two positions of `model`: max_j |a_j − b_j| / scale_j, lengths scaled by the model's
/// length_scale(), angles (radians) compared modulo 2π, other coordinates as they are.
double mode_distance(const Model& model, const Eigen::VectorXd& a, const Eigen::VectorXd& b);

/// Which real assembly mode a position is in: the nearest mode by mode_distance(), and the next nearest.
struct ModeLocation {
  int mode = -1;               ///< index into the modes of the nearest (−1: there are none)
  double distance = 0.0;       ///< mode_distance() from the position to that mode
  int next = -1;               ///< index of the next nearest (−1: fewer than two modes)
  double next_distance = 0.0;  ///< mode_distance() from the position to the next nearest
};

/// The mode of `modes` nearest to q (a position of `model`, as long as its coordinates) and the next nearest, by
/// mode_distance(); ties go to the lower index. Pure function.
ModeLocation locate_mode(const Model& model, const Eigen::VectorXd& q, const std::vector<AssemblyMode>& modes);

}  // namespace phiq
