// The nfourbar model of the benchmarks, built in code (shared by phiq_bench and phiq_bench_peers so that both time
// the very same phiq model).
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "phiq/phiq.hpp"

namespace phiq_bench {

// "prefix" + i, appended rather than concatenated: GCC 12 warns falsely (-Wrestrict, PR 105329) on
// "literal" + std::string temporaries.
inline std::string indexed(const char* prefix, phiq::Index i) {
  std::string s(prefix);
  s += std::to_string(i);
  return s;
}

// IFToMM-style N four-bar in natural coordinates: cranks of length 1 pinned at (i, 0), i = 0..N, tips P_i joined by
// N couplers of length 1; crank 0 carries the angle coordinate theta that is driven. Starts on the parallelogram
// solution P_i = (i + cos θ, sin θ). 2N + 3 coordinates: x0, y0, x1, y1, …, xN, yN, θ.
//
// braced: also bars of length 2 from P_i to P_{i+2} (i = 0..N−2). On the parallelogram motion they always hold, and
// each is the sum of the two couplers it spans to first order: N − 1 consistent redundant equations (rank analysis
// and the square solve through redundancy at scale, bench_redundancy.cpp).
inline phiq::Model nfourbar(phiq::Index n, double theta0, double rate,
                            phiq::LinearSolverKind kind = phiq::LinearSolverKind::kKlu, bool braced = false) {
  using namespace phiq;
  ModelBuilder b;
  b.set_linear_solver(kind);
  auto S = Slot::coordinate;
  auto C = Slot::constant;
  std::vector<Point2> tip;
  for (Index i = 0; i <= n; ++i) {
    Index x = b.add_coordinate(indexed("x", i), static_cast<double>(i) + std::cos(theta0));
    Index y = b.add_coordinate(indexed("y", i), std::sin(theta0));
    tip.push_back({S(x), S(y)});
  }
  Index th = b.add_coordinate("theta", theta0);
  for (Index i = 0; i <= n; ++i)
    b.add(indexed("crank", i), DistanceSpec{{C(static_cast<double>(i)), C(0)}, tip[i], 1.0});
  for (Index i = 0; i < n; ++i) b.add(indexed("coupler", i), DistanceSpec{tip[i], tip[i + 1], 1.0});
  if (braced)
    for (Index i = 0; i + 2 <= n; ++i) b.add(indexed("brace", i), DistanceSpec{tip[i], tip[i + 2], 2.0});
  b.add("crank0_angle", SegmentAngleSpec{{C(0), C(0)}, tip[0], S(th)});
  b.add_driver("motor", th, MotionLaw::linear(theta0, rate));
  return std::move(b).build();
}

}  // namespace phiq_bench
