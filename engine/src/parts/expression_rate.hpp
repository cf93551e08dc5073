// Internal: a compiled expression's jet along the path the rate of the generalized forces walks (force_rate.cpp),
// with its exact rate along a design parameter: what frames of expressions (relative angles) need.
#pragma once

#include <array>

#include "expression/dual.hpp"
#include "parts/frame_jets.hpp"
#include "phiq/expression.hpp"

namespace phiq::detail {

// The motion at t: q, q̇, q̈ (q̈ may be null), and their rates along p, s, ṡ, s̈ (s̈ null with q̈).
struct MotionRates {
  const double *q, *qd, *qdd, *s, *sd, *sdd;
  double t;
};

// e's value and first and second derivatives along the motion (k < 0: σ ↦ (q + σ q̇ + σ²/2 q̈, t + σ), as
// part_motion() walks it), or along coordinate k at fixed t (k ≥ 0: σ ↦ q + σ e_k, a Jacobian column; the second
// derivative then 0, as a slot's), each with its rate along p: q, q̇, q̈ moving along s, ṡ, s̈ in Taylor mode over
// dual numbers (the second derivative's rate holds e's third derivatives: exact, no step), plus, where `copies`
// (e of the scene read at p − 2h, p − h, p + h, p + 2h) is not null, the fourth-order difference over h of their
// jets at the same (q, q̇, q̈, t): exact for an expression linear in what p moves. Pre-condition: the copies read
// the coordinates e reads.
JetT<Dual> expression_jet_rate(const CompiledExpression& e, const std::array<const CompiledExpression*, 4>* copies,
                               double h, const MotionRates& m, Index k);

}  // namespace phiq::detail
