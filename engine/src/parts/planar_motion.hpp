// Internal: the motion of a planar frame in closed form, as scalars: what part_motion() returns for it
// (part_motion.cpp) and what inverse dynamics reads of it for every part at every row (inverse_dynamics.cpp),
// without the 3×3 rotations and cross products with vectors along z, whose terms are zeros.
#pragma once

#include <cmath>

#include "phiq/parts.hpp"

namespace phiq::detail {

// A planar frame's slots: a body's x, y, ψ; or an origin's x, y, z and x's target's (a point or a vector) x, y.
struct PlanarFrame {
  Slot slots[5];
  bool body = false, x_is_point = true;
  // A rigid bar's: its force is given at its two points (the origin's share and x's, the constant mass matrix of
  // solve/part_forces.hpp), which add_planar_force() adds as they are. planar_motion() does not read it.
  bool bar = false;
};

// `f`'s slots into `out`; false for the other frames.
inline bool planar_frame(const PartFrame& f, PlanarFrame& out) {
  if (f.kind == PartFrameKind::kPlanarBody) {
    out.slots[0] = f.planar.x, out.slots[1] = f.planar.y, out.slots[2] = f.planar.psi, out.body = true;
    return true;
  }
  if (f.kind != PartFrameKind::kPoints || f.spatial_frame) return false;
  for (int k = 0; k < 3; ++k) out.slots[k] = f.origin.r[k];
  out.slots[3] = f.x_toward.r[0], out.slots[4] = f.x_toward.r[1];
  out.body = false, out.x_is_point = f.x_is_point;
  return true;
}

// A planar frame at (q, q̇, q̈): its origin with its velocity and acceleration, the cosine and sine of its angle θ,
// θ̇ and θ̈; for a frame of points also d, x's direction from the origin, and |d|².
struct PlanarMotion {
  kin3::V3 at, velocity, acceleration;
  double cos = 1.0, sin = 0.0, omega = 0.0, alpha = 0.0;
  double dx = 0.0, dy = 0.0, d2 = 0.0;
};

// A body's (x, y, ψ), or an origin point and an x direction (θ its angle: ω = (d × ḋ)/|d|², α = (d × d̈)/|d|² −
// 2 (d · ḋ)(d × ḋ)/|d|⁴). `qd` not null; `qdd` may be null (accelerations 0). False for a direction of zero length
// (the jets' and part_pose()'s NaN). Always inlined: called out of line, its PlanarMotion was zeroed, written and
// read back through memory, half of the time a sweep's efforts spent in Q (bench/bench_efforts.cpp).
[[gnu::always_inline]] inline bool planar_motion(const PlanarFrame& f, const double* q, const double* qd,
                                                 const double* qdd, PlanarMotion& m) {
  auto rate = [&](const Slot& s) { return s.is_coordinate() ? qd[s.coord()] : 0.0; };
  auto accel = [&](const Slot& s) { return s.is_coordinate() && qdd ? qdd[s.coord()] : 0.0; };
  const Slot* o = f.slots;
  if (f.body) {
    m.at = {o[0].of(q), o[1].of(q), 0.0};
    m.velocity = {rate(o[0]), rate(o[1]), 0.0}, m.acceleration = {accel(o[0]), accel(o[1]), 0.0};
    const double psi = o[2].of(q);
    m.cos = std::cos(psi), m.sin = std::sin(psi), m.omega = rate(o[2]), m.alpha = accel(o[2]);
    return true;
  }
  const Slot* x = f.slots + 3;
  m.at = {o[0].of(q), o[1].of(q), o[2].of(q)};
  m.velocity = {rate(o[0]), rate(o[1]), rate(o[2])}, m.acceleration = {accel(o[0]), accel(o[1]), accel(o[2])};
  double dx = x[0].of(q), dy = x[1].of(q), vx = rate(x[0]), vy = rate(x[1]), ax = accel(x[0]), ay = accel(x[1]);
  if (f.x_is_point) {
    dx -= m.at.x, dy -= m.at.y, vx -= m.velocity.x, vy -= m.velocity.y;
    ax -= m.acceleration.x, ay -= m.acceleration.y;
  }
  const double d2 = dx * dx + dy * dy, n = std::sqrt(d2), turn = dx * vy - dy * vx;
  if (!(n > 0.0)) return false;
  m.cos = (1.0 / n) * dx, m.sin = (1.0 / n) * dy, m.omega = turn / d2;  // the axes as part_pose() rounds them
  m.alpha = (dx * ay - dy * ax) / d2 - 2.0 * (dx * vx + dy * vy) * turn / (d2 * d2);
  m.dx = dx, m.dy = dy, m.d2 = d2;
  return true;
}

}  // namespace phiq::detail
