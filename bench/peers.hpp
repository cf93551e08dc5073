// The peers of phiq_bench_peers (bench_peers.cpp): the same nfourbar drive, solved by other programs.
//
// The workload, shared by every peer: nfourbar N (N + 1 unit cranks pinned at (i, 0), tips joined by N unit
// couplers), crank 0 driven at θ(t) = π/4 + (π/2) t, time step h = 1/50 s (a quarter turn in 50 steps, as in
// phiq_bench's BM_NFourBarSweepStep). Each drive step: positions to the tolerance, then velocities, then
// accelerations. The exact solution is the parallelogram P_i = (i + cos θ, sin θ), against which every peer is checked.
//
// This header is included by translation units compiled with and without NDEBUG (peer_simbody.cpp must be compiled
// without it, see bench/CMakeLists.txt), so it holds only plain declarations: no Eigen, no Simbody.
#pragma once

#include <algorithm>
#include <cmath>
#include <memory>

namespace phiq_bench {

inline constexpr double kTheta0 = M_PI / 4;            // θ(0), rad
inline constexpr double kRate = M_PI / 2;              // θ̇, rad/s
inline constexpr int kStepsPerSweep = 50;              // a quarter turn
inline constexpr double kStep = 1.0 / kStepsPerSweep;  // h, s
inline constexpr double kTolerance = 1e-10;            // positions (and Simbody's velocities), metres / max norm
inline constexpr double kCheckTolerance = 1e-8;        // a peer whose tips leave the exact solution by more fails

inline double theta_at(double t) { return kTheta0 + kRate * t; }

// Where each drive step's Newton iteration (Simbody: projection) starts. The benchmark argument `pred`.
enum class Start {
  kPrevious = 0,   // the previous step's solution: the classic course approach (phiq: Predictor::kPrevious)
  kQuadratic = 1,  // q + h q̇ + h²/2 q̈ from the previous step (phiq's default with velocities and accelerations)
};

// Largest deviation of crank tips (and, where a peer checks them, other points) from the exact solution.
struct Deviation {
  double position = 0.0, velocity = 0.0, acceleration = 0.0;
  void merge(const Deviation& o) {
    position = std::max(position, o.position);
    velocity = std::max(velocity, o.velocity);
    acceleration = std::max(acceleration, o.acceleration);
  }
  double worst() const { return std::max({position, velocity, acceleration}); }
};

// Exact tip i at time t: position, velocity and acceleration of P_i = (i + cos θ, sin θ) with θ̈ = 0.
struct ExactTip {
  double x, y, vx, vy, ax, ay;
};
inline ExactTip exact_tip(int i, double t) {
  const double th = theta_at(t), c = std::cos(th), s = std::sin(th), w = kRate;
  return {i + c, s, -w * s, w * c, -w * w * c, -w * w * s};
}

// Simbody (libsimbody-dev): the chain crank 0 – coupler 0 – crank 1 – coupler 1 – … – crank N as 2N + 1 pin
// mobilizers (crank 0 pinned to ground at the origin), each crank i ≥ 1 closed onto its ground pivot (i, 0) by a
// Constraint::PointOnLine (the pivot's line along z: the two planar equations), crank 0's angle prescribed by a
// Motion. Defined in peer_simbody.cpp (compiled without NDEBUG); available when PHIQ_HAVE_SIMBODY is defined.
class SimbodyNFourBar {
 public:
  SimbodyNFourBar(int n, Start start);
  ~SimbodyNFourBar();
  SimbodyNFourBar(const SimbodyNFourBar&) = delete;
  SimbodyNFourBar& operator=(const SimbodyNFourBar&) = delete;
  // Back to t = 0 on the exact solution, velocities and accelerations realised (row 0, not a drive step).
  void reset();
  // One drive step to time t: start (the previous q, or q + h u + h²/2 u̇), prescribe q, projectQ, prescribe u,
  // projectU (both to kTolerance in the max norm), realise accelerations. Throws std::runtime_error when a
  // projection fails. Note: in Simbody's joint angles this parallelogram moves linearly in t (±θ(t)), so the
  // quadratic start is already exact and the projections then have nothing to do.
  void step(double t);
  // Against the exact solution at the current time: crank tips and crank pivots (position), tips (velocity,
  // acceleration).
  Deviation deviation() const;
  long long projection_iterations() const;  // projectQ Newton iterations since construction
  double acceleration_seconds() const;      // thread CPU time spent realising accelerations (s), drive steps only
  int mobilities() const;                   // 2N + 1
  int constraint_equations() const;         // 2N

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace phiq_bench
