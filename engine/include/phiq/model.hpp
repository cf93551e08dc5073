/// @file
/// The immutable description of a mechanism: generalized coordinates, constraint equations, the fixed sparsity
/// pattern of Φq, and the symbolic factorisation of that pattern. A Model is built once (ModelBuilder or a scene
/// file) and then only read: any number of threads may evaluate it and solve with it at once, each with its own
/// Workspace (workspace.hpp).
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <iterator>
#include <limits>
#include <memory>
#include <optional>
#include <type_traits>
#include <string>
#include <string_view>
#include <typeindex>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <Eigen/Core>

#include "phiq/constraint_block.hpp"
#include "phiq/constraint_kinds_3d.hpp"
#include "phiq/linear_solver.hpp"
#include "phiq/name_index.hpp"
#include "phiq/sparse_pattern.hpp"

namespace phiq {

namespace detail {
/// Throws phiq::Error for an index `i` outside [0, size) of a `what` ("row", "coordinate").
[[noreturn]] void throw_index_out_of_range(Index i, Index size, const char* what);
/// `i` as a vector index, checked: the accessors that take a row or coordinate index read out of bounds otherwise
/// (an embedding program's stale index is its error, said as one, not a crash). One comparison, on cold paths.
inline std::size_t index_in(Index i, Index size, const char* what) {
  if (i < 0 || i >= size) throw_index_out_of_range(i, size, what);
  return static_cast<std::size_t>(i);
}
}  // namespace detail

namespace detail {
/// Whether a driver's law has a function: a default-constructed MotionLaw has none (its evaluation throws, and its
/// domain reads [0, 0]); an equation's absent law is f ≡ 0.
inline bool law_has_value(const MotionLaw& law) { return law.has_value(); }
inline bool law_has_value(const std::optional<MotionLaw>& law) { return !law || law->has_value(); }
}  // namespace detail

/// One constraint of a model, as diagnostics name it.
struct ConstraintInfo {
  std::string name;              ///< as given by the user (or "<kind>#<k>")
  std::string_view kind;         ///< DistanceSpec::kKind, ... (a static string: no copy per constraint)
  Index first_row = 0;           ///< its first row in Φ
  int rows = 0;                  ///< how many rows it owns
  bool depends_on_time = false;  ///< rheonomic (a driver, or an equation in t)
};

/// The per-row and per-coordinate scales of the dimensional tolerances, fixed per model (computed by
/// ModelBuilder::build() so that the Newton loop only reads them). A position is within the tolerance `tol` when
/// every row |Φ_i| ≤ tol · row_scale_i + floor_i and the estimated error of every coordinate is within
/// tol · coordinate_scale_j + floor_j (NewtonOptions::tolerance).
///
/// Lengths are relative to the links they belong to, so that one model may mix millimetres and kilometres: a
/// length row is scaled by its own constraint's length (a distance's L, a crank's length, the moving arm of a pin:
/// DistanceSpec::characteristic_length()); a length coordinate by the smallest of those among the rows that read it
/// (a point is located as accurately as the shortest link attached to it needs); a length row that carries no
/// length (a point on a line, a segment angle, an equation) by the largest scale of the length coordinates it
/// reads. What is left (no length anywhere near it) falls back to length_scale(). With
/// ModelBuilder::set_length_scale() (scene `solver.length_scale`) every length row and coordinate uses that one
/// scale instead. Angle and unitless rows and coordinates: 1.
///
/// The rounding floor of a row is kUlpFloor (64 ulps) times Σ_j |∂Φ_i/∂q_j| · |q_j| at the point tested
/// (Model::row_rounding_floor()): how much the row's value moves when every coordinate it reads moves by 64 ulps of
/// itself. A residual cannot be resolved below that, wherever the origin is (a link 10⁶ m from it), and a row that
/// hardly depends on large coordinates (atan(x) at x = 10²⁶, a driver 1/x) gets no floor from them: its residual
/// is held to the tolerance. floor_j of a coordinate is kUlpFloor · |q_j|.
struct ToleranceScales {
  Eigen::VectorXd row_scale;         ///< per row, metres for length rows, 1 for angle and unitless rows
  Eigen::VectorXd coordinate_scale;  ///< per coordinate, metres for length coordinates, 1 otherwise
  /// 1 / row_scale: the Newton loop's per-iteration tests multiply instead of dividing.
  Eigen::VectorXd inverse_row_scale;
  Eigen::VectorXd inverse_coordinate_scale;  ///< 1 / coordinate_scale (see inverse_row_scale)
  /// 64 ulps: the rounding floor per unit of |q| (see above).
  static constexpr double kUlpFloor = 64.0 * std::numeric_limits<double>::epsilon();
};

class Model;

namespace detail {
/// Where a Model is now: what its Workspaces (and ScaledJacobianRows) hold instead of its address, so that a Model
/// that moves (in a growing std::vector) takes its workspaces along, and one that is destroyed leaves them refusing
/// to work (Workspace::model() throws) instead of reading freed memory. Shared by the model and its workspaces.
struct ModelAnchor {
  const Model* model = nullptr;  ///< the model's current address; null once it is destroyed
};
/// Throws phiq::Error "the Model this <what> was made for no longer exists" (`anchor` not null: the model was
/// destroyed), or "this <what> was moved from" (null).
[[noreturn]] void throw_model_gone(const ModelAnchor* anchor, const char* what);
/// The model `anchor` points at now; throws phiq::Error (throw_model_gone) when there is none.
inline const Model& model_of(const ModelAnchor* anchor, const char* what) {
  if (!anchor || !anchor->model) throw_model_gone(anchor, what);
  return *anchor->model;
}

/// Model's data, a base of its own so that Model's moves, which re-point the anchor, need not list every member
/// (a member added later and forgotten in a hand-written move would silently be left behind).
struct ModelData {
  std::vector<std::string> names_;
  detail::NameIndex index_of_;          ///< coordinate names → indices (names in names_)
  detail::NameIndex constraint_index_;  ///< constraint names → indices (names in constraints_[k].name)
  Eigen::VectorXd initial_;
  std::vector<Unit> coordinate_units_;
  std::vector<std::shared_ptr<ConstraintBlock>> blocks_;  ///< read-only once built (shared by without_rows())
  std::vector<const ConstraintBlock*> time_blocks_;
  std::vector<ConstraintInfo> constraints_;
  /// Each constraint's block (index into blocks_) and its index there: (block, index) per constraint.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> constraint_place_;
  std::vector<Index> row_constraint_;
  std::vector<Unit> row_units_;
  std::shared_ptr<const CscPattern> pattern_ = std::make_shared<CscPattern>();
  std::vector<EntryIndex> slot_of_entry_;
  double length_scale_ = 1.0;
  ToleranceScales scales_;
  double time_begin_ = -1e308, time_end_ = 1e308;
  std::string time_limiter_;
  // KLU by default: its refactorisation is 10-12x cheaper per drive step than UMFPACK on nfourbar from 10^3 to
  // 10^5 four-bars (bench/README.md).
  LinearSolverKind lu_kind_ = LinearSolverKind::kKlu;
  std::shared_ptr<const SparseLuSymbolic> symbolic_;
  std::vector<Index> dropped_rows_, solve_rows_;  ///< both empty unless rows are dropped (without_rows())
  std::shared_ptr<const CscPattern> solve_pattern_ = pattern_;
  std::vector<Index> solve_entries_;
  std::optional<Index> grubler_;
  std::vector<std::string> body_names_;
};
}  // namespace detail

/// An immutable mechanism: coordinates, constraints, the fixed CSC pattern of Φq and its symbolic analysis.
/// Built by ModelBuilder or load_scene(). Every const member function is thread-safe. Movable, not copyable.
/// Its Workspaces follow it when it moves (a std::vector<Model> may grow while they exist) and refuse to work
/// (phiq::Error) once it is destroyed; moving it while another thread solves with it is a data race.
class Model : private detail::ModelData {
 public:
  /// Takes `other`'s data and its workspaces: they refer to this model from now on. `other` is left without
  /// workspaces (making one of it throws phiq::Error) until it is assigned a model again.
  Model(Model&& other) noexcept;
  /// Takes `other`'s data and workspaces (as the move constructor); the workspaces made for this model before
  /// refuse to work from now on, as if it had been destroyed.
  Model& operator=(Model&& other) noexcept;
  Model& operator=(const Model&) = delete;
  /// Workspaces made for the model refuse to work from now on (phiq::Error, not a read of freed memory).
  ~Model();

  /// n, the size of q.
  Index num_coordinates() const { return static_cast<Index>(names_.size()); }
  /// m, the number of rows of Φ (kinematic and rheonomic).
  Index num_equations() const { return static_cast<Index>(row_constraint_.size()); }
  /// Coordinate names, in the order of q.
  const std::vector<std::string>& coordinate_names() const { return names_; }
  /// Index of a coordinate by name; throws phiq::Error for an unknown name.
  Index coordinate_index(const std::string& name) const;
  /// Index of a coordinate by name, or -1 for an unknown name.
  Index find_coordinate(std::string_view name) const;
  /// The initial guesses (rough placement) of q.
  const Eigen::VectorXd& initial_positions() const { return initial_; }
  /// Unit of coordinate j, inferred from the constraints that read it. Throws phiq::Error unless 0 ≤ j < n.
  Unit coordinate_unit(Index j) const {
    return coordinate_units_[detail::index_in(j, num_coordinates(), "coordinate")];
  }

  /// The constraints, in the order they were added (rows follow that order).
  const std::vector<ConstraintInfo>& constraints() const { return constraints_; }
  /// The constraint blocks, one per kind, for tools that read the constraints' data (mechanism_sketch.hpp).
  const std::vector<std::shared_ptr<ConstraintBlock>>& blocks() const { return blocks_; }
  /// Index into constraints() of the constraint named `name` (as given to ModelBuilder::add or in the scene);
  /// throws phiq::Error for an unknown name. O(1): a hash index over the names, kept from the build.
  Index constraint_index(std::string_view name) const;
  /// Index into constraints() of the constraint named `name`, or -1 for an unknown name.
  Index find_constraint(std::string_view name) const;
  /// The constraint named `name`: its kind and its rows [first_row, first_row + rows) in Φ. Throws phiq::Error
  /// for an unknown name.
  const ConstraintInfo& constraint(std::string_view name) const {
    return constraints_[static_cast<std::size_t>(constraint_index(name))];
  }
  /// The row of Φ named `row_name` as row_name() names it: "name" for a one-row constraint, "name[k]" for row k of
  /// a multi-row one (a constraint whose own name is the whole string comes first). Throws phiq::Error for a name
  /// that names no row (an unknown constraint, k out of range, or a bare multi-row name).
  Index row_index(std::string_view row_name) const;
  /// The block of blocks() that holds constraint c (an index into constraints()) and c's index in it: O(1), a table
  /// built with the model (what a reaction or a dropped row's gradient evaluates one constraint through). Throws
  /// phiq::Error unless 0 ≤ c < constraints().size().
  std::pair<const ConstraintBlock*, std::size_t> constraint_block(Index c) const {
    const auto [b, i] =
        constraint_place_[detail::index_in(c, static_cast<Index>(constraint_place_.size()), "constraint")];
    return {blocks_[b].get(), i};
  }
  /// Index into constraints() of the constraint owning `row`. Throws phiq::Error unless 0 ≤ row < m.
  Index constraint_of_row(Index row) const { return row_constraint_[detail::index_in(row, num_equations(), "row")]; }
  /// Unit of a row of Φ (for its tolerance). Throws phiq::Error unless 0 ≤ row < m.
  Unit row_unit(Index row) const { return row_units_[detail::index_in(row, num_equations(), "row")]; }
  /// "name" for one-row constraints, "name[k]" for row k of a multi-row one. Throws phiq::Error unless 0 ≤ row < m.
  std::string row_name(Index row) const;
  /// "" when every constraint's equations are defined at q; else "constraint 'NAME': what happened" for the first
  /// that is not (a curve parameter past the end of an open curve: PointOnCurveSpec::outside_domain()). The sweeps
  /// check every converged position (SolveStatus::kOutsideDomain). Thread-safe.
  std::string outside_domain(const double* q) const;
  /// The Grübler–Kutzbach count of the model's joints: 3 (nb − 1) − Σ c_i for planar bodies, 6 (nb − 1) − Σ c_i for
  /// spatial bodies, nb counting ground and c_i the freedoms joint i removes (drivers and the bodies' Euler
  /// normalisations are not counted). std::nullopt where it is not defined: no bodies (ModelBuilder::add_body), a
  /// constraint that is not a joint between bodies or ground (natural coordinates, equations, …), or planar and
  /// spatial parts mixed. A lower count than the degrees of freedom n − rank shows redundant joints.
  std::optional<Index> grubler() const { return grubler_; }
  /// Names of the bodies recorded with ModelBuilder::add_body(), in order.
  const std::vector<std::string>& body_names() const { return body_names_; }
  /// True when some constraint depends on t (then Φt is not identically zero).
  bool has_time_dependence() const { return !time_blocks_.empty(); }

  /// Characteristic length of the model (metres): the largest length in the constraints' data, else the extent of
  /// the initial placement, else 1 (or the one set with ModelBuilder::set_length_scale()). Each length row's and
  /// coordinate's tolerance is relative to its own scale (tolerance_scales()); this one is their fallback.
  double length_scale() const { return length_scale_; }
  /// The tolerance scale of every row and coordinate (from their units and length_scale()).
  const ToleranceScales& tolerance_scales() const { return scales_; }
  /// The fixed pattern of Φq (m × n); Jacobian values are stored in its order.
  const CscPattern& jacobian_pattern() const { return *pattern_; }
  /// For each entry of the constraint blocks' triplet lists, in the order build_pattern() appended them, its slot
  /// in jacobian_pattern()'s value array: ConstraintBlock::jacobian()'s `slot_of_entry`, for solvers that evaluate
  /// a few constraints at a time through blocks() (the block-triangular assembly of a singular start).
  const std::vector<EntryIndex>& slot_of_entry() const { return slot_of_entry_; }
  /// The sparse LU the model was analysed for.
  LinearSolverKind linear_solver() const { return lu_kind_; }
  /// Symbolic analysis of the square system the solvers factorise (solve_pattern()); nullptr when it is not square
  /// (solve rows ≠ coordinates).
  const SparseLuSymbolic* symbolic() const { return symbolic_.get(); }

  // Redundant rows left out of the square solves. A model whose equations are redundant (more rows than their
  // rank) is solved on a maximal independent set of rows (rank_analysis.hpp): without_rows() makes that model.
  // Φ, Φq, Φt and γ are still evaluated for every row (the convergence test checks the rows left out too:
  // consistent redundant rows hold wherever the kept rows do); the LU factorises and solves with the kept rows only.

  /// A model equal to this one that leaves `rows` out of its square solves: same coordinates, constraints,
  /// evaluation and tolerances (the constraint data is shared, read-only), its own pattern of the kept rows and
  /// symbolic analysis (when they are square). Rows are ascending or not, without repeats, 0 ≤ row < m; an empty
  /// list gives back the full model. Throws phiq::Error for rows out of range or repeated. Thread-safe.
  Model without_rows(std::vector<Index> rows) const;
  /// Rows left out of the square solves, ascending (empty for a model built by ModelBuilder).
  const std::vector<Index>& dropped_rows() const { return dropped_rows_; }
  /// Rows the square solves use, ascending, when some are dropped; empty when none is (then they are all rows, and
  /// solve_pattern() is jacobian_pattern()).
  const std::vector<Index>& solve_rows() const { return solve_rows_; }
  /// How many rows the square solves use: solve_pattern().rows.
  Index num_solve_rows() const { return solve_pattern_->rows; }
  /// The pattern of Φq restricted to solve_rows() (rows renumbered 0 …); the same object as jacobian_pattern()
  /// when no row is dropped.
  const CscPattern& solve_pattern() const { return *solve_pattern_; }
  /// For each entry k of solve_pattern(), its position in jacobian_pattern()'s value array (empty when no row is
  /// dropped: the arrays are the same).
  const std::vector<Index>& solve_entries() const { return solve_entries_; }

  /// Earliest / latest time at which every driver is defined (tabulated laws have a finite range).
  double time_domain_begin() const { return time_begin_; }
  double time_domain_end() const { return time_end_; }  ///< see time_domain_begin()
  /// Name of the driver that limits the time domain (empty when none does).
  const std::string& time_domain_limiter() const { return time_limiter_; }

  /// Φ(q, t) into phi (m entries). Pre-condition: q has n entries. Thread-safe.
  void residual(const double* q, double t, double* phi) const;
  /// Φq(q, t) values into csc_values (jacobian_pattern().nnz() entries, in pattern order). Thread-safe.
  void jacobian(const double* q, double t, double* csc_values) const;
  /// residual() and jacobian() together, in one pass over the constraints (cheaper than the two calls on large
  /// models, where each pass streams the constraint data from memory). Thread-safe.
  void residual_and_jacobian(const double* q, double t, double* phi, double* csc_values) const;
  /// ∂Φ/∂t into out (m entries; zero rows for constraints that do not depend on t). Thread-safe.
  void phi_t(const double* q, double t, double* out) const;
  /// γ = −(Φq q̇)q q̇ − 2Φqt q̇ − Φtt into out (m entries). Pre-condition: qd has n entries. Thread-safe.
  void gamma(const double* q, const double* qd, double t, double* out) const;
  /// The rounding floor of `row` at (q, t) (ToleranceScales): kUlpFloor · Σ_j |∂Φ_row/∂q_j| · |q_j|, from the
  /// Jacobian of the one constraint owning the row. Meant for the few rows a tolerance test finds above tol (a
  /// search over the blocks and one constraint's Jacobian per call). Pre-condition: 0 ≤ row < m, q has n entries.
  /// Thread-safe.
  double row_rounding_floor(Index row, const double* q, double t) const;

 private:
  friend class ModelBuilder;
  Model();
  Model(const Model& other);  // without_rows() only: the constraint blocks are shared, not copied; its own anchor
  /// The name of coordinate k, as index_of_ reads it.
  auto coordinate_name_of() const {
    return [this](Index k) -> const std::string& { return names_[static_cast<std::size_t>(k)]; };
  }
  /// The name of constraint k, as the builder's constraint_names_ reads it.
  auto constraint_name_of() const {
    return [this](Index k) -> const std::string& { return constraints_[static_cast<std::size_t>(k)].name; };
  }

  // Zero-fills csc_values unless no two entries share a slot; returns whether entries are stored (=) rather than
  // added (jacobian(), residual_and_jacobian()).
  bool prepare_jacobian_values(double* csc_values) const;
  // Workspaces and ScaledJacobianRows hold this anchor, not the model's address: the moves re-point it, the
  // destructor nulls it (null here once moved from).
  std::shared_ptr<detail::ModelAnchor> anchor_;
  friend class Workspace;
  friend class ScaledJacobianRows;
};

/// Builds a Model in code. Coordinates first (they are referenced by index), then constraints:
///
///   phiq::ModelBuilder b;
///   auto th = b.add_coordinate("theta2", 0.0), xa = b.add_coordinate("xA", 0.3), ...;
///   b.add("crank", phiq::PolarSpec{{S(xa), S(ya)}, {C(0), C(0)}, 0.3, S(th)});
///   b.add_driver("motor", th, phiq::MotionLaw::linear(0.0, 2.0));
///   phiq::Model model = std::move(b).build();
///
/// Invalid data (unknown coordinate index, non-positive length, NaN, duplicate names) throws phiq::Error.
class ModelBuilder {
 public:
  ModelBuilder();                         ///< an empty model
  ~ModelBuilder();                        ///< discards an unbuilt model
  ModelBuilder(ModelBuilder&&) noexcept;  ///< moves the model being built

  /// Adds coordinate `name` with its initial guess; returns its index in q. Throws phiq::Error for an empty or
  /// duplicate name or a non-finite value.
  Index add_coordinate(const std::string& name, double initial);
  /// Coordinates added so far.
  Index num_coordinates() const { return static_cast<Index>(model_.names_.size()); }
  /// Index of a coordinate by name, or -1.
  Index find_coordinate(const std::string& name) const;
  /// Name of coordinate j. Throws phiq::Error unless 0 ≤ j < num_coordinates().
  const std::string& coordinate_name(Index j) const {
    return model_.names_[detail::index_in(j, num_coordinates(), "coordinate")];
  }
  /// True when a constraint of that name has been added.
  bool has_constraint(const std::string& name) const {
    return constraint_names_.find(name, model_.constraint_name_of()) >= 0;
  }
  /// The kind (ConstraintInfo::kind) of the constraint of that name added so far, or empty.
  std::string_view constraint_kind(const std::string& name) const {
    const Index k = constraint_names_.find(name, model_.constraint_name_of());
    return k < 0 ? std::string_view() : std::string_view(model_.constraints_[static_cast<std::size_t>(k)].kind);
  }
  /// Makes room for that many more coordinates and constraints (an optimisation for large generated models, e.g.
  /// the members of a scene family; never required).
  void reserve(Index more_coordinates, Index more_constraints);
  /// Sets a coordinate's initial guess (rough placement for assembly).
  void set_initial(Index j, double value);

  /// Adds a constraint of any kind of kinds/registry.hpp; its rows follow those added before. Returns its index.
  /// A kind with kAddedCoordinates (PointOnCurveSpec: the curve parameter) gets those coordinates added after
  /// the model's others so far, named "NAME.<suffix>", with the kind's initial guess from the placement
  /// (`added_initial`); the spec's own slots for them are ignored and bound here (`added`).
  /// Throws phiq::Error "constraint 'NAME': ..." for a slot that is not a coordinate of the model or a constant
  /// that is not finite, a law without a function, or data its kind refuses ("distance: length must be positive").
  template <ConstraintKind Spec>
  Index add(const std::string& name, Spec spec);
  /// Records a planar rigid body in reference-point coordinates, for the Grübler–Kutzbach count (Model::grubler());
  /// adds no coordinate and no constraint. Returns its index among the bodies. Throws phiq::Error for an empty or
  /// duplicate body name, or a frame whose slots are not coordinates of the model.
  Index add_body(const std::string& name, const Frame2& frame);
  /// Records a spatial rigid body (position and Euler parameters) for the Grübler–Kutzbach count and adds its
  /// normalisation constraint (EulerParametersSpec) named `name.euler` when any Euler parameter is a coordinate.
  /// Returns its index among the bodies. Throws phiq::Error as the planar overload, and when the Euler parameters'
  /// values (initial guesses as they are now, and constants) are all 0: no orientation. Pre-condition: their
  /// initial guesses are set (add_coordinate, set_initial) before the body is added.
  Index add_body(const std::string& name, const Frame3& frame);
  /// Adds the unit-norm constraint of a natural unit vector (UnitVectorSpec), named `name.unit`. Returns the
  /// constraint's index.
  Index add_unit_vector(const std::string& name, const Point3& vector);
  /// Shorthand for a CoordinateDriverSpec.
  Index add_driver(const std::string& name, Index coordinate, MotionLaw law);

  /// Overrides the automatic tolerance scales (ToleranceScales: each length row relative to its own link) with
  /// one length scale for every length row and coordinate.
  void set_length_scale(double metres);
  /// Chooses the sparse LU (default KLU; see bench/README.md for why).
  void set_linear_solver(LinearSolverKind kind) { model_.lu_kind_ = kind; }
  /// Batch mode: if the built model has the same Jacobian pattern and linear solver as `other` (e.g. the same
  /// scene with other parameter values), it shares other's pattern and symbolic analysis (read-only, reference
  /// counted) instead of analysing again; otherwise it is analysed as usual. Model::symbolic() tells which.
  /// `other` must outlive build().
  void share_analysis_with(const Model& other) { share_analysis_with_ = &other; }

  /// Computes the pattern, units, scale and the symbolic analysis. The builder is consumed.
  Model build() &&;

 private:
  Index add_info(const std::string& name, const char* kind, int rows, bool depends_on_time);
  void check_slot(const Slot& s, const std::string& name) const;
  template <class Spec>
  TypedBlock<Spec>& block_for();
  /// @cond internal
  void count_joint(const JointCount& c);
  void check_body(const std::string& name, std::initializer_list<Slot> slots);
  void tolerance_scales(const CscPattern& pattern, const std::vector<double>& own);  // model_.scales_, in build()
  /// @endcond

  Model model_;
  std::unordered_map<std::type_index, std::size_t> block_of_type_;
  detail::NameIndex constraint_names_;  ///< duplicate check in O(1): models reach 10^6 constraints
  double length_scale_override_ = 0.0;
  const Model* share_analysis_with_ = nullptr;
  // The Grübler–Kutzbach count, gathered while adding: bodies per dimension, freedoms removed by joints per
  // dimension, and whether a constraint that is not a joint was added.
  Index bodies_[2] = {0, 0};   ///< planar, spatial
  Index removed_[2] = {0, 0};  ///< by planar joints, by spatial joints
  bool joints_of_dimension_[2] = {false, false};
  bool non_joint_ = false;
  detail::NameIndex body_names_;  ///< duplicate check in O(1) without a node per name: scenes reach 10^6 bodies
};

namespace detail {
/// A new, empty block of the registered kind ConstraintKinds::at<kind>. Every registered kind's TypedBlock is
/// compiled once, in engine/src/kinds/typed_blocks*.cpp, rather than again in each file that adds constraints (they
/// were a third of the scene readers' compile time).
std::shared_ptr<ConstraintBlock> new_registered_block(std::size_t kind);
}  // namespace detail

template <class Spec>
TypedBlock<Spec>& ModelBuilder::block_for() {
  // try_emplace: no node is allocated when the block exists (one lookup per added constraint)
  auto [it, inserted] = block_of_type_.try_emplace(std::type_index(typeid(Spec)), model_.blocks_.size());
  if (inserted) {
    constexpr std::size_t kind = ConstraintKinds::index_of<Spec>();
    if constexpr (kind < ConstraintKinds::size)
      model_.blocks_.push_back(detail::new_registered_block(kind));
    else
      model_.blocks_.push_back(std::make_shared<TypedBlock<Spec>>());  // a kind of the caller's own
  }
  return static_cast<TypedBlock<Spec>&>(*model_.blocks_[it->second]);
}

template <ConstraintKind Spec>
Index ModelBuilder::add(const std::string& name, Spec spec) {
  const std::string label =
      name.empty() ? std::string(Spec::kKind) + "#" + std::to_string(model_.constraints_.size()) : name;
  spec.for_each_slot([&](const Slot& s, Unit) { check_slot(s, label); });
  // (here, not at the first solve: a law without a function would otherwise read as the time domain [0, 0] and
  // throw from inside Φ, on a worker thread when the model is evaluated in parallel)
  if constexpr (requires { spec.law; })
    if (!detail::law_has_value(spec.law))
      throw Error("constraint '" + label + "': its motion law has no function (a default-constructed MotionLaw)");
  try {  // the kind's own checks name the kind; the constraint is named here, as check_slot names it
    spec.prepare(model_.initial_.data());
  } catch (const Error& e) {
    throw Error("constraint '" + label + "': " + e.what());
  }
  // A kind with coordinates of its own (a curve's parameter) has them added here, after its checks, as
  // "NAME.<suffix>" (nothing is added for a constraint refused), each with the kind's guess from the placement.
  if constexpr (requires { Spec::kAddedCoordinates; }) {
    if (has_constraint(label)) throw Error("duplicate constraint name '" + label + "'");
    for (int i = 0; i < static_cast<int>(std::size(Spec::kAddedCoordinates)); ++i) {
      const Index j = add_coordinate(label + "." + Spec::kAddedCoordinates[i], 0.0);
      spec.added(i) = Slot::coordinate(j);
      const double guess = spec.added_initial(i, model_.initial_.data());
      model_.initial_(j) = std::isfinite(guess) ? guess : 0.0;
    }
  }
  const bool td = spec.depends_on_time();
  const Index id = add_info(label, Spec::kKind, Spec::kRows, td);
  count_joint(spec.joint_count());
  const Index row0 = model_.constraints_[static_cast<std::size_t>(id)].first_row;
  if (row0 + Spec::kRows >= INT32_MAX) throw Error("the model has more equations than phiq handles (2^31)");
  block_for<Spec>().entries().push_back({std::move(spec), static_cast<EntryIndex>(row0), 0});
  return id;
}

}  // namespace phiq
