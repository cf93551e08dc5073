// Basic vocabulary shared by every part of phiq: indices, slots, units and the API error type.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace phiq {

// Indices are 64-bit: SuiteSparse's "l" interfaces (UMFPACK dl, KLU l, CHOLMOD long) take SuiteSparse_long, and
// 10^6-coordinate models have more than 2^31 Jacobian entries in some of their derived products.
using Index = std::int64_t;

// Thrown at the API boundary for programming errors (wrong sizes, unknown names, out-of-range indices, calling
// an algorithm before its pre-condition holds) and for invalid model data. Numerical outcomes are never
// exceptions: they are statuses (see kinematics.hpp).
class Error : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// `text` made fit for a one-line message: control characters escaped (\n, \t, \xNN). User text quoted in errors
// (expressions, names from a scene) may contain them.
std::string single_line(const std::string& text);

// What a coordinate or a constraint row measures. Tolerances are dimensional: a length is compared with
// tol * length_scale, an angle with tol (radians), a quantity of unknown unit with tol.
enum class Unit : std::uint8_t { kNone = 0, kLength = 1, kAngle = 2 };

const char* to_string(Unit u);

// A scalar that a constraint reads: either generalized coordinate `coord` or the constant `value`. Fixed points
// and ground are made of constant slots, so constraints never need separate "grounded" variants.
struct Slot {
  Index coord = -1;
  double value = 0.0;

  static Slot coordinate(Index i) { return Slot{i, 0.0}; }
  static Slot constant(double v) { return Slot{-1, v}; }
  bool is_coordinate() const { return coord >= 0; }
  double of(const double* q) const { return coord >= 0 ? q[coord] : value; }
  // Time derivative: constants do not move.
  double rate(const double* qd) const { return coord >= 0 ? qd[coord] : 0.0; }
};

// A planar point given by two slots (natural coordinates, or a fixed point, or a mix such as (xB, 0)).
struct Point2 {
  Slot x, y;
};

// A planar body frame in reference-point coordinates: position of its reference point and orientation angle.
// Ground is a frame of constants.
struct Frame2 {
  Slot x, y, psi;
};

}  // namespace phiq
