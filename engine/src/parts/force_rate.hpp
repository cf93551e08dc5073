// Internal: the exact rate of the generalized forces Q(q, q̇, q̈, t) of phiq/inverse_dynamics.hpp along a design
// parameter p, with q, q̇, q̈ moving along their sensitivities s, ṡ, s̈ (phiq/sensitivity.hpp):
//
//   dQ/dp = Q_q s + Q_q̇ ṡ + Q_q̈ s̈ + ∂Q/∂p |q,q̇,q̈,
//
// in dual numbers (a + ε b, ε² = 0) through the same frame jets as part_motion(): every pose, velocity,
// acceleration, Jacobian column and load is carried with its derivative along ε, so no Q is differenced; a frame of
// expressions' jets by the expressions' Taylor pass in dual numbers (parts/expression_rate.hpp). What p
// changes of the parts and loads themselves (a mass, a centre of mass, an inertia, gravity, a load's point, a
// component's or a frame's expression, a spring's constants) enters through the rates of those data between the
// scene read at p ± h, p ± 2h (OutputSensitivity::parts_along / loads_along), exact for data linear in p.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "phiq/parts.hpp"

namespace phiq::detail {

// The parts and loads of the scene read at p − 2h, p − h, p + h, p + 2h (null: the efforts' own) and h.
struct ForcesAlong {
  std::array<const std::vector<Part>*, 4> parts{};
  std::array<const Loads*, 4> loads{};
  double step = 1.0;
};

// dQ/dp at (q, q̇, q̈, t) into `dq` (n entries, overwritten), `s`, `sd`, `sdd` the sensitivities of q, q̇, q̈ to p
// (the full ones: a co-moving coordinate's included). `qdd` and `sdd` may be null together (no accelerations).
// False, with `dq` unspecified, where this form does not reach: a frame (its kind, a slot's coordinate; a frame of
// expressions' components, angle, axis or an expression's coordinates), a count, an expression's presence or a
// torsional spring's coordinates that differ along p; the caller then differences Q (effort_sensitivity.cpp). A
// torsional spring's angle (an expression's or a spatial joint's) is carried with its first and second derivatives,
// exact.
bool generalized_force_rate(const std::vector<Part>& parts, const Loads& loads, const ForcesAlong& along,
                            const double* q, const double* qd, const double* qdd, const double* s, const double* sd,
                            const double* sdd, double t, Eigen::VectorXd& dq);

}  // namespace phiq::detail
