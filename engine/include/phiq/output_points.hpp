/// @file
/// Points whose motion a sweep outputs (a coupler curve, a tool tip): position, velocity and acceleration
/// evaluated exactly from q, q̇, q̈ by the kinematics of the point's kind, not by differences along the sweep.
///
/// A point kind says how its position follows from q. The planar kinds are a natural point (two slots) and a
/// point fixed on a planar body (reference point and angle, local coordinates). Motions are stored with three
/// components so that a spatial kind (a point on a body with Euler parameters) can be added as another kind
/// without changing the storage, the sweep or the CSV code that reads dimension().
#pragma once

#include <array>
#include <string>

#include "phiq/types.hpp"

namespace phiq {

/// How an output point's position follows from q.
enum class OutputPointKind {
  kPlanarPoint,      ///< a natural point (x, y slots): r = (x, y)
  kPlanarBodyPoint,  ///< a point fixed on a planar body: r = r_body + R(ψ) s, s in the body's frame
};

/// A point whose motion is output. Build with planar_point() or planar_body_point().
struct OutputPoint {
  std::string name;  ///< column prefix (`name.x`, `name.vx`, ...)
  OutputPointKind kind = OutputPointKind::kPlanarPoint;  ///< how its position follows from q
  Point2 point;      ///< kPlanarPoint: its slots
  Frame2 body;       ///< kPlanarBodyPoint: the body's frame
  double local_x = 0.0;  ///< kPlanarBodyPoint: s_x, the point in the body's frame (m)
  double local_y = 0.0;  ///< kPlanarBodyPoint: s_y (m)

  /// Components of its position (2 for the planar kinds; 3 for a spatial kind).
  int dimension() const { return 2; }
  /// The largest coordinate index it reads, −1 if none (a fixed point).
  Index max_coordinate() const;
};

/// A natural point (or a fixed one, with constant slots).
OutputPoint planar_point(std::string name, Point2 p);
/// A point fixed on a planar body at s = (sx, sy) in the body's frame.
OutputPoint planar_body_point(std::string name, Frame2 body, double sx, double sy);

/// Position, velocity and acceleration of a point; components beyond dimension() are 0, and so are the
/// derivatives not evaluated.
struct PointMotion {
  std::array<double, 3> r{};  ///< position (m)
  std::array<double, 3> v{};  ///< velocity (m/s)
  std::array<double, 3> a{};  ///< acceleration (m/s²)
};

/// The motion of `p` at (q, q̇, q̈): the position always, the velocity when qd is given, the acceleration when qd
/// and qdd are given. Exact: for a body point ṙ_P = ṙ + ψ̇ R'(ψ) s and r̈_P = r̈ + ψ̈ R'(ψ) s − ψ̇² R(ψ) s.
/// Pre-condition: the arrays have more than p.max_coordinate() entries. Thread-safe.
PointMotion evaluate_point(const OutputPoint& p, const double* q, const double* qd, const double* qdd);

}  // namespace phiq
