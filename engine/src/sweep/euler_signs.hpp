// The sign of a parallel chunk's seed's Euler parameters. e and −e are one orientation, so both solve a spatial
// body's equations, and the seeding pass, stepping a chunk's whole span at once, reaches whichever its Newton is
// nearer: a body turning more than a quarter turn per chunk span gets a seed on −e, and the chunk, though in the
// right orientation, is refused at its seam (the sweep in order follows e continuously). Each seed is turned, body
// by body, to the sign its motion continues with, before the chunk starts from it (parallel_sweep.cpp).
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "phiq/model.hpp"

namespace phiq::detail {

// The coordinates (e0 … e3) of each body whose four Euler parameters are all coordinates, and the seeds' Euler
// parameters before the one being aligned (their times, the sign they continue with). A seed's sign is that of the
// orientation extrapolated at its time as a rotation: from the seed before it by the turn its ė and ë make over the
// span, ω Δt + α Δt²/2 (the seeding pass solves them at row 0 and at each seed) — right however many turns a body
// makes per chunk span, while that second-order turn errs by less than a half turn —; else (no rates there: a
// singular position) at constant turning rate from the two seeds before it, right while a body turns less than a
// half turn per chunk span (an extrapolation of e itself, component by component, turns the sign before a quarter
// turn), or, the first seed, with the sign the seeding pass reached. A seed is turned only where it is clearly
// opposite (euler_signs.cpp).
class EulerSeedSigns {
 public:
  explicit EulerSeedSigns(const Model& model);
  // Whether the model has a body whose sign can be wrong (else align() does nothing).
  bool empty() const { return bodies_.empty(); }
  // Row 0's position at t0, and its q̇ and q̈ (each empty where not known).
  void start(double t0, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd);
  // Turns `seed`'s Euler parameters, body by body, to the sign of the orientation extrapolated at t from the
  // seeds aligned before (seeds come in time order); its q̇ and q̈ there (each empty when not known) carry the
  // extrapolation to the next seed. Returns whether any body's were turned.
  bool align(double t, Eigen::VectorXd& seed, const Eigen::VectorXd& qd = {}, const Eigen::VectorXd& qdd = {});
  // Whether a body may turn a quarter turn or more over `span` from the last seed, by its rates there
  // (|ω| span + |α| span²/2), else by the turn between the two seeds before (|θ| span / their span): where none
  // does, the constant-rate extrapolation is right, and the next seed's rates need not be solved for align().
  bool turns_far(double span) const;
  // The largest turn (rad) a body may make over `span` from the last seed, as turns_far() bounds it; infinite with
  // nothing known (no seed yet, no rates).
  double largest_turn(double span) const;
  // Turns q's Euler parameters, body by body, to the sign of those of `reference` (same size). Returns whether any
  // body's were turned.
  bool turn_like(const double* reference, Eigen::VectorXd& q) const;

 private:
  using Quat = std::array<double, 4>;
  std::vector<std::array<Index, 4>> bodies_;
  // per body: the last two aligned seeds' (row 0's first) Euler parameters, and the last one's ė and ë
  std::vector<Quat> last_, before_, rate_, accel_;
  double t_last_ = 0.0, t_before_ = 0.0;
  int known_ = 0;          // seeds (row 0 included) in last_, before_
  bool has_rate_ = false;  // rate_ is the last seed's ė (accel_ its ë, or 0 where not known)
  // body b's rate_ and accel_ from `qd`, `qdd` (empty: unknown, 0), turned over or not (has_rate_ is the caller's)
  void keep_rates(const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd, std::size_t b, bool turned);
};

}  // namespace phiq::detail
