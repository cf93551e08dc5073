// Internal to the engine: the C² cubic spline through values p_k at parameter steps h_k, open (natural ends,
// M = 0) or closed (cyclic), its pieces' coefficients: a closed or open Curve's (curve.cpp, values points in the
// plane) and a periodic motion law's (motion_law.cpp, values numbers).
#pragma once

#include <Eigen/SparseLU>
#include <vector>

#include "phiq/types.hpp"

namespace phiq::detail {

inline int spline_dimension(double) { return 1; }
inline int spline_dimension(const kin::V2&) { return 2; }
inline double spline_component(double v, int) { return v; }
inline double spline_component(const kin::V2& v, int i) { return i == 0 ? v.x : v.y; }
inline void spline_set(double& v, const Eigen::MatrixXd& m, Eigen::Index row) { v = m(row, 0); }
inline void spline_set(kin::V2& v, const Eigen::MatrixXd& m, Eigen::Index row) { v = {m(row, 0), m(row, 1)}; }

// Piece k is a + b s + c s² + d s³, s from 0 to h_k.
template <class P>
struct CubicPieces {
  std::vector<P> a, b, c, d;
};

// The spline through p (n values) with steps h (n − 1 pieces open; n closed, piece n − 1 from p_{n−1} back to p_0).
// Pre-condition: every h_k > 0, n ≥ 2 (closed: n ≥ 2 pieces). Second derivatives M_k at the points:
// h_{k−1} M_{k−1} + 2 (h_{k−1} + h_k) M_k + h_k M_{k+1} = 6 (slope_k − slope_{k−1}) at every inner point (every
// point of a closed spline, indices cyclic), M = 0 at open ends; strictly diagonally dominant: always factorises.
template <class P>
CubicPieces<P> cubic_spline(const std::vector<P>& p, const std::vector<double>& h, bool closed) {
  const std::size_t n = p.size(), pieces = h.size();
  const int dims = spline_dimension(p.front());
  const Eigen::Index m = static_cast<Eigen::Index>(n);
  std::vector<Eigen::Triplet<double>> t;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(m, dims);
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Index i = static_cast<Eigen::Index>(k);
    if (!closed && (k == 0 || k == n - 1)) {
      t.emplace_back(i, i, 1.0);
      continue;
    }
    const std::size_t km = (k + n - 1) % n, kp = (k + 1) % n;
    const double hm = h[(k + pieces - 1) % pieces], hk = h[k % pieces];
    t.emplace_back(i, static_cast<Eigen::Index>(km), hm);
    t.emplace_back(i, i, 2.0 * (hm + hk));
    t.emplace_back(i, static_cast<Eigen::Index>(kp), hk);
    const P slope = (1.0 / hk) * (p[kp] - p[k]), before = (1.0 / hm) * (p[k] - p[km]);
    for (int d = 0; d < dims; ++d) rhs(i, d) = 6.0 * (spline_component(slope, d) - spline_component(before, d));
  }
  Eigen::SparseMatrix<double> a(m, m);
  a.setFromTriplets(t.begin(), t.end());
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(a);
  const Eigen::MatrixXd mm = lu.solve(rhs);
  CubicPieces<P> out;
  for (std::size_t k = 0; k < pieces; ++k) {
    const std::size_t kp = (k + 1) % n;
    P m0, m1;
    spline_set(m0, mm, static_cast<Eigen::Index>(k)), spline_set(m1, mm, static_cast<Eigen::Index>(kp));
    const double hk = h[k];
    out.a.push_back(p[k]);
    out.b.push_back((1.0 / hk) * (p[kp] - p[k]) - (hk / 6.0) * (2.0 * m0 + m1));
    out.c.push_back(0.5 * m0);
    out.d.push_back((1.0 / (6.0 * hk)) * (m1 - m0));
  }
  return out;
}

}  // namespace phiq::detail
