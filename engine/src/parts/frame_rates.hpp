// Internal: the rates along a design parameter p of what a part's frame reads besides q and t (its constants, a
// frame of expressions' expressions and axis), from the frame of the scene read at p − 2h, p − h, p + h, p + 2h:
// what the dual path of the generalized forces' rate (force_rate.cpp) carries in its ε parts.
#pragma once

#include <array>
#include <cstddef>

#include "phiq/parts.hpp"

namespace phiq::detail {

// The fourth-order difference over h of what the copies at p − 2h, p − h, p + h, p + 2h give: exact for a datum
// linear in p.
inline double copies_rate(const double x[4], double h) { return ((x[0] - x[3]) + 8.0 * (x[2] - x[1])) / (12.0 * h); }
inline kin3::V3 vector_rate(const std::array<kin3::V3, 4>& x, double h) {
  return (1.0 / (12.0 * h)) * ((x[0] - x[3]) + 8.0 * (x[2] - x[1]));
}

// The rates along p of a frame's constants (a ground pivot at a dimension), slot by slot; of a frame of
// expressions, its expressions' copies along p and its axis's rate.
struct FrameRates {
  std::array<const Slot*, 9> slots{};
  std::array<double, 9> rate{};
  std::size_t count = 0;
  // a frame of expressions: its origin's components and its angle, each with its copies (where p moves it)
  std::array<const CompiledExpression*, 4> expressions{};
  std::array<std::array<const CompiledExpression*, 4>, 4> copies{};
  std::array<bool, 4> moves{};
  double step = 1.0;
  kin3::V3 axis{};
  // The rate of the constant in slot `s` of the frame (0 for a slot of another frame).
  double of(const Slot& s) const {
    for (std::size_t i = 0; i < count; ++i)
      if (slots[i] == &s) return rate[i];
    return 0.0;
  }
  // The copies along p of the frame's expression `e`; null where p does not move it.
  const std::array<const CompiledExpression*, 4>* copies_of(const CompiledExpression& e) const {
    for (std::size_t i = 0; i < expressions.size(); ++i)
      if (expressions[i] == &e) return moves[i] ? &copies[i] : nullptr;
    return nullptr;
  }
};

// The rates of `own` from its copies along p (null: `own` itself) over the step h. False where the copies are not
// the same frame but for their data: another kind, another coordinate in a slot; for a frame of expressions, other
// components, another angle's presence, or an expression that reads other coordinates.
bool frame_rates(const PartFrame& own, const std::array<const PartFrame*, 4>& copies, double h, FrameRates& out);

}  // namespace phiq::detail
