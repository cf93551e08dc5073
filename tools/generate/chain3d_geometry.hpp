// The fixed geometry of `phiq generate chain3d` (tools/README.md), shared by the generator
// (generate_chain3d.cpp) and its closed form (closed_forms.cpp, `closed-form:chain3d`).
//
// Every crank turns about the same hinge axis u, deliberately not a coordinate axis, so that no row of the model
// is aligned with x, y or z. A crank's angle θ is measured about u from e1 = d towards e2 = u × d, with d ⟂ u: the
// crank points along c(θ) = cos θ e1 + sin θ e2. The parallelogram row has its pivots along d (O_i = i d); the
// twisted row (--twist) along u (O_i = i u). A body whose x axis is c(θ) and whose z axis is u (a crank body of the
// reference-point scenes) has the Euler parameters p(θ) = cos(θ/2) qa + sin(θ/2) qb, where qa are those of the
// frame [e1, e2, u] (θ = 0) and qb = (0, u) ⊗ qa (a turn about u after it: (cos θ/2, u sin θ/2) ⊗ qa).
#pragma once

#include <Eigen/Geometry>

#include <array>
#include <cmath>

namespace phiq::tools::chain3d {

using Vec = std::array<double, 3>;
using Quat = std::array<double, 4>;  // e0 (the scalar part), e1, e2, e3

struct Geometry {
  Vec u, e1, e2;  // the hinge axis, d, u × d
  Quat qa, qb;    // p(θ) = cos(θ/2) qa + sin(θ/2) qb
};

inline Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// u = (1, 2, 2)/3 and d = (2, 1, −2)/3 (u · d = 0), with e2 and the Euler parameters derived from them.
inline Geometry geometry() {
  Geometry g;
  g.u = {1.0 / 3, 2.0 / 3, 2.0 / 3};
  g.e1 = {2.0 / 3, 1.0 / 3, -2.0 / 3};
  g.e2 = cross(g.u, g.e1);
  // The Euler parameters of the rotation with columns e1, e2, u (Eigen's conversion), then qb = (0, u) ⊗ qa.
  Eigen::Matrix3d r;
  r << g.e1[0], g.e2[0], g.u[0], g.e1[1], g.e2[1], g.u[1], g.e1[2], g.e2[2], g.u[2];
  const Eigen::Quaterniond a(r), b = Eigen::Quaterniond(0.0, g.u[0], g.u[1], g.u[2]) * a;
  g.qa = {a.w(), a.x(), a.y(), a.z()};
  g.qb = {b.w(), b.x(), b.y(), b.z()};
  return g;
}

// Length of the couplers: 1 for the parallelogram row (twist 0: each coupler parallel to d); for the twisted row,
// whose neighbouring cranks differ by the phase `twist` about the common axis one unit apart,
// √(1 + |c(θ + twist) − c(θ)|²) = √(3 − 2 cos twist).
inline double coupler_length(double twist) { return twist == 0.0 ? 1.0 : std::sqrt(3.0 - 2.0 * std::cos(twist)); }

}  // namespace phiq::tools::chain3d
