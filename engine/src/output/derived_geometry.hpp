// The shapes of derived parts (drawn_parts.cpp), made from the points and axes the kinds' sketch() names: links,
// pins, shafts, blocks, discs, and the polylines of belts, threads and cam profiles. Pure geometry, no model.
#pragma once

#include <optional>
#include <vector>

#include "phiq/kinds/curve.hpp"
#include "phiq/parts.hpp"
#include "phiq/shapes.hpp"

namespace phiq::derived {

/// The rotation about z by `angle` (rad).
RotationMatrix about_z(double angle);
/// A rotation whose z column is `u` (normalised; u ≠ 0); x and y complete it, right-handed.
RotationMatrix z_along(kin3::V3 u);
/// a · b, two rotations composed.
RotationMatrix compose(const RotationMatrix& a, const RotationMatrix& b);
/// Rᵀ (x − at): the point of the world `x` in the frame `pose`.
kin3::V3 to_local(const Pose& pose, kin3::V3 x);
/// R v: a direction of the frame `pose` in the world.
kin3::V3 turn(const Pose& pose, kin3::V3 v);

/// A capsule of `radius` whose axis runs from a to b (none when they coincide).
std::optional<Shape> capsule(kin3::V3 a, kin3::V3 b, double radius);
/// A cylinder of `radius` and `length` centred at `at`, its axis along `axis`.
Shape cylinder(kin3::V3 at, kin3::V3 axis, double radius, double length);
/// A box of edge lengths `size` centred at `at`, its edges along the columns of `rotation`.
Shape box(kin3::V3 at, const RotationMatrix& rotation, kin3::V3 size);
/// A sphere of `radius` about `at`.
Shape sphere(kin3::V3 at, double radius);
/// A polyline drawn with width `width`.
Shape polyline(std::vector<kin3::V3> points, bool closed, double width);

/// The path of a belt around two pulleys, pulley 1 of radius r1 about the origin and pulley 2 of radius r2 about
/// (d, 0): open (the outer tangents, r1 − r2 < d) or crossed (the inner ones, r1 + r2 < d), and the arcs it wraps;
/// closed, the arcs sampled at most `step` radians apart. Its exact length is
///   open: 2 √(d² − (r1 − r2)²) + π (r1 + r2) + 2 (r1 − r2) asin((r1 − r2)/d),
///   crossed: 2 √(d² − (r1 + r2)²) + (r1 + r2) (π + 2 asin((r1 + r2)/d)).
std::vector<kin3::V3> belt_path(double d, double r1, double r2, bool crossed, double step);

/// A helix about the axis through `at` along `axis` (unit), starting from the direction `ref` (⟂ axis, unit): radius
/// `radius`, lead `pitch` per turn (right-handed about `axis` for pitch > 0), `turns` turns centred on `at`,
/// `per_turn` points a turn.
std::vector<kin3::V3> helix(kin3::V3 at, kin3::V3 axis, kin3::V3 ref, double radius, double pitch, int turns,
                            int per_turn);

/// `count` points of a curve at equal steps of its parameter (a closed curve's last before its first again; an open
/// curve's from its start to its end, count + 1 of them).
std::vector<kin3::V3> curve_samples(const Curve& curve, int count);

}  // namespace phiq::derived
