/// @file
/// Points whose motion a sweep outputs (a coupler curve, a tool tip): position, velocity and acceleration
/// evaluated exactly from q, q̇, q̈ by the kinematics of the point's kind, not by differences along the sweep.
///
/// A point kind says how its position follows from q. The planar kinds are a natural point (two slots) and a
/// point fixed on a planar body (reference point and angle, local coordinates); the spatial ones a natural point
/// (three slots) and a point fixed on a body with Euler parameters, both as an Attachment3 (X = r + R(p) s), whose
/// exact rate and q̈-free acceleration the spatial constraints use too. Motions are stored with three components;
/// the CSV writes dimension() of them.
#pragma once

#include <array>
#include <string>

#include "phiq/spatial_attachment.hpp"
#include "phiq/types.hpp"

namespace phiq {

/// How an output point's position follows from q.
enum class OutputPointKind {
  kPlanarPoint,       ///< a natural point (x, y slots): r = (x, y)
  kPlanarBodyPoint,   ///< a point fixed on a planar body: r = r_body + R(ψ) s, s in the body's frame
  kSpatialPoint,      ///< a natural point in space (x, y, z slots)
  kSpatialBodyPoint,  ///< a point fixed on a spatial body: r = r_body + R(e) s, e the body's Euler parameters
};

/// A point whose motion is output. Build with planar_point() or planar_body_point().
struct OutputPoint {
  std::string name;                                      ///< column prefix (`name.x`, `name.vx`, ...)
  OutputPointKind kind = OutputPointKind::kPlanarPoint;  ///< how its position follows from q
  Point2 point;                                          ///< kPlanarPoint: its slots
  Frame2 body;                                           ///< kPlanarBodyPoint: the body's frame
  double local_x = 0.0;                                  ///< kPlanarBodyPoint: s_x, the point in the body's frame (m)
  double local_y = 0.0;                                  ///< kPlanarBodyPoint: s_y (m)
  Attachment3 spatial;                                   ///< kSpatialPoint, kSpatialBodyPoint: the point as r + R(p) s

  /// Components of its position (2 for the planar kinds; 3 for the spatial ones).
  int dimension() const {
    return kind == OutputPointKind::kSpatialPoint || kind == OutputPointKind::kSpatialBodyPoint ? 3 : 2;
  }
  /// The largest coordinate index it reads, −1 if none (a fixed point).
  Index max_coordinate() const;
};

/// A natural point (or a fixed one, with constant slots).
OutputPoint planar_point(std::string name, Point2 p);
/// A point fixed on a planar body at s = (sx, sy) in the body's frame.
OutputPoint planar_body_point(std::string name, Frame2 body, double sx, double sy);
/// A natural point in space (or a fixed one, with constant slots).
OutputPoint spatial_point(std::string name, Point3 p);
/// A point fixed on a spatial body (position and Euler parameters) at `at` in the body's frame (m).
OutputPoint spatial_body_point(std::string name, const Frame3& body, kin3::V3 at);

/// Position, velocity and acceleration of a point; components beyond dimension() are 0, and so are the
/// derivatives not evaluated.
struct PointMotion {
  std::array<double, 3> r{};  ///< position (m)
  std::array<double, 3> v{};  ///< velocity (m/s)
  std::array<double, 3> a{};  ///< acceleration (m/s²)
};

/// The motion of `p` at (q, q̇, q̈): the position always, the velocity when qd is given, the acceleration when qd
/// and qdd are given. Exact: for a planar body point ṙ_P = ṙ + ψ̇ R'(ψ) s and r̈_P = r̈ + ψ̈ R'(ψ) s − ψ̇² R(ψ) s;
/// for a spatial one, with R(e) homogeneous quadratic in e, ṙ_P = ṙ + 2 B(e, ė) s and r̈_P = r̈ + 2 B(e, ë) s +
/// 2 R(ė) s (Attachment3::rate at q̈, plus Attachment3::bias).
/// Pre-condition: the arrays have more than p.max_coordinate() entries. Thread-safe.
PointMotion evaluate_point(const OutputPoint& p, const double* q, const double* qd, const double* qdd);

}  // namespace phiq
