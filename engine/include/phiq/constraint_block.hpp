/// @file
/// Constraint blocks: all constraints of one kind, evaluated in one loop (one virtual call per block and operation,
/// not per constraint). The solver sees only ConstraintBlock.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "phiq/constraint_kinds.hpp"
#include "phiq/kinds/reaction_site.hpp"

namespace phiq {

/// Where a Jacobian entry goes in the CSC value array, and a constraint's first row and first entry: 32-bit, since
/// the value passes read them for every entry (a model has fewer than 2³¹ rows and entries: ModelBuilder::build()
/// checks).
using EntryIndex = std::int32_t;

/// The constraints of one kind, behind the one interface the Model and the solvers see. Constraint i of the block
/// (0 ≤ i < size()) owns the rows_per_constraint() consecutive global rows that start at first_row(i).
///
/// The evaluation functions (residual(), jacobian(), phi_t(), gamma()) take a range [begin, end) of the block's
/// constraints, 0 ≤ begin ≤ end ≤ size(), and write the rows of those constraints only, at their global row offsets,
/// into an output that spans all rows of the model (all Jacobian entries for jacobian()). `q` and `qd` span all
/// coordinates of the model. Constraints own disjoint rows, so disjoint ranges touch disjoint outputs.
///
/// Thread safety: the const functions are thread-safe (the specs are read-only; EquationSpec uses thread-local
/// scratch), so disjoint ranges may be evaluated by different threads into the same arrays. build_pattern() and
/// TypedBlock::entries() modify the block; they are used once, while the model is built.
class ConstraintBlock {
 public:
  virtual ~ConstraintBlock() = default;
  /// Name of the constraint kind of this block (the spec's kKind, e.g. "distance"); a static string.
  virtual const char* kind() const = 0;
  /// Number of constraints in the block.
  virtual std::size_t size() const = 0;
  /// Number of rows each constraint owns (the spec's kRows).
  virtual int rows_per_constraint() const = 0;
  /// Global index of the first row of constraint `i` (0 ≤ i < size()); its rows are first_row(i) …
  /// first_row(i) + rows_per_constraint() − 1.
  virtual Index first_row(std::size_t i) const = 0;

  /// Writes Φ(q, t) of constraints [begin, end) into `phi` at their global row offsets (DistanceSpec::residual()).
  /// `phi` has one entry per row of the model; other rows are left untouched. Thread-safe.
  virtual void residual(std::size_t begin, std::size_t end, const double* q, double t, double* phi) const = 0;
  /// Accumulates (adds) the Φq values of constraints [begin, end) into `csc_values`, the value array of the model's
  /// CSC Jacobian pattern: the k-th entry of the model's triplet list (as appended by build_pattern()) is added at
  /// `csc_values[slot_of_entry[k]]` (entries sharing a (row, column) share a slot). The caller zeroes
  /// `csc_values` first; entries of other constraints are left untouched. With `overwrite`, each entry is stored
  /// (=) instead of added: the model asks for it when no two entries of the whole model share a slot, which spares
  /// it the zero fill (a pass over all non-zeros per Newton iteration). Requires build_pattern() to have run.
  /// Thread-safe.
  virtual void jacobian(std::size_t begin, std::size_t end, const double* q, double t, const EntryIndex* slot_of_entry,
                        double* csc_values, bool overwrite = false) const = 0;
  /// residual() and jacobian() at the same (q, t) in one pass over the constraints: each constraint's data is read
  /// once (the Newton loop needs both at every accepted iterate; on large models each pass streams the whole
  /// constraint list from memory). Same contracts as the two calls. Thread-safe.
  virtual void residual_and_jacobian(std::size_t begin, std::size_t end, const double* q, double t, double* phi,
                                     const EntryIndex* slot_of_entry, double* csc_values, bool overwrite) const = 0;
  /// Writes Φt = ∂Φ/∂t of the time-dependent constraints in [begin, end) into `out` at their global row offsets;
  /// the rows of the others are left untouched (their Φt is zero: the caller zero-fills `out`). Thread-safe.
  virtual void phi_t(std::size_t begin, std::size_t end, const double* q, double t, double* out) const = 0;
  /// Writes γ = −(Φq q̇)q q̇ − 2 Φqt q̇ − Φtt of constraints [begin, end) into `out` at their global row offsets,
  /// the right-hand side of Φq q̈ = γ (DistanceSpec::gamma()). `qd` is q̇, indexed like `q`. Thread-safe.
  virtual void gamma(std::size_t begin, std::size_t end, const double* q, const double* qd, double t,
                     double* out) const = 0;
  /// Adds Φq v of constraints [begin, end) at (q, t) to `out` at their global row offsets (other rows untouched):
  /// each Jacobian entry (DistanceSpec::jacobian()) on a coordinate j adds its value × v[j] to its row. `v` spans
  /// all coordinates, `out` all rows. A product over a few constraints without the model's CSC values (the
  /// sensitivities' derivatives along a parameter that reaches a few constraints: sensitivity.hpp). Thread-safe.
  virtual void add_jacobian_product(std::size_t begin, std::size_t end, const double* q, double t, const double* v,
                                    double* out) const = 0;
  /// Whether constraint `i` is the same constraint as constraint `i` of `other`: a block of the same kind with more
  /// than `i` constraints (else false) whose spec there is equal to this one (the kind's operator==, datum by
  /// datum: laws, curves and expressions by what they hold, not by address). What ParameterReach compares to find
  /// the constraints a parameter changes. Thread-safe.
  virtual bool same_data(std::size_t i, const ConstraintBlock& other) const = 0;
  /// Whether constraint `i` (0 ≤ i < size()) depends explicitly on time (DistanceSpec::depends_on_time()).
  virtual bool depends_on_time(std::size_t i) const = 0;
  /// Σ_j |∂Φ_r/∂q_j| · |q_j| over the coordinates that local row `row` (0 ≤ row < rows_per_constraint()) of
  /// constraint `i` reads, at (q, t): how far the row moves when every coordinate moves by the same relative amount,
  /// so that ε times it is the rounding of the row's value at q (ToleranceScales, Model::row_rounding_floor()).
  /// Thread-safe.
  virtual double coordinate_sensitivity(std::size_t i, int row, const double* q, double t) const = 0;

  /// Appends the (row, column) of every Jacobian entry of every constraint that falls on a coordinate to `rows` and
  /// `cols` (the model's triplet list, in evaluation order), and records where each constraint's entries start, so
  /// that jacobian() finds their slots. Used once, while the model is built, before any jacobian(); not
  /// thread-safe (it modifies the block).
  virtual void build_pattern(std::vector<Index>& rows, std::vector<Index>& cols) = 0;
  /// Marks the unit of every coordinate the constraints read (DistanceSpec::for_each_slot()): a coordinate still
  /// Unit::kNone in `units` takes the unit a constraint gives it; one given a unit other than the one it has falls
  /// back to Unit::kNone (compared with the plain tolerance). Slots read with Unit::kNone change nothing. `units`
  /// has one entry per coordinate. Used once, while the model is built.
  virtual void infer_coordinate_units(std::vector<Unit>& units) const = 0;
  /// Writes the unit of every row of the block's constraints into `units` (one entry per row of the model, indexed
  /// by global row), given the units of the coordinates (DistanceSpec::row_unit()). Used once, while the model is
  /// built.
  virtual void row_units(const std::vector<Unit>& coordinate_units, std::vector<Unit>& units) const = 0;
  /// Writes each constraint's own characteristic length (DistanceSpec::characteristic_length(): link lengths,
  /// attachment arms; 0 if it carries none) into every row it owns: `lengths` has one entry per row of the model,
  /// indexed by global row. Used once, while the model is built, for the rows' tolerance scales (ToleranceScales)
  /// and, their largest, the model's length scale (Model::length_scale()).
  virtual void row_lengths(std::vector<double>& lengths) const = 0;
  /// The first constraint of the block whose equations are not defined at q (a curve parameter past the end of
  /// an open curve: PointOnCurveSpec::outside_domain()), and what happened; {size(), ""} when there is none.
  /// Kinds without a domain are always inside. Thread-safe.
  virtual std::pair<std::size_t, std::string> outside_domain(const double* /*q*/) const { return {size(), ""}; }
  /// Adds Φq,iᵀ y to `out` (one entry per coordinate) for constraint i at (q, t): Σ_r y[row0 + r] ∂Φ_r/∂q, y
  /// indexed by the model's rows. What a joint's reaction is made of (joint_reactions.hpp). Thread-safe.
  virtual void add_transposed_product(std::size_t i, const double* q, double t, const double* y, double* out) const = 0;
  /// Whether the kind states where its reaction acts (ReactionSite, kinds/reaction_site.hpp).
  virtual bool has_reaction_site() const { return false; }
  /// How many values the kind's reaction has, its kReactionWidth: 3 (Fx, Fy, Mz) for a planar joint, 6 for a
  /// spatial one; 0 when it states no ReactionSite. A fact of the kind, the same for every constraint of the block.
  virtual int reaction_width() const { return 0; }
  /// Whether constraint i has a reaction: its kind states a ReactionSite and, where the kind tells its constraints
  /// apart (`states_reaction()`: a spatial distance between bodies, not one between natural points), it does.
  virtual bool states_reaction(std::size_t /*i*/) const { return false; }
  /// Constraint i's ReactionSite at q, when has_reaction_site(); else false. Thread-safe.
  virtual bool reaction_site(std::size_t /*i*/, const double* /*q*/, ReactionSite& /*out*/) const { return false; }
  /// Constraint i's GearMesh, when its kind is a gear pair or a rack and pinion (GearSpec::gear_mesh()); else false.
  virtual bool gear_mesh(std::size_t /*i*/, GearMesh& /*out*/) const { return false; }
  /// Constraint i's SpatialMesh, when its kind is a spatial gear pair (SpatialGearSpec::spatial_mesh()); else false.
  virtual bool spatial_mesh(std::size_t /*i*/, SpatialMesh& /*out*/) const { return false; }
  /// The coordinates constraint i adds (a kind with kAddedCoordinates: a curve's parameter) and the length each is
  /// measured in proportion to (PointOnCurveSpec::added_scale()): at most `capacity` of them into `coordinate` and
  /// `scale`, returning how many it adds (0 for the kinds that add none). For the sensitivities' co-motion
  /// (ParameterReach::comotion). Thread-safe.
  virtual int added_coordinates(std::size_t /*i*/, Index* /*coordinate*/, double* /*scale*/, int /*capacity*/) const {
    return 0;
  }
  /// A new block of the same kind without constraints, to append_copy() to: the constraints a design parameter
  /// reaches, kept apart from the models along it (OutputSensitivity::reached).
  virtual std::unique_ptr<ConstraintBlock> empty_copy() const = 0;
  /// Appends a copy of constraint `i` of `from` (a block of the same kind: else phiq::Error), its rows included. Such
  /// a block evaluates Φ, Φt, γ and Φq v (add_jacobian_product()); it has no Jacobian pattern. Not thread-safe.
  virtual void append_copy(const ConstraintBlock& from, std::size_t i) = 0;
  /// The rates of the data of constraints [begin, end) along a design parameter, from their copies in the four
  /// models at p − 2h, p − h, p + h, p + 2h: `along[k]` holds them as constraints 0 … end − begin − 1 (the
  /// constraints a parameter reaches, ReachedConstraints). A block of this kind, one constraint for each, whose data
  /// are the data's rates (DistanceSpec::data_derivative()), for data_derivative(); null when the kind does not
  /// differentiate its data, or when data it does not list move (their derivatives are then differenced).
  virtual std::unique_ptr<ConstraintBlock> data_rates(std::size_t /*begin*/, std::size_t /*end*/,
                                                      const std::array<const ConstraintBlock*, 4>& /*along*/,
                                                      double /*h*/) const {
    return nullptr;
  }
  /// A block of this kind holding one copy of constraint `i` (its rows included) with each datum moved by `s` times
  /// its rate, `rates` being what data_rates() made, constraint `j` of it: the constraint along the line
  /// p + s of the data's rates, whose derivative at s = 0 is the constraint's along p (the joints a bearing reads,
  /// detail::FrictionLosses). Null when the kind does not differentiate its data or lists a datum that cannot be
  /// moved so (a motion law, an expression, a curve: detail::datum_moved()).
  virtual std::unique_ptr<ConstraintBlock> data_moved(std::size_t /*i*/, const ConstraintBlock& /*rates*/,
                                                      std::size_t /*j*/, double /*s*/) const {
    return nullptr;
  }
  /// Writes the derivative along a design parameter, at fixed (q, q̇, q̈, t), of Φ (`order` 0), Φq q̇ + Φt (1) or
  /// Φq q̈ − γ (2) of constraints [begin, end) into `out` at their global rows, `rates` being what data_rates() made
  /// for that range: exact, one evaluation (DistanceSpec::data_derivative()). `qd` is read for order ≥ 1, `qdd`
  /// for order 2. Thread-safe.
  virtual void data_derivative(std::size_t /*begin*/, std::size_t /*end*/, const ConstraintBlock& /*rates*/,
                               int /*order*/, const double* /*q*/, const double* /*qd*/, const double* /*qdd*/,
                               double /*t*/, double* /*out*/) const {}
};

namespace detail {
/// Pattern mode: records the column of every entry that falls on a coordinate.
struct PatternSink {
  Index row0;
  std::vector<Index>* rows;
  std::vector<Index>* cols;
  void operator()(int row, const Slot& s, double) {
    if (s.is_coordinate()) rows->push_back(row0 + row), cols->push_back(s.coord());
  }
};
/// Value mode: same entries, same order, values accumulated into their CSC slots (or stored, with kOverwrite:
/// only where no two entries share a slot).
template <bool kOverwrite>
struct ValueSink {
  const EntryIndex* slot;
  double* values;
  void operator()(int, const Slot& s, double v) {
    if (!s.is_coordinate()) return;
    if constexpr (kOverwrite)
      values[*slot++] = v;
    else
      values[*slot++] += v;
  }
};
}  // namespace detail

/// The largest coordinate index that `spec` reads (over its for_each_slot()), or −1 if it reads only constants.
/// The arrays q and qd passed to the spec's functions need at least max_coordinate(spec) + 1 entries. Thread-safe.
/// @tparam Spec a constraint kind of constraint_kinds.hpp (DistanceSpec, PinSpec, ...).
template <class Spec>
Index max_coordinate(const Spec& spec) {
  Index m = -1;
  spec.for_each_slot([&](const Slot& s, Unit) { m = std::max(m, s.coord()); });
  return m;
}

/// The ConstraintBlock of one constraint kind `Spec`: it stores the constraints' specs contiguously and evaluates
/// them in plain loops over the range, so the per-constraint calls are resolved at compile time and inlined. The
/// ModelBuilder keeps one block per kind. The overrides behave as documented on ConstraintBlock.
/// @tparam Spec a constraint kind of constraint_kinds.hpp (DistanceSpec, PinSpec, ...), with the interface
/// documented on DistanceSpec.
template <class Spec>
class TypedBlock final : public ConstraintBlock {
 public:
  /// One constraint of the block: its data and where its rows and Jacobian entries are in the model.
  struct Entry {
    Spec spec;        ///< the constraint's data and equations
    EntryIndex row0;  ///< first global row (the constraint owns rows row0 … row0 + Spec::kRows − 1)
    EntryIndex nz0;   ///< index of its first Jacobian entry in the model's triplet list, set by build_pattern()
  };

  const char* kind() const override { return Spec::kKind; }
  std::size_t size() const override { return entries_.size(); }
  int rows_per_constraint() const override { return Spec::kRows; }
  Index first_row(std::size_t i) const override { return entries_[i].row0; }
  /// The spec of constraint `i` (0 ≤ i < size()). Thread-safe.
  const Spec& spec(std::size_t i) const { return entries_[i].spec; }
  /// The constraints, for ModelBuilder to append to while the model is built (before build_pattern()). Not
  /// thread-safe.
  std::vector<Entry>& entries() { return entries_; }

  void residual(std::size_t begin, std::size_t end, const double* q, double t, double* phi) const override {
    for (std::size_t i = begin; i < end; ++i) entries_[i].spec.residual(q, t, phi + entries_[i].row0);
  }
  void jacobian(std::size_t begin, std::size_t end, const double* q, double t, const EntryIndex* slot_of_entry,
                double* csc_values, bool overwrite) const override {
    if (overwrite)
      evaluate<false, true>(begin, end, q, t, nullptr, slot_of_entry, csc_values);
    else
      evaluate<false, false>(begin, end, q, t, nullptr, slot_of_entry, csc_values);
  }
  void residual_and_jacobian(std::size_t begin, std::size_t end, const double* q, double t, double* phi,
                             const EntryIndex* slot_of_entry, double* csc_values, bool overwrite) const override {
    if (overwrite)
      evaluate<true, true>(begin, end, q, t, phi, slot_of_entry, csc_values);
    else
      evaluate<true, false>(begin, end, q, t, phi, slot_of_entry, csc_values);
  }
  void phi_t(std::size_t begin, std::size_t end, const double* q, double t, double* out) const override {
    for (std::size_t i = begin; i < end; ++i)
      if (entries_[i].spec.depends_on_time()) entries_[i].spec.phi_t(q, t, out + entries_[i].row0);
  }
  void gamma(std::size_t begin, std::size_t end, const double* q, const double* qd, double t,
             double* out) const override {
    for (std::size_t i = begin; i < end; ++i) entries_[i].spec.gamma(q, qd, t, out + entries_[i].row0);
  }
  void add_jacobian_product(std::size_t begin, std::size_t end, const double* q, double t, const double* v,
                            double* out) const override {
    for (std::size_t i = begin; i < end; ++i) {
      double* row = out + entries_[i].row0;
      auto sink = [&](int r, const Slot& s, double value) {
        if (s.is_coordinate()) row[r] += value * v[s.coord()];
      };
      entries_[i].spec.jacobian(q, t, sink);
    }
  }
  bool same_data(std::size_t i, const ConstraintBlock& other) const override {
    const auto* o = dynamic_cast<const TypedBlock*>(&other);
    return o && i < o->entries_.size() && i < entries_.size() && entries_[i].spec == o->entries_[i].spec;
  }
  bool depends_on_time(std::size_t i) const override { return entries_[i].spec.depends_on_time(); }
  double coordinate_sensitivity(std::size_t i, int row, const double* q, double t) const override {
    double sum = 0.0;
    auto sink = [&](int r, const Slot& s, double v) {
      if (r == row && s.is_coordinate()) sum += std::fabs(v) * std::fabs(q[s.coord()]);
    };
    entries_[i].spec.jacobian(q, t, sink);
    return sum;
  }

  void build_pattern(std::vector<Index>& rows, std::vector<Index>& cols) override {
    // Values are ignored in pattern mode; evaluate at a harmless point (entries never depend on values). One
    // array for the whole block: one per constraint made building a model of n coordinates O(n²).
    Index top = -1;
    for (const Entry& e : entries_) top = std::max(top, max_coordinate(e.spec));
    const std::vector<double> zeros(static_cast<std::size_t>(top + 1), 0.0);
    for (Entry& e : entries_) {
      e.nz0 = static_cast<EntryIndex>(rows.size());  // < 2³¹: ModelBuilder::build() checks the total
      detail::PatternSink sink{e.row0, &rows, &cols};
      e.spec.jacobian(zeros.data(), 0.0, sink);
    }
  }
  void infer_coordinate_units(std::vector<Unit>& units) const override {
    for (const Entry& e : entries_)
      e.spec.for_each_slot([&](const Slot& s, Unit u) {
        if (!s.is_coordinate() || u == Unit::kNone) return;
        Unit& cu = units[static_cast<std::size_t>(s.coord())];
        if (cu == Unit::kNone)
          cu = u;
        else if (cu != u)
          cu = Unit::kNone;  // used as both: fall back to the plain tolerance
      });
  }
  void row_units(const std::vector<Unit>& coordinate_units, std::vector<Unit>& units) const override {
    for (const Entry& e : entries_)
      for (int r = 0; r < Spec::kRows; ++r)
        units[static_cast<std::size_t>(e.row0 + r)] = e.spec.row_unit(r, coordinate_units);
  }
  void add_transposed_product(std::size_t i, const double* q, double t, const double* y, double* out) const override {
    const double* yi = y + entries_[i].row0;
    auto sink = [&](int r, const Slot& s, double value) {
      if (s.is_coordinate()) out[s.coord()] += value * yi[r];
    };
    entries_[i].spec.jacobian(q, t, sink);
  }
  bool has_reaction_site() const override {
    return requires(const Spec& k, const double* at) { k.reaction_site(at); };
  }
  int reaction_width() const override {
    if constexpr (requires(const Spec& k, const double* at) { k.reaction_site(at); }) {
      static_assert(Spec::kReactionWidth == 3 || Spec::kReactionWidth == 6,
                    "a kind with a reaction_site() states kReactionWidth: 3 in the plane, 6 in space");
      return Spec::kReactionWidth;
    }
    return 0;
  }
  bool reaction_site(std::size_t i, const double* q, ReactionSite& out) const override {
    if constexpr (requires(const Spec& k, const double* at) { k.reaction_site(at); }) {
      out = entries_[i].spec.reaction_site(q);
      return true;
    }
    return false;
  }
  bool states_reaction(std::size_t i) const override {
    if constexpr (requires(const Spec& k) { k.states_reaction(); })
      return entries_[i].spec.states_reaction();
    else
      return has_reaction_site();
  }
  bool gear_mesh(std::size_t i, GearMesh& out) const override {
    if constexpr (requires(const Spec& k) { k.gear_mesh(); }) {
      out = entries_[i].spec.gear_mesh();
      return true;
    }
    return false;
  }
  bool spatial_mesh(std::size_t i, SpatialMesh& out) const override {
    if constexpr (requires(const Spec& k) { k.spatial_mesh(); }) {
      out = entries_[i].spec.spatial_mesh();
      return true;
    }
    return false;
  }
  std::pair<std::size_t, std::string> outside_domain(const double* q) const override {
    if constexpr (requires(const Spec& k, const double* at) { k.outside_domain(at); }) {
      for (std::size_t i = 0; i < entries_.size(); ++i)
        if (std::string why = entries_[i].spec.outside_domain(q); !why.empty()) return {i, std::move(why)};
    }
    return {entries_.size(), ""};
  }
  std::unique_ptr<ConstraintBlock> empty_copy() const override { return std::make_unique<TypedBlock>(); }
  void append_copy(const ConstraintBlock& from, std::size_t i) override {
    const auto* o = dynamic_cast<const TypedBlock*>(&from);
    if (!o || i >= o->entries_.size()) throw Error("append_copy: not a constraint of a block of this kind");
    entries_.push_back(o->entries_[i]);
  }
  int added_coordinates(std::size_t i, Index* coordinate, double* scale, int capacity) const override {
    if constexpr (requires { Spec::kAddedCoordinates; }) {
      constexpr int kAdded = static_cast<int>(std::size(Spec::kAddedCoordinates));
      static_assert(
          requires(const Spec& k) { k.added_scale(0); },
          "a kind with added coordinates states what each is measured in proportion to (added_scale)");
      const Spec& spec = entries_[i].spec;
      const int count = std::min(kAdded, capacity);
      for (int k = 0; k < count; ++k) {
        const Slot& slot = spec.added(k);
        coordinate[k] = slot.is_coordinate() ? slot.coord() : -1;
        scale[k] = spec.added_scale(k);
      }
      return count;
    } else {
      return 0;
    }
  }
  std::unique_ptr<ConstraintBlock> data_rates(std::size_t begin, std::size_t end,
                                              const std::array<const ConstraintBlock*, 4>& along,
                                              double h) const override {
    if constexpr (DataDifferentiable<Spec>) {
      std::array<const TypedBlock*, 4> a{};
      for (std::size_t k = 0; k < 4; ++k) {
        a[k] = dynamic_cast<const TypedBlock*>(along[k]);
        if (!a[k] || a[k]->entries_.size() != end - begin) return nullptr;
      }
      auto rates = std::make_unique<TypedBlock>();
      rates->entries_.reserve(end - begin);
      for (std::size_t i = begin; i < end; ++i) {
        Entry e = entries_[i];  // its rows: the swept model's
        const std::size_t j = i - begin;
        if (!detail::spec_data_rate(
                entries_[i].spec,
                {&a[0]->entries_[j].spec, &a[1]->entries_[j].spec, &a[2]->entries_[j].spec, &a[3]->entries_[j].spec}, h,
                e.spec))
          return nullptr;
        rates->entries_.push_back(e);
      }
      return rates;
    } else {
      return nullptr;
    }
  }
  std::unique_ptr<ConstraintBlock> data_moved(std::size_t i, const ConstraintBlock& rates, std::size_t j,
                                              double s) const override {
    if constexpr (DataDifferentiable<Spec>) {
      const auto* r = dynamic_cast<const TypedBlock*>(&rates);
      if (!r || i >= entries_.size() || j >= r->entries_.size()) return nullptr;
      auto moved = std::make_unique<TypedBlock>();
      moved->entries_.push_back(entries_[i]);
      if (!detail::spec_data_moved(r->entries_[j].spec, s, moved->entries_.back().spec)) return nullptr;
      return moved;
    } else {
      return nullptr;
    }
  }
  void data_derivative(std::size_t begin, std::size_t end, const ConstraintBlock& rates, int order, const double* q,
                       const double* qd, const double* qdd, double t, double* out) const override {
    if constexpr (DataDifferentiable<Spec>) {
      const auto& r = static_cast<const TypedBlock&>(rates);  // data_rates() made it, of this kind
      for (std::size_t i = begin; i < end; ++i)
        entries_[i].spec.data_derivative(r.entries_[i - begin].spec, order, q, qd, qdd, t, out + entries_[i].row0);
    }
  }
  void row_lengths(std::vector<double>& lengths) const override {
    for (const Entry& e : entries_)
      for (int r = 0; r < Spec::kRows; ++r)
        lengths[static_cast<std::size_t>(e.row0 + r)] = e.spec.characteristic_length();
  }

 private:
  // Φq of constraints [begin, end) into their CSC slots (stored or added), and with kResidual their Φ too.
  template <bool kResidual, bool kOverwrite>
  void evaluate(std::size_t begin, std::size_t end, const double* q, double t, double* phi,
                const EntryIndex* slot_of_entry, double* csc_values) const {
    for (std::size_t i = begin; i < end; ++i) {
      const Entry& e = entries_[i];
      detail::ValueSink<kOverwrite> sink{slot_of_entry + e.nz0, csc_values};
      if constexpr (kResidual && requires { e.spec.residual_and_jacobian(q, t, phi, sink); }) {
        e.spec.residual_and_jacobian(q, t, phi + e.row0, sink);  // the kind's own fused evaluation
      } else {
        if constexpr (kResidual) e.spec.residual(q, t, phi + e.row0);
        e.spec.jacobian(q, t, sink);
      }
    }
  }

  std::vector<Entry> entries_;
};

}  // namespace phiq
