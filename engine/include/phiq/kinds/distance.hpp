/// @file
/// The distance between two points (natural coordinates): a bar. One constraint kind: its equation, derivatives,
/// validation, joint count, sketch and scene form (the contract is documented on DistanceSpec; kinds/registry.hpp lists
/// every kind).
#pragma once

#include <cmath>
#include <tuple>

#include "phiq/kinds/kind_support.hpp"

namespace phiq {

///   Φ = (|b − a|² − L²) / (2L)
/// Dividing by 2L makes the row a length (≈ |b − a| − L near the solution) for any L, so that one tolerance serves
/// links of 1 mm and of 1 km alike. L > 0.
///
/// Scene type `distance`. Time-independent; its row is a length; its characteristic length is L; it reads the four
/// slots of a and b, all lengths.
///
/// Its member functions are the interface that every constraint kind supplies (TypedBlock calls them, in one loop
/// per kind); the other kinds copy their documentation from here.
struct DistanceSpec {
  /// Value equality, datum by datum (slots bit for bit, numbers by value, laws and curves by what they hold):
  /// whether two constraints are the same constraint. ParameterReach compares each constraint of the swept
  /// model with its counterpart in the models along a parameter, to evaluate only those the parameter changes.
  /// Every kind has it (kinds/registry.hpp); a defaulted one serves wherever the data are plain values.
  bool operator==(const DistanceSpec&) const = default;
  /// Number of rows of Φ a constraint of this kind owns: its residual, Φt and γ have kRows values and its Jacobian
  /// entries have rows 0 … kRows − 1 (local rows; the model places them at the constraint's first global row).
  static constexpr int kRows = 1;
  /// Name of the kind, as reported in diagnostics (ConstraintInfo::kind, ConstraintBlock::kind()) and used in the
  /// default name "kind#k" of an unnamed constraint. A static string.
  static constexpr const char* kKind = "distance";
  /// @var a
  /// @brief A, first end point (m).
  Point2 a, b;          ///< B, second end point (m)
  double length = 1.0;  ///< L, the distance |B − A|, metres, finite and > 0 (checked when the constraint is added)

  /// Whether Φ depends explicitly on time t. When false, Φt = 0 and Φtt = 0: phi_t() is never called and the model
  /// leaves the constraint's Φt rows at zero. The answer is fixed for the life of the spec.
  bool depends_on_time() const { return false; }
  /// The unit of residual row `row` (0 ≤ row < kRows): what the row measures, which chooses its tolerance (a length
  /// is compared with tol · its tolerance scale (ToleranceScales), an angle with tol, Unit::kNone with tol).
  /// `coordinate_units` holds the unit inferred for every coordinate of the model (from the for_each_slot() of all
  /// constraints); kinds whose rows have a fixed unit ignore it. Called once, while the model is built.
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  /// The largest length this constraint carries as data (m), 0 if it carries none. It is the tolerance scale of
  /// the constraint's own length rows (each row is held relative to its own link, ToleranceScales); the model's
  /// length scale is the largest of these over all constraints. Called once, while the model is built.
  double characteristic_length() const { return length; }
  /// Calls `f(slot, unit)` for every scalar Slot this constraint reads, coordinates and constants alike, with the
  /// unit that the slot measures for this kind (Unit::kNone where the kind does not tell). The same slot may be
  /// reported more than once. Used to validate the constraint when it is added (coordinate indices in range,
  /// constants finite), to infer the units of the coordinates, and to find the largest coordinate it reads
  /// (max_coordinate()).
  /// @tparam F callable as `f(const Slot&, Unit)`.
  /// @par Thread safety
  /// Thread-safe if `f` is: const, no shared state.
  template <class F>
  void for_each_slot(F&& f) const {
    f(a.x, Unit::kLength), f(a.y, Unit::kLength), f(b.x, Unit::kLength), f(b.y, Unit::kLength);
  }
  /// Evaluates the residual Φ(q, t) of this constraint: writes its kRows values at `phi[0]` … `phi[kRows − 1]`,
  /// row r in the unit row_unit(r) names. Zero where the constraint holds.
  /// @par Arguments
  /// - `q`: the generalized coordinates, read through the spec's slots (constant slots ignore it)
  /// - `t`: time (s); read only by kinds whose depends_on_time() is true
  /// - `phi`: output, this constraint's rows (the block passes the model's residual at the first global row)
  ///
  /// @pre `q` has at least max_coordinate(spec) + 1 entries (every coordinate the spec reads); `phi` has room for
  /// kRows values.
  /// @par Thread safety
  /// Thread-safe: const, and no shared state except EquationSpec's thread-local scratch, so one spec may be
  /// evaluated by several threads at once.
  void residual(const double* q, double, double* phi) const {
    kin::V2 d = kin::pos(b, q) - kin::pos(a, q);
    phi[0] = (kin::dot(d, d) - length * length) / (2.0 * length);
  }
  /// Emits the entries of Φq, the Jacobian of this constraint's rows with respect to the coordinates, at (q, t):
  /// calls `s(row, slot, value)` once per entry, with `row` the local row (0 ≤ row < kRows), `slot` the Slot the
  /// derivative is taken with respect to and `value` = ∂Φ_row/∂slot. Entries on constant slots are emitted too and
  /// skipped by the sink (a constant is no unknown); entries that repeat a (row, slot) pair add up.
  ///
  /// The calls come in a fixed order, and the set of entries depends only on the spec's data and on which of its
  /// slots are constants — never on the values of q or t — so that the pattern pass (ConstraintBlock::build_pattern(),
  /// once, at q = 0) and every later value pass (ConstraintBlock::jacobian()) see the same sequence of entries.
  /// @par Arguments
  /// - `q`: the generalized coordinates
  /// - `t`: time (s); read only by kinds whose depends_on_time() is true
  /// - `s`: the sink, called as `s(int row, const Slot& slot, double value)`
  ///
  /// @tparam Sink callable as `s(int, const Slot&, double)`.
  /// @pre `q` has at least max_coordinate(spec) + 1 entries (every coordinate the spec reads).
  /// @par Thread safety
  /// Thread-safe if the sink is: const, and no shared state except EquationSpec's thread-local scratch.
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    kin::V2 d = (1.0 / length) * (kin::pos(b, q) - kin::pos(a, q));
    s(0, a.x, -d.x), s(0, a.y, -d.y), s(0, b.x, d.x), s(0, b.y, d.y);
  }
  /// residual() and jacobian() in one go, with the same operations (the same values to the last bit): the
  /// difference of the end points is read from q once. Optional for a kind: ConstraintBlock's fused pass calls it
  /// when a kind has it (the distance is most rows of the large generated models), and the two functions otherwise.
  template <class Sink>
  void residual_and_jacobian(const double* q, double, double* phi, Sink& s) const {
    const kin::V2 d = kin::pos(b, q) - kin::pos(a, q);
    phi[0] = (kin::dot(d, d) - length * length) / (2.0 * length);
    const kin::V2 u = (1.0 / length) * d;
    s(0, a.x, -u.x), s(0, a.y, -u.y), s(0, b.x, u.x), s(0, b.y, u.y);
  }
  /// Writes Φt = ∂Φ/∂t, the explicit time derivative of the residual at (q, t): kRows values at `out`, in the
  /// row's unit per second. Only called when depends_on_time() is true (the time-independent kinds write zeros).
  /// @par Arguments
  /// - `q`: the generalized coordinates
  /// - `t`: time (s)
  /// - `out`: output, this constraint's rows
  ///
  /// @pre `q` has at least max_coordinate(spec) + 1 entries (every coordinate the spec reads); `out` has room for
  /// kRows values.
  /// @par Thread safety
  /// Thread-safe: const, and no shared state except EquationSpec's thread-local scratch.
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  /// Writes γ, the right-hand side of the acceleration equations Φq q̈ = γ of this constraint:
  ///
  ///     γ = −(Φq q̇)q q̇ − 2 Φqt q̇ − Φtt
  ///
  /// that is, minus the part of Φ̈ that does not contain q̈: kRows values at `out`, in the row's unit per second².
  /// @par Arguments
  /// - `q`: the generalized coordinates
  /// - `qd`: the generalized velocities q̇, indexed like q (constant slots have zero velocity)
  /// - `t`: time (s); read only by kinds whose depends_on_time() is true
  /// - `out`: output, this constraint's rows
  ///
  /// @pre `q` and `qd` have at least max_coordinate(spec) + 1 entries; `out` has room for kRows values.
  /// @par Thread safety
  /// Thread-safe: const, and no shared state except EquationSpec's thread-local scratch.
  void gamma(const double*, const double* qd, double, double* out) const {
    kin::V2 dd = kin::vel(b, qd) - kin::vel(a, qd);
    out[0] = -kin::dot(dd, dd) / length;
  }

  /// The data a design parameter may move, for data_derivative(): member pointers to numbers, Slots and Point2s
  /// (a coordinate slot is no datum: its rate is 0). Optional, with data_derivative(): a kind without them has its
  /// derivatives along a parameter differenced from the four models along it (sensitivity.hpp).
  static constexpr auto data_members() { return std::tuple{&DistanceSpec::a, &DistanceSpec::b, &DistanceSpec::length}; }
  /// The derivative of the constraint's equations along its data at fixed (q, q̇, q̈, t), `rate` holding each
  /// datum's rate along the parameter (data_members(): numbers their rate, constant slots a constant holding
  /// theirs, coordinate slots 0): ∂Φ/∂p (`order` 0), ∂(Φq q̇ + Φt)/∂p (1), ∂(Φq q̈ − γ)/∂p (2), kRows values at
  /// `out`. What the sensitivities to a parameter read where it reaches the constraint (sensitivity.hpp): exact,
  /// where the differences of four models are exact only up to 2(h/L)⁴ for a length. With d = b − a, ḋ its
  /// data's rate, v, w the velocities and accelerations of d, and L̇:
  ///
  ///   ∂Φ/∂p = d·ḋ / L − L̇ (|d|² + L²) / (2L²),   ∂(Φq q̇)/∂p = ḋ·v / L − L̇ d·v / L²,
  ///   ∂(Φq q̈ − γ)/∂p = ḋ·w / L − L̇ (d·w + |v|²) / L².
  /// @pre `qd` (order ≥ 1) and `qdd` (order 2) as q.
  void data_derivative(const DistanceSpec& rate, int order, const double* q, const double* qd, const double* qdd,
                       double, double* out) const {
    const kin::V2 d = kin::pos(b, q) - kin::pos(a, q), dd = kin::pos(rate.b, q) - kin::pos(rate.a, q);
    const double L = length, Ld = rate.length;
    if (order == 0) {
      out[0] = kin::dot(d, dd) / L - Ld * (kin::dot(d, d) + L * L) / (2.0 * L * L);
      return;
    }
    const kin::V2 v = kin::vel(b, qd) - kin::vel(a, qd);
    if (order == 1) {
      out[0] = kin::dot(dd, v) / L - Ld * kin::dot(d, v) / (L * L);
      return;
    }
    const kin::V2 w = kin::vel(b, qdd) - kin::vel(a, qdd);
    out[0] = kin::dot(dd, w) / L - Ld * (kin::dot(d, w) + kin::dot(v, v)) / (L * L);
  }

  /// What the constraint counts for in the Grübler–Kutzbach formula (Model::grubler()). Called once, when the
  /// constraint is added. A distance between natural points is no joint between bodies: the count is undefined.
  JointCount joint_count() const { return JointCount::other(); }
  /// Checks the constraint's data and derives what it needs from the placement `q0` (the initial guesses of every
  /// coordinate): reference scales of rows, normalised axes. Called once by ModelBuilder::add(), which names the
  /// constraint in front of the message. Throws phiq::Error for data the kind refuses (here: L not positive).
  void prepare(const double* /*q0*/) const {
    detail::require(std::isfinite(length) && length > 0.0, "distance: length must be positive and finite");
  }
  /// What draws the constraint, said once for the mechanism's sketch (mechanism_sketch.hpp) and the derived parts
  /// (drawn_parts.hpp), through the primitives of kinds/registry.hpp (detail::SketchProbe): `sk.bar(p, q, L)` for a
  /// bar between two planar points (L its length, 0 if the kind has none), `sk.arm(frame, s)` for a body's arm from
  /// its reference point to a local point, and the kinds' own geometry (a gear's pitch circle, a cam's profile, …).
  /// Kinds that draw nothing say why.
  template <class Sketch>
  void sketch(Sketch& sk) const {
    sk.bar(a, b, length);
  }
  /// How scenes write it (models/README.md).
  static constexpr SceneForm kScene[] = {
      {"constraints", "distance", 2, "- {name: rod, type: distance, points: [A, B], length: 1.0}"}};
  /// Reads a constraint of this kind from a scene entry whose `type` is one of kScene's: `f` is the entry's fields
  /// in the scene vocabulary (SceneFields in kind_support.hpp: points, segments, numbers, attachments, …), which
  /// names the file, line and field of any error. Called by the scene reader, through the registry.
  template <class Fields>
  static DistanceSpec read(const Fields& f) {
    f.expect({"type", "name", "points", "length"});
    auto [pa, pb] = f.segment("points");
    return DistanceSpec{pa, pb, f.positive("length")};
  }
};

}  // namespace phiq
