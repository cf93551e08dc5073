/// @file
/// The constraint kinds of phiq, as plain data (one struct per kind).
///
/// Every kind states its equation Φ(q, t) = 0 in a comment and supplies, for the rows it owns:
///   residual(q, t, phi)        Φ
///   jacobian(q, t, sink)       Φq as (row, slot, value) entries through `sink`, always in the same order and with the
///                              same set of entries (the set may depend on which slots are constants, never on values),
///                              so that one pass in pattern mode fixes the sparsity pattern of the model
///   phi_t(q, t, out)           ∂Φ/∂t (only called when depends_on_time())
///   gamma(q, qd, t, out)       γ = −(Φq q̇)q q̇ − 2 Φqt q̇ − Φtt, the right-hand side of Φq q̈ = γ
/// plus the unit of each row and, through for_each_slot, the unit of each coordinate it reads. The solver never
/// needs to know which kind it is evaluating (see constraint_block.hpp). The contract of these functions is
/// documented once, on DistanceSpec; the other kinds refer to it and say where they differ.
///
/// Covers the four coordinate families of the notes: natural coordinates (distance, fixed point through Pin with a
/// constant side, point on line, constant angle), reference-point coordinates (revolute Pin between body frames,
/// prismatic), relative coordinates (loop closure), mixes (segment angle, polar), general equations and drivers.
#pragma once

#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "phiq/expression.hpp"
#include "phiq/motion_law.hpp"
#include "phiq/types.hpp"

namespace phiq {

namespace kin {
struct V2 {
  double x, y;
};
inline V2 operator+(V2 a, V2 b) { return {a.x + b.x, a.y + b.y}; }
inline V2 operator-(V2 a, V2 b) { return {a.x - b.x, a.y - b.y}; }
inline V2 operator*(double s, V2 a) { return {s * a.x, s * a.y}; }
inline double dot(V2 a, V2 b) { return a.x * b.x + a.y * b.y; }
inline double cross(V2 a, V2 b) { return a.x * b.y - a.y * b.x; }
inline V2 perp(V2 a) { return {-a.y, a.x}; }  // rotation by +90°
inline V2 rotate(double psi, V2 s) {
  double c = std::cos(psi), n = std::sin(psi);
  return {c * s.x - n * s.y, n * s.x + c * s.y};
}
inline V2 pos(const Point2& p, const double* q) { return {p.x.of(q), p.y.of(q)}; }
inline V2 vel(const Point2& p, const double* qd) { return {p.x.rate(qd), p.y.rate(qd)}; }
/// |s| when the frame moves (any of x, y, ψ is a coordinate), 0 for a fixed frame (see PinSpec).
inline double moving_arm(const Frame2& f, V2 s) {
  const bool fixed = !f.x.is_coordinate() && !f.y.is_coordinate() && !f.psi.is_coordinate();
  return fixed ? 0.0 : std::hypot(s.x, s.y);
}
}  // namespace kin

/// Distance between two points (natural coordinates): rigid-body condition of a bar.
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
  /// Number of rows of Φ a constraint of this kind owns: its residual, Φt and γ have kRows values and its Jacobian
  /// entries have rows 0 … kRows − 1 (local rows; the model places them at the constraint's first global row).
  static constexpr int kRows = 1;
  /// Name of the kind, as reported in diagnostics (ConstraintInfo::kind, ConstraintBlock::kind()) and used in the
  /// default name "kind#k" of an unnamed constraint. A static string.
  static constexpr const char* kKind = "distance";
  /// @var a
  /// @brief A, first end point (m).
  Point2 a, b;  ///< B, second end point (m)
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
};

/// Coincidence of two attachment points ("pin"): a revolute pair between two bodies in reference-point coordinates,
/// a body point fixed to ground (one side constant), a fixed point (natural point against a constant), or a body
/// pinned to a natural point (mixed). Attachment k is frame_k = (x, y, ψ) plus the local vector s_k:
///   Φ = r_a + R(ψ_a) s_a − r_b − R(ψ_b) s_b            (2 rows, lengths)
/// A natural point is a frame with ψ constant and s = 0.
struct PinSpec {
  static constexpr int kRows = 2;  ///< two rows: x and y of the gap between the attachment points
  /// @copydoc DistanceSpec::kKind
  /// Scenes write a pin as `revolute` (between attachments) or `fixed_point` (a point at constant coordinates).
  static constexpr const char* kKind = "pin";
  /// @var a
  /// @brief Frame of attachment a: a body frame (x, y in m, ψ in rad), a natural point (ψ constant) or ground.
  Frame2 a, b;  ///< frame of attachment b, like a
  /// @var sa
  /// @brief s_a, the attachment point in a's local frame (m); (0, 0) for a natural point or a body's origin.
  kin::V2 sa{0, 0}, sb{0, 0};  ///< s_b, the attachment point in b's local frame (m)

  /// @copydoc DistanceSpec::depends_on_time
  /// A pin is time-independent.
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// Both rows of a pin are lengths.
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  /// For a pin: the longer arm, max(|s_a|, |s_b|), of the frames that move. An attachment on a fixed frame
  /// (ground: x, y, ψ all constants) is a position in the plane, not a link dimension: the 10^6-th pivot of a chain
  /// on the ground at (10^6, 0) must not make the model's length scale 10^6 m.
  double characteristic_length() const { return std::max(kin::moving_arm(a, sa), kin::moving_arm(b, sb)); }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Pin
  /// A pin reads x, y (lengths) and ψ (an angle) of frame a, then of frame b.
  template <class F>
  void for_each_slot(F&& f) const {
    f(a.x, Unit::kLength), f(a.y, Unit::kLength), f(a.psi, Unit::kAngle);
    f(b.x, Unit::kLength), f(b.y, Unit::kLength), f(b.psi, Unit::kAngle);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    kin::V2 pa = kin::V2{a.x.of(q), a.y.of(q)} + kin::rotate(a.psi.of(q), sa);
    kin::V2 pb = kin::V2{b.x.of(q), b.y.of(q)} + kin::rotate(b.psi.of(q), sb);
    phi[0] = pa.x - pb.x;
    phi[1] = pa.y - pb.y;
  }
  /// @copydoc DistanceSpec::jacobian
  /// @par Pin
  /// A pin emits the ψ entries of an attachment only if its ψ is a coordinate and its arm s is non-zero (decided by
  /// the data, never by q).
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    const bool ra = has_arm(a, sa), rb = has_arm(b, sb);
    kin::V2 ja = ra ? kin::perp(kin::rotate(a.psi.of(q), sa)) : kin::V2{0, 0};
    kin::V2 jb = rb ? kin::perp(kin::rotate(b.psi.of(q), sb)) : kin::V2{0, 0};
    s(0, a.x, 1.0), s(0, b.x, -1.0), s(1, a.y, 1.0), s(1, b.y, -1.0);
    if (ra) s(0, a.psi, ja.x), s(1, a.psi, ja.y);
    if (rb) s(0, b.psi, -jb.x), s(1, b.psi, -jb.y);
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = out[1] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double, double* out) const {
    // d²/dt² R(ψ)s = ψ̈ perp(Rs) − ψ̇² Rs; the ψ̈ part is in Φq q̈.
    double wa = a.psi.rate(qd), wb = b.psi.rate(qd);
    kin::V2 ga = (wa * wa) * kin::rotate(a.psi.of(q), sa);
    kin::V2 gb = (wb * wb) * kin::rotate(b.psi.of(q), sb);
    out[0] = ga.x - gb.x;
    out[1] = ga.y - gb.y;
  }

 private:
  /// @cond internal
  /// Whether the attachment turns with a coordinate: then Φ depends on its ψ.
  static bool has_arm(const Frame2& f, kin::V2 s) { return f.psi.is_coordinate() && (s.x != 0.0 || s.y != 0.0); }
  /// @endcond
};

/// Prismatic pair between body a and body b (reference-point coordinates). With e = R(ψ_a) u the sliding axis (u a
/// unit vector in a's frame), P_a = r_a + R(ψ_a) s_a a point of the line on a and P_b = r_b + R(ψ_b) s_b a point of b:
///   Φ0 = ψ_b − ψ_a − θ0                 (no relative rotation; angle)
///   Φ1 = e × (P_b − P_a)                (P_b stays on the line of a; length since |e| = 1)
struct PrismaticSpec {
  static constexpr int kRows = 2;  ///< two rows: Φ0 (relative rotation) and Φ1 (distance of P_b from the line)
  /// @copydoc DistanceSpec::kKind
  /// Scene type `prismatic`.
  static constexpr const char* kKind = "prismatic";
  /// @var a
  /// @brief Frame of body a, which carries the sliding line (x, y in m, ψ in rad).
  Frame2 a, b;  ///< frame of body b, which slides along the line
  /// @var sa
  /// @brief s_a, a point of the sliding line in a's local frame (m).
  kin::V2 sa{0, 0}, sb{0, 0};  ///< s_b, the point of b kept on the line, in b's local frame (m)
  kin::V2 axis{1, 0};  ///< u, direction of the line in a's local frame; normalised when the constraint is added
  double angle = 0.0;  ///< θ0, the constant relative angle ψ_b − ψ_a (rad)

  /// @copydoc DistanceSpec::depends_on_time
  /// A prismatic pair is time-independent.
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// For a prismatic pair, row 0 (relative rotation) is an angle and row 1 (distance from the line) a length.
  Unit row_unit(int row, const std::vector<Unit>&) const { return row == 0 ? Unit::kAngle : Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  /// For a prismatic pair: the longer arm, max(|s_a|, |s_b|), of the frames that move. An attachment on a fixed frame
  /// (ground: x, y, ψ all constants) is a position in the plane, not a link dimension: the 10^6-th pivot of a chain
  /// on the ground at (10^6, 0) must not make the model's length scale 10^6 m.
  double characteristic_length() const { return std::max(kin::moving_arm(a, sa), kin::moving_arm(b, sb)); }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Prismatic pair
  /// A prismatic pair reads x, y (lengths) and ψ (an angle) of frame a, then of frame b.
  template <class F>
  void for_each_slot(F&& f) const {
    f(a.x, Unit::kLength), f(a.y, Unit::kLength), f(a.psi, Unit::kAngle);
    f(b.x, Unit::kLength), f(b.y, Unit::kLength), f(b.psi, Unit::kAngle);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    Geometry g = geometry(q);
    phi[0] = b.psi.of(q) - a.psi.of(q) - angle;
    phi[1] = kin::cross(g.e, g.h);
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    Geometry g = geometry(q);
    s(0, b.psi, 1.0), s(0, a.psi, -1.0);
    s(1, a.x, g.e.y), s(1, a.y, -g.e.x), s(1, b.x, -g.e.y), s(1, b.y, g.e.x);
    // ∂/∂ψa: e turns and P_a moves: −e·(r_b + R_b s_b − r_a); ∂/∂ψb = e·(R_b s_b)
    s(1, a.psi, -kin::dot(g.e, g.h + g.arm_a)), s(1, b.psi, kin::dot(g.e, g.arm_b));
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = out[1] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double, double* out) const {
    Geometry g = geometry(q);
    double wa = a.psi.rate(qd), wb = b.psi.rate(qd);
    kin::V2 edot = wa * kin::perp(g.e);
    kin::V2 hdot = kin::V2{b.x.rate(qd), b.y.rate(qd)} + wb * kin::perp(g.arm_b) -
                   kin::V2{a.x.rate(qd), a.y.rate(qd)} - wa * kin::perp(g.arm_a);
    // q̈-free parts: ë = −ψ̇a² e, ḧ = −ψ̇b² R_b s_b + ψ̇a² R_a s_a
    kin::V2 hdd = (wa * wa) * g.arm_a - (wb * wb) * g.arm_b;
    double phidd = -wa * wa * kin::cross(g.e, g.h) + 2.0 * kin::cross(edot, hdot) + kin::cross(g.e, hdd);
    out[0] = 0.0;
    out[1] = -phidd;
  }

 private:
  /// @cond internal
  /// The vectors of the equations at q: e = R(ψ_a) u, arm_k = R(ψ_k) s_k, h = P_b − P_a.
  struct Geometry {
    kin::V2 e, arm_a, arm_b, h;
  };
  /// Computes Geometry at q.
  Geometry geometry(const double* q) const {
    Geometry g;
    double pa = a.psi.of(q), pb = b.psi.of(q);
    g.e = kin::rotate(pa, axis);
    g.arm_a = kin::rotate(pa, sa);
    g.arm_b = kin::rotate(pb, sb);
    g.h = kin::V2{b.x.of(q), b.y.of(q)} + g.arm_b - kin::V2{a.x.of(q), a.y.of(q)} - g.arm_a;
    return g;
  }
  /// @endcond
};

/// Point p on the straight line through a and b (natural coordinates):
///   Φ = ((b − a) × (p − a)) / ref
/// ref is |b − a| at the initial placement (set when the model is built), so that the row is the distance of p from
/// the line, a length. It scales the row; it does not change the solution.
struct PointOnLineSpec {
  static constexpr int kRows = 1;  ///< one row: the distance of p from the line
  /// @copydoc DistanceSpec::kKind
  /// Scene type `point_on_line`.
  static constexpr const char* kKind = "point_on_line";
  /// @var p
  /// @brief P, the point kept on the line (m).
  /// @var a
  /// @brief A, first point of the line (m).
  Point2 p, a, b;  ///< B, second point of the line (m); must differ from A at the initial placement to set ref
  /// |B − A| at the initial placement (m), set when the constraint is added (1 if that length is zero or not
  /// finite). It scales the row and does not change the solution.
  double ref = 1.0;

  /// @copydoc DistanceSpec::depends_on_time
  /// A point on a line is time-independent.
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// The row of a point on a line is a length.
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  /// A point on a line carries no length as data (ref only scales the row): 0.
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Point on a line
  /// A point on a line reads p, a and b, all lengths.
  template <class F>
  void for_each_slot(F&& f) const {
    f(p.x, Unit::kLength), f(p.y, Unit::kLength), f(a.x, Unit::kLength), f(a.y, Unit::kLength);
    f(b.x, Unit::kLength), f(b.y, Unit::kLength);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    kin::V2 u = kin::pos(b, q) - kin::pos(a, q), w = kin::pos(p, q) - kin::pos(a, q);
    phi[0] = kin::cross(u, w) / ref;
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    kin::V2 u = kin::pos(b, q) - kin::pos(a, q), w = kin::pos(p, q) - kin::pos(a, q);
    const double k = 1.0 / ref;
    // ∂/∂u = (w_y, −w_x), ∂/∂w = (−u_y, u_x); a enters both with a minus sign
    s(0, p.x, -k * u.y), s(0, p.y, k * u.x);
    s(0, b.x, k * w.y), s(0, b.y, -k * w.x);
    s(0, a.x, k * (u.y - w.y)), s(0, a.y, k * (w.x - u.x));
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double*, const double* qd, double, double* out) const {
    kin::V2 ud = kin::vel(b, qd) - kin::vel(a, qd), wd = kin::vel(p, qd) - kin::vel(a, qd);
    out[0] = -2.0 * kin::cross(ud, wd) / ref;
  }
};

/// Constant angle α from segment u = b − a to segment v = d − c (natural coordinates):
///   Φ = (cos α (u × v) − sin α (u · v)) / ref   = |u||v| sin(θ_uv − α) / ref
/// ref is |u||v| at the initial placement, so the row is (close to) the angle error in radians. Well conditioned for
/// every α (unlike a pure dot or cross form); it is also met at α + π, a branch Newton does not reach from nearby.
struct ConstantAngleSpec {
  static constexpr int kRows = 1;  ///< one row: (close to) the angle error
  /// @copydoc DistanceSpec::kKind
  /// Scene type `constant_angle`.
  static constexpr const char* kKind = "constant_angle";
  /// @var a
  /// @brief A, start of segment u = B − A (m).
  /// @var b
  /// @brief B, end of segment u (m).
  /// @var c
  /// @brief C, start of segment v = D − C (m).
  Point2 a, b, c, d;  ///< D, end of segment v (m)
  double angle = 0.0;  ///< α, the constant angle from u to v (rad, counter-clockwise), finite
  /// |u||v| at the initial placement (m²), set when the constraint is added (1 if either segment has zero length).
  /// It scales the row and does not change the solution.
  double ref = 1.0;

  /// @copydoc DistanceSpec::depends_on_time
  /// A constant angle is time-independent.
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// The row of a constant angle is an angle (close to the angle error in radians).
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kAngle; }
  /// @copydoc DistanceSpec::characteristic_length
  /// A constant angle carries no length as data (ref only scales the row): 0.
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Constant angle
  /// A constant angle reads the points a, b, c and d, all lengths.
  template <class F>
  void for_each_slot(F&& f) const {
    f(a.x, Unit::kLength), f(a.y, Unit::kLength), f(b.x, Unit::kLength), f(b.y, Unit::kLength);
    f(c.x, Unit::kLength), f(c.y, Unit::kLength), f(d.x, Unit::kLength), f(d.y, Unit::kLength);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    kin::V2 u = kin::pos(b, q) - kin::pos(a, q), v = kin::pos(d, q) - kin::pos(c, q);
    phi[0] = (std::cos(angle) * kin::cross(u, v) - std::sin(angle) * kin::dot(u, v)) / ref;
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    kin::V2 u = kin::pos(b, q) - kin::pos(a, q), v = kin::pos(d, q) - kin::pos(c, q);
    const double ca = std::cos(angle) / ref, sa = std::sin(angle) / ref;
    kin::V2 du{ca * v.y - sa * v.x, -ca * v.x - sa * v.y};
    kin::V2 dv{-ca * u.y - sa * u.x, ca * u.x - sa * u.y};
    s(0, a.x, -du.x), s(0, a.y, -du.y), s(0, b.x, du.x), s(0, b.y, du.y);
    s(0, c.x, -dv.x), s(0, c.y, -dv.y), s(0, d.x, dv.x), s(0, d.y, dv.y);
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double*, const double* qd, double, double* out) const {
    kin::V2 ud = kin::vel(b, qd) - kin::vel(a, qd), vd = kin::vel(d, qd) - kin::vel(c, qd);
    out[0] = -2.0 * (std::cos(angle) * kin::cross(ud, vd) - std::sin(angle) * kin::dot(ud, vd)) / ref;
  }
};

/// Angle coordinate θ of segment a → b against the x axis (mixes natural coordinates with an angle, typically to
/// drive a natural-coordinate mechanism by a crank angle):
///   Φ = (x_b − x_a) sin θ − (y_b − y_a) cos θ       = |b − a| sin(θ_ab − θ), a length
/// Its gradient never vanishes for a segment of non-zero length, unlike a cos/sin pair chosen by quadrant.
struct SegmentAngleSpec {
  static constexpr int kRows = 1;  ///< one row, a length
  /// @copydoc DistanceSpec::kKind
  /// Scene type `segment_angle`.
  static constexpr const char* kKind = "angle";
  /// @var a
  /// @brief A, start of the segment (m).
  Point2 a, b;  ///< B, end of the segment (m)
  Slot theta;  ///< θ, the angle of b − a against the x axis (rad): usually a coordinate; a constant fixes it

  /// @copydoc DistanceSpec::depends_on_time
  /// A segment angle is time-independent.
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// The row of a segment angle is a length (|b − a| sin(θ_ab − θ)), not an angle.
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  /// A segment angle carries no length as data: 0.
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Segment angle
  /// A segment angle reads a and b (lengths), then θ (an angle).
  template <class F>
  void for_each_slot(F&& f) const {
    f(a.x, Unit::kLength), f(a.y, Unit::kLength), f(b.x, Unit::kLength), f(b.y, Unit::kLength);
    f(theta, Unit::kAngle);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    kin::V2 d = kin::pos(b, q) - kin::pos(a, q);
    double th = theta.of(q);
    phi[0] = d.x * std::sin(th) - d.y * std::cos(th);
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    kin::V2 d = kin::pos(b, q) - kin::pos(a, q);
    double th = theta.of(q), sn = std::sin(th), cs = std::cos(th);
    s(0, a.x, -sn), s(0, a.y, cs), s(0, b.x, sn), s(0, b.y, -cs), s(0, theta, d.x * cs + d.y * sn);
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double, double* out) const {
    kin::V2 d = kin::pos(b, q) - kin::pos(a, q), dd = kin::vel(b, qd) - kin::vel(a, qd);
    double th = theta.of(q), w = theta.rate(qd), sn = std::sin(th), cs = std::cos(th);
    out[0] = -2.0 * w * (dd.x * cs + dd.y * sn) + w * w * (d.x * sn - d.y * cs);
  }
};

/// Point p at distance L from o in direction θ (mixed coordinates; the notes' crank  x_A − L2 cos θ2 = 0,
/// y_A − L2 sin θ2 = 0 with o the origin):
///   Φ = p − o − L (cos θ, sin θ)                         (2 rows, lengths)
struct PolarSpec {
  static constexpr int kRows = 2;  ///< two rows: x and y, lengths
  /// @copydoc DistanceSpec::kKind
  /// Scene type `polar`.
  static constexpr const char* kKind = "polar";
  /// @var p
  /// @brief P, the point placed at distance L from o (m).
  Point2 p, o;  ///< O, the origin of the polar vector (m)
  double length = 1.0;  ///< L, metres, finite (a negative L points against θ)
  Slot theta;  ///< θ, the direction of P − O against the x axis (rad): a coordinate or a constant

  /// @copydoc DistanceSpec::depends_on_time
  /// A polar constraint is time-independent.
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// Both rows of a polar constraint are lengths.
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  /// For a polar constraint: |L|.
  double characteristic_length() const { return std::fabs(length); }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Polar
  /// A polar constraint reads p and o (lengths), then θ (an angle).
  template <class F>
  void for_each_slot(F&& f) const {
    f(p.x, Unit::kLength), f(p.y, Unit::kLength), f(o.x, Unit::kLength), f(o.y, Unit::kLength);
    f(theta, Unit::kAngle);
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    double th = theta.of(q);
    phi[0] = p.x.of(q) - o.x.of(q) - length * std::cos(th);
    phi[1] = p.y.of(q) - o.y.of(q) - length * std::sin(th);
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    double th = theta.of(q);
    s(0, p.x, 1.0), s(0, o.x, -1.0), s(0, theta, length * std::sin(th));
    s(1, p.y, 1.0), s(1, o.y, -1.0), s(1, theta, -length * std::cos(th));
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = out[1] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double, double* out) const {
    double th = theta.of(q), w = theta.rate(qd);
    out[0] = -length * w * w * std::cos(th);
    out[1] = -length * w * w * std::sin(th);
  }
};

/// Loop closure in relative coordinates: the links of a kinematic loop, each a vector of length ℓ_k (a constant or
/// a coordinate, e.g. a slider travel) at angle θ_k = offset_k + Σ_j sign_kj q_j (absolute angles, or the running
/// sums of relative joint angles as in the notes: ψ2, ψ2 + ψ3, ψ2 + ψ3 + ψ4), add up to the constant closure vector c:
///   Φ = Σ_k ℓ_k (cos θ_k, sin θ_k) − c                  (2 rows, lengths)
struct LoopSpec {
  static constexpr int kRows = 2;  ///< two rows: x and y of the closure error, lengths
  /// @copydoc DistanceSpec::kKind
  /// Scene type `loop`.
  static constexpr const char* kKind = "loop";
  /// One term sign · q_j of the angle θ_k of a link.
  struct Term {
    Slot angle;  ///< q_j, an angle (rad): usually a coordinate (absolute or relative joint angle)
    double sign = 1.0;  ///< its factor in θ_k: +1 or −1 (any finite factor is accepted)
  };
  /// One link of the loop: the vector ℓ_k (cos θ_k, sin θ_k), with θ_k = offset + Σ_terms sign · q_j.
  struct Link {
    Slot length;  ///< ℓ_k (m): a constant link length, or a coordinate (e.g. a slider travel)
    double offset = 0.0;  ///< constant part of θ_k (rad), finite
    std::vector<Term> terms;  ///< the variable part of θ_k; empty for a link of constant direction
  };
  std::vector<Link> links;  ///< the links of the loop, at least one (checked when the constraint is added)
  kin::V2 closure{0, 0};  ///< c, the constant closure vector (m): (0, 0) when the loop returns to its start

  /// @copydoc DistanceSpec::depends_on_time
  /// A loop is time-independent.
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// Both rows of a loop are lengths.
  Unit row_unit(int, const std::vector<Unit>&) const { return Unit::kLength; }
  /// @copydoc DistanceSpec::characteristic_length
  /// For a loop: the largest of |c| and the constant link lengths |ℓ_k| (lengths that are coordinates are not
  /// data).
  double characteristic_length() const {
    double l = std::hypot(closure.x, closure.y);
    for (const Link& k : links)
      if (!k.length.is_coordinate()) l = std::max(l, std::fabs(k.length.value()));
    return l;
  }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Loop
  /// A loop reads, link by link, the length ℓ_k (a length) and then the angle of each term (angles); an angle shared
  /// by several links is reported once per link.
  template <class F>
  void for_each_slot(F&& f) const {
    for (const Link& k : links) {
      f(k.length, Unit::kLength);
      for (const Term& t : k.terms) f(t.angle, Unit::kAngle);
    }
  }
  /// θ_k = offset + Σ sign · q_j, the angle of link `k` at coordinates `q` (rad). Thread-safe.
  /// @pre `q` has at least max_coordinate(spec) + 1 entries.
  double angle_of(const Link& k, const double* q) const {
    double th = k.offset;
    for (const Term& t : k.terms) th += t.sign * t.angle.of(q);
    return th;
  }
  /// θ̇_k = Σ sign · q̇_j, the angular velocity of link `k` at velocities `qd` (rad/s); the offset is constant.
  /// Thread-safe.
  /// @pre `qd` has at least max_coordinate(spec) + 1 entries.
  double rate_of(const Link& k, const double* qd) const {
    double w = 0.0;
    for (const Term& t : k.terms) w += t.sign * t.angle.rate(qd);
    return w;
  }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    double sx = -closure.x, sy = -closure.y;
    for (const Link& k : links) {
      double th = angle_of(k, q), l = k.length.of(q);
      sx += l * std::cos(th);
      sy += l * std::sin(th);
    }
    phi[0] = sx;
    phi[1] = sy;
  }
  /// @copydoc DistanceSpec::jacobian
  /// @par Loop
  /// A loop emits, link by link, ∂Φ/∂ℓ_k (both rows) and then the two entries of each angle term; an angle shared
  /// by several links gets one pair of entries per link, and these add up.
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    for (const Link& k : links) {
      double th = angle_of(k, q), l = k.length.of(q), cs = std::cos(th), sn = std::sin(th);
      s(0, k.length, cs), s(1, k.length, sn);
      for (const Term& t : k.terms) s(0, t.angle, -t.sign * l * sn), s(1, t.angle, t.sign * l * cs);
    }
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const { out[0] = out[1] = 0.0; }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double, double* out) const {
    // Φ̈ = Σ ℓ̈ e + (ℓ θ̈ + 2 ℓ̇ θ̇) perp(e) − ℓ θ̇² e  ⇒  γ = Σ ℓ θ̇² e − 2 ℓ̇ θ̇ perp(e)
    double gx = 0.0, gy = 0.0;
    for (const Link& k : links) {
      double th = angle_of(k, q), w = rate_of(k, qd), l = k.length.of(q), ld = k.length.rate(qd);
      double cs = std::cos(th), sn = std::sin(th);
      gx += l * w * w * cs + 2.0 * ld * w * sn;
      gy += l * w * w * sn - 2.0 * ld * w * cs;
    }
    out[0] = gx;
    out[1] = gy;
  }
};

/// Rheonomic driver on one coordinate (a motor):
///   Φ = q_j − f(t),   Φt = −f'(t),   γ = f''(t)       (0 for a linear law: the notes' erratum)
struct CoordinateDriverSpec {
  static constexpr int kRows = 1;  ///< one row, in the unit of the driven coordinate
  /// @copydoc DistanceSpec::kKind
  /// Added with ModelBuilder::add_driver() or, in a scene, as a driver given by `coordinate`.
  static constexpr const char* kKind = "driver";
  Slot coordinate;  ///< q_j, the driven coordinate; must be a coordinate (checked when the constraint is added)
  MotionLaw law;  ///< f(t), the prescribed value of q_j, in q_j's unit; defines the time range of the model

  /// @copydoc DistanceSpec::depends_on_time
  /// A driver always depends on time.
  bool depends_on_time() const { return true; }
  /// @copydoc DistanceSpec::row_unit
  /// A driver's row has the unit of the driven coordinate, `coordinate_units[coordinate.coord()]` (Unit::kNone if
  /// none was inferred).
  Unit row_unit(int, const std::vector<Unit>& coordinate_units) const {
    return coordinate.is_coordinate() ? coordinate_units[coordinate.coord()] : Unit::kNone;
  }
  /// @copydoc DistanceSpec::characteristic_length
  /// A driver carries no length as data: 0.
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Driver
  /// A driver reads only the driven coordinate, with Unit::kNone: driving a coordinate does not tell what it
  /// measures.
  template <class F>
  void for_each_slot(F&& f) const {
    f(coordinate, Unit::kNone);
  }
  /// @copydoc DistanceSpec::residual
  /// @par Driver
  /// A driver evaluates its law at `t`: Φ = q_j − f(t) (NaN outside the law's domain).
  void residual(const double* q, double t, double* phi) const { phi[0] = coordinate.of(q) - law.evaluate(t).f; }
  /// @copydoc DistanceSpec::jacobian
  /// @par Driver
  /// A driver emits one entry, 1 on the driven coordinate; `q` and `t` are not read.
  template <class Sink>
  void jacobian(const double*, double, Sink& s) const {
    s(0, coordinate, 1.0);
  }
  /// @copydoc DistanceSpec::phi_t
  /// @par Driver
  /// For a driver: Φt = −f'(t); `q` is not read.
  void phi_t(const double*, double t, double* out) const { out[0] = -law.evaluate(t).df; }
  /// @copydoc DistanceSpec::gamma
  /// @par Driver
  /// For a driver: γ = f''(t) (0 for a linear law); `q` and `qd` are not read.
  void gamma(const double*, const double*, double t, double* out) const { out[0] = law.evaluate(t).ddf; }
};

/// General equation written as text, optionally driven by a motion law:
///   Φ = g(q, t) − f(t)            (f ≡ 0 without a law)
/// with Φq, Φt and γ derived exactly from g (expression.hpp). `unit` says what g measures (for tolerances).
struct EquationSpec {
  static constexpr int kRows = 1;  ///< one row, in `unit`
  /// @copydoc DistanceSpec::kKind
  /// Scene type `equation` without a law; a scene driver given by `expr` is an equation with a law.
  static constexpr const char* kKind = "equation";
  /// g(q, t), compiled with its derivatives; never null (checked when the constraint is added). Immutable, so
  /// copies of the spec share it.
  std::shared_ptr<const CompiledExpression> g;
  std::optional<MotionLaw> law;  ///< f(t), in g's unit; none means f ≡ 0
  Unit unit = Unit::kNone;  ///< what g measures: the row's unit, for its tolerance (Unit::kNone: plain tol)

  /// @copydoc DistanceSpec::depends_on_time
  /// An equation depends on time if it has a law or if g contains t.
  bool depends_on_time() const { return law.has_value() || g->depends_on_time(); }
  /// @copydoc DistanceSpec::row_unit
  /// An equation's row has the declared `unit`.
  Unit row_unit(int, const std::vector<Unit>&) const { return unit; }
  /// @copydoc DistanceSpec::characteristic_length
  /// An equation carries no length as data: 0.
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Equation
  /// An equation reads the coordinates g depends on (CompiledExpression::coordinates(), ascending), each with
  /// Unit::kNone: the text does not tell what they measure.
  template <class F>
  void for_each_slot(F&& f) const {
    for (Index i : g->coordinates()) f(Slot::coordinate(i), Unit::kNone);
  }
  /// @copydoc DistanceSpec::residual
  /// @par Equation
  /// For an equation: Φ = g(q, t) − f(t). g is evaluated with thread-local scratch (see CompiledExpression).
  void residual(const double* q, double t, double* phi) const {
    phi[0] = g->value(q, t) - (law ? law->evaluate(t).f : 0.0);
  }
  /// @copydoc DistanceSpec::jacobian
  /// @par Equation
  /// An equation emits one entry per coordinate of g, in ascending order, through a thread-local gradient buffer:
  /// concurrent calls from different threads are safe, but the sink must not call jacobian() of an EquationSpec.
  template <class Sink>
  void jacobian(const double* q, double t, Sink& s) const {
    thread_local std::vector<double> grad;
    const auto& cols = g->coordinates();
    grad.resize(cols.size());
    g->gradient(q, t, grad.data());
    for (std::size_t k = 0; k < cols.size(); ++k) s(0, Slot::coordinate(cols[k]), grad[k]);
  }
  /// @copydoc DistanceSpec::phi_t
  /// @par Equation
  /// For an equation: Φt = ∂g/∂t − f'(t), exact; thread-local scratch as for residual().
  void phi_t(const double* q, double t, double* out) const {
    out[0] = (g->depends_on_time() ? g->partial_t(q, t) : 0.0) - (law ? law->evaluate(t).df : 0.0);
  }
  /// @copydoc DistanceSpec::gamma
  /// @par Equation
  /// For an equation: γ of g, exact (CompiledExpression::gamma()), plus f''(t); thread-local scratch as for
  /// residual().
  void gamma(const double* q, const double* qd, double t, double* out) const {
    out[0] = g->gamma(q, qd, t) + (law ? law->evaluate(t).ddf : 0.0);
  }
};

}  // namespace phiq
