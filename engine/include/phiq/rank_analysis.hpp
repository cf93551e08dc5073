/// @file
/// Rank and redundancy of the constraint equations at one configuration: which rows of Φq are linearly independent,
/// how many degrees of freedom the mechanism has there, and which equations are redundant (linear combinations of
/// others, e.g. the third hinge of a door). Rank is a property of a configuration, not of a model: a four-bar at its
/// change point loses rank only there, a parallelogram with a fifth bar everywhere on its motion.
///
/// Method: a rank-revealing sparse QR (SuiteSparseQR, Heath's method) of the scaled transposed Jacobian
/// J̃ᵀ = (D_r⁻¹ Φq D_c)ᵀ, whose columns are the equations, kinematic rows first, then the rheonomic ones (a driver
/// is only called redundant when the kinematic rows already fix what it drives), each group in model order or in a
/// fill-reducing order (RankOrdering). D_r and D_c are the model's tolerance scales (ToleranceScales: lengths by
/// their own links, 1 for angles and unitless rows), so that the rank does not depend on units or on where the
/// origin is. With the fixed column order the factorisation takes the equations
/// greedily: an equation is redundant when it is (within the tolerance) a combination of equations before it in
/// that order.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "phiq/model.hpp"

namespace phiq {

/// In which order the rank analysis takes the equations (it keeps an equation unless it combines those before it).
enum class RankOrdering {
  kAuto,          ///< kModelOrder up to 20000 equations, kFillReducing beyond
  kModelOrder,    ///< scene order (kinematic rows, then rheonomic): the later of two dependent equations is redundant
  kFillReducing,  ///< CCOLAMD's fill-reducing order within the kinematic rows, then within the rheonomic ones
};

/// Settings of analyse_rank().
struct RankOptions {
  /// Order of the greedy choice. The model order names the redundant equations the way a user reads the scene (the
  /// third hinge, not the first), but the QR of a long chain taken in that order fills in quadratically; the
  /// fill-reducing order keeps the analysis of 10^5–10^6 equations near linear (bench/README.md) and still keeps
  /// every driver after the kinematic rows.
  RankOrdering ordering = RankOrdering::kAuto;
  /// Relative rank tolerance δ: an equation is redundant when the part of its scaled Jacobian row not spanned by
  /// the rows before it has a 2-norm ≤ δ · (largest scaled row norm). 1e-8 ≈ √ε: at a position solved to a
  /// tolerance of 1e-10 the Jacobian itself is only known to about that relative accuracy, so dependencies closer
  /// than δ cannot be told from exact ones, while dependencies as loose as 1e-6 (a hinge misaligned by a
  /// micrometre per metre) are real and reported as independent equations.
  double tolerance = 1e-8;
  /// Dense cross-check (singular values of J̃ by Eigen's BDCSVD) when min(m, n) is at most this: the sparse rank
  /// must agree with the number of singular values above δ, else the result is reported as uncertain.
  Index dense_check_limit = 400;
  /// A near-miss margin: the result is uncertain when an independent equation's pivot is within this factor of the
  /// tolerance (δ < |R_kk| ≤ margin · δ) or, in the dense check, a singular value lies in (δ / margin, δ · margin].
  double margin = 100.0;
};

/// What analyse_rank() found.
struct RankReport {
  Index coordinates = 0;          ///< n
  Index equations = 0;            ///< m, all rows (kinematic and rheonomic)
  Index kinematic_equations = 0;  ///< rows of constraints that do not depend on t
  Index driver_equations = 0;     ///< rows of rheonomic constraints (drivers, equations in t)
  Index rank = 0;                 ///< rank of the kinematic rows
  Index dof = 0;                  ///< n − rank: degrees of freedom of the mechanism here (drivers not counted)
  Index driven_rank = 0;          ///< rank of all rows
  Index driven_dof = 0;           ///< n − driven_rank: freedoms the drivers leave (0 for a fully driven mechanism)
  std::optional<Index> grubler;   ///< Grübler–Kutzbach count from the joints (Model::grubler()), if defined
  std::vector<Index> independent_rows;  ///< a maximal independent set of rows, ascending (the square solve keeps these)
  std::vector<Index> redundant_rows;    ///< the other rows, ascending
  std::vector<std::string> redundant;   ///< names of the constraints owning redundant rows, in model order, once each
  double tolerance = 0.0;               ///< δ used
  RankOrdering ordering = RankOrdering::kModelOrder;  ///< the order used (kAuto resolved)
  double smallest_pivot = 0.0;  ///< smallest |R_kk| / largest row norm of an independent equation (1 if none)
  bool dense_checked = false;   ///< the dense cross-check ran
  Index dense_rank = -1;        ///< its rank of all rows (−1 when it did not run)
  /// The rank is uncertain: a pivot or singular value within RankOptions::margin of the tolerance, or the sparse and
  /// dense ranks disagree. `message` says which; the numbers above are the sparse QR's.
  bool uncertain = false;
  std::string message;  ///< one line; empty when nothing is uncertain
  /// One line: n, m, rank, dof, redundant equations.
  std::string BriefReport() const;
};

/// Rank analysis of Φq(q, t) (all rows). Pre-condition: q has num_coordinates() finite entries (else phiq::Error).
/// Throws phiq::Error if SuiteSparseQR fails (out of memory). Thread-safe.
RankReport analyse_rank(const Model& model, const Eigen::VectorXd& q, double t, const RankOptions& options = {});

/// For each row r of `rows`, the rows of `basis` whose scaled Jacobian rows combine to r's (the least-squares
/// coefficients c of J̃_basisᵀ c = J̃_rᵀ larger than 1e-8 · max|c|), and the relative residual of that fit
/// (≈ 0 when r is a combination of the basis). The basis rows must be independent at q. Used to name the
/// constraints that conflict with an inconsistent redundant row. Thread-safe.
struct RowCombination {
  Index row = -1;             ///< the redundant row
  std::vector<Index> basis;   ///< the rows it is a combination of, ascending
  double fit_residual = 0.0;  ///< ‖J̃_basisᵀ c − J̃_rᵀ‖ / ‖J̃_r‖
};
/// See RowCombination. Throws phiq::Error if `basis` is dependent at q (CHOLMOD finds J̃ J̃ᵀ singular).
std::vector<RowCombination> combinations_of(const Model& model, const Eigen::VectorXd& q, double t,
                                            const std::vector<Index>& basis, const std::vector<Index>& rows);

/// The scaled Jacobian D_r⁻¹ Φq D_c restricted to a list of rows — what the rank analysis and the minimum-norm
/// assembly factorise. Set-up (the constructor) fixes its pattern and, for every entry, where it comes from in
/// Φq's value array and its scale; an evaluation is then one Φq evaluation and a gather, with no allocation, so
/// that iterative solvers pay for the pattern once. Not thread-safe (its Φq scratch): one object per thread.
class ScaledJacobianRows {
 public:
  /// The rows `rows` of `model` (in that order: row k of the result is model row rows[k]). Throws phiq::Error for a
  /// row out of range. The object follows the model where it moves; evaluate() throws phiq::Error once the model
  /// is destroyed (as Workspace does).
  ScaledJacobianRows(const Model& model, std::vector<Index> rows);
  /// The rows, in the order of the pattern's rows.
  const std::vector<Index>& rows() const { return rows_; }
  /// The pattern (rows().size() × n); shared so that solvers can keep it.
  const std::shared_ptr<const CscPattern>& pattern() const { return pattern_; }
  /// The values at (q, t), in pattern order, into `values` (resized). Pre-condition: q has n entries.
  void evaluate(const Eigen::VectorXd& q, double t, std::vector<double>& values);
  /// The values from Φq's values already evaluated (jacobian_pattern() order), into `values` (resized).
  void gather(const double* jacobian_values, std::vector<double>& values) const;

 private:
  std::shared_ptr<const detail::ModelAnchor> model_;  // where the model is now (Model::anchor_)
  std::vector<Index> rows_;
  std::shared_ptr<const CscPattern> pattern_;
  std::vector<Index> source_;  // entry k is Φq's value source_[k] · coordinate_scale(column) / row_scale(row)
  std::vector<double> full_;   // Φq values (scratch of evaluate())
};

/// The scaled Jacobian at (q, t) restricted to `rows` (in that order), as a pattern and values: a one-off
/// ScaledJacobianRows. Thread-safe.
void scaled_jacobian_rows(const Model& model, const Eigen::VectorXd& q, double t, const std::vector<Index>& rows,
                          CscPattern* pattern, std::vector<double>* values);

}  // namespace phiq
