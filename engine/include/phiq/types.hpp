/// @file
/// Basic vocabulary shared by every part of phiq: indices, slots, units and the API error type.
#pragma once

#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "phiq/text.hpp"  // single_line, format_time: every message is built with them

namespace phiq {

/// Indices are 64-bit: SuiteSparse's "l" interfaces (UMFPACK dl, KLU l, CHOLMOD long) take SuiteSparse_long, and
/// 10^6-coordinate models have more than 2^31 Jacobian entries in some of their derived products.
using Index = std::int64_t;

/// Thrown at the API boundary for programming errors (wrong sizes, unknown names, out-of-range indices, calling
/// an algorithm before its pre-condition holds) and for invalid model data. Numerical outcomes are never
/// exceptions: they are statuses (see kinematics.hpp).
class Error : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// What a coordinate or a constraint row measures. Tolerances are dimensional: a length is compared with
/// tol * its own tolerance scale (ToleranceScales: its link), an angle with tol (radians), a quantity of unknown unit
/// with tol.
enum class Unit : std::uint8_t {
  kNone = 0,    ///< unknown or unitless: compared with tol
  kLength = 1,  ///< metres: compared with tol · its tolerance scale (ToleranceScales)
  kAngle = 2,   ///< radians: compared with tol
};

/// "none", "length" or "angle".
const char* to_string(Unit u);
/// The unit's symbol as messages write it after a number: "m", "rad", or "" (kNone).
const char* unit_symbol(Unit u);

/// A scalar that a constraint reads: either generalized coordinate coord() or the constant value(). Fixed points
/// and ground are made of constant slots, so constraints never need separate "grounded" variants.
///
/// One 64-bit word (constraints are mostly slots, and the Newton loop streams all of them at every iterate: at
/// 16 bytes a slot, the planar distance was 80 bytes of a 2·10⁴-row model's 1.6 MB pass): a constant is its own
/// double; a coordinate is a NaN with a tag no arithmetic produces and its index in the low 50 bits. A NaN constant
/// is stored as the default quiet NaN, so it stays a constant (and ModelBuilder rejects it as not finite).
class Slot {
 public:
  /// The constant 0.
  Slot() = default;
  /// The slot of coordinate `i` (an index into q, 0 ≤ i < 2⁵⁰; the upper bound against the model is checked when
  /// the constraint is added to a ModelBuilder). Throws Error for a negative or too large index.
  static Slot coordinate(Index i) {
    if (i < 0 || i > static_cast<Index>(kIndexMask))
      throw Error("slot: coordinate index " + std::to_string(i) + " out of range");
    return Slot(kTag | static_cast<std::uint64_t>(i));
  }
  /// A constant slot.
  static Slot constant(double v) {
    if (v != v) v = std::numeric_limits<double>::quiet_NaN();  // canonical quiet NaN: never the coordinate tag
    std::uint64_t b;
    std::memcpy(&b, &v, sizeof b);
    return Slot(b);
  }
  /// True for a coordinate, false for a constant.
  bool is_coordinate() const { return (bits_ & kTagMask) == kTag; }
  /// Index of the coordinate in q, or −1 for a constant.
  Index coord() const { return is_coordinate() ? static_cast<Index>(bits_ & kIndexMask) : -1; }
  /// The constant (0 for a coordinate).
  double value() const { return is_coordinate() ? 0.0 : as_double(); }
  /// Bit for bit: the same coordinate, or the same constant (+0 and −0 differ: two constants that print alike may
  /// still be two data).
  bool operator==(const Slot&) const = default;
  /// Its value at q (q must have more than coord() entries).
  double of(const double* q) const { return is_coordinate() ? q[bits_ & kIndexMask] : as_double(); }
  /// Time derivative: constants do not move.
  double rate(const double* qd) const { return is_coordinate() ? qd[bits_ & kIndexMask] : 0.0; }

 private:
  // Sign, all exponent bits, the quiet bit and the next one set: a negative quiet NaN with payload bit 50 set.
  // Hardware and libm NaNs have an empty payload (0xFFF8… or 0x7FF8…), so no computed constant carries the tag.
  static constexpr std::uint64_t kTagMask = 0xFFFC000000000000ULL;
  static constexpr std::uint64_t kTag = 0xFFFC000000000000ULL;
  static constexpr std::uint64_t kIndexMask = (std::uint64_t{1} << 50) - 1;
  explicit Slot(std::uint64_t bits) : bits_(bits) {}
  double as_double() const {
    double v;
    std::memcpy(&v, &bits_, sizeof v);
    return v;
  }
  std::uint64_t bits_ = 0;  // +0.0
};
static_assert(sizeof(Slot) == 8, "a slot is one word");

/// A planar point given by two slots (natural coordinates, or a fixed point, or a mix such as (xB, 0)).
struct Point2 {
  bool operator==(const Point2&) const = default;  ///< slot by slot
  Slot x;                                          ///< x coordinate (m)
  Slot y;                                          ///< y coordinate (m)
};

/// A planar body frame in reference-point coordinates: position of its reference point and orientation angle.
/// Ground is a frame of constants.
struct Frame2 {
  bool operator==(const Frame2&) const = default;  ///< slot by slot
  Slot x;                                          ///< x of the reference point (m)
  Slot y;                                          ///< y of the reference point (m)
  Slot psi;                                        ///< orientation (rad)
};

/// A spatial point given by three slots (natural coordinates, or a fixed point): also a natural unit vector's
/// components (ux, uy, uz).
struct Point3 {
  bool operator==(const Point3&) const = default;  ///< slot by slot
  Slot x;                                          ///< x coordinate (m; unitless for a vector)
  Slot y;                                          ///< y coordinate
  Slot z;                                          ///< z coordinate
};

/// A spatial body frame in reference-point coordinates: position of its reference point and its orientation as
/// Euler parameters (a unit quaternion, e0 the scalar part). Ground is a frame of constants with e = (1, 0, 0, 0).
struct Frame3 {
  bool operator==(const Frame3&) const = default;  ///< slot by slot
  Slot x;                                          ///< x of the reference point (m)
  Slot y;                                          ///< y of the reference point (m)
  Slot z;                                          ///< z of the reference point (m)
  Slot e0;  ///< Euler parameter e0 (scalar part; unitless): e0² + e1² + e2² + e3² = 1 is the body's own constraint
  Slot e1;  ///< Euler parameter e1
  Slot e2;  ///< Euler parameter e2
  Slot e3;  ///< Euler parameter e3
  /// The fixed frame: origin, no rotation.
  static Frame3 ground() {
    const Slot o = Slot::constant(0.0), one = Slot::constant(1.0);
    return Frame3{o, o, o, one, o, o, o};
  }
  /// True when every slot is a constant (ground or a fixed frame).
  bool is_fixed() const {
    return !x.is_coordinate() && !y.is_coordinate() && !z.is_coordinate() && !e0.is_coordinate() &&
           !e1.is_coordinate() && !e2.is_coordinate() && !e3.is_coordinate();
  }
};

}  // namespace phiq
