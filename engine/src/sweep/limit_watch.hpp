// Internal to the engine: the limits a sweep checks (OutputPlan::limits), row by row in delivery order, each
// stretch of rows outside its range said once, as a `limit` warning, when the stretch ends.
#pragma once

#include <string>
#include <vector>

#include "phiq/output_plan.hpp"
#include "phiq/sweep.hpp"

namespace phiq::detail {

class LimitWatch {
 public:
  explicit LimitWatch(const std::vector<OutputLimit>& limits);
  // The row at t, delivered in order: q always, qd null when q̇ is not solved, efforts null where not computed (a row
  // not written). Pre-condition: the limits read coordinates the model has and efforts it computes (check_limits).
  void row(double t, const double* q, const double* qd, const double* efforts);
  // The stretches still open at the last row delivered, said; then the warnings, in the order their stretches
  // began, appended to `warnings`.
  void finish(std::vector<SweepWarning>& warnings);
  // Whether limit i's value was outside its range at the last row, and whether its stretch began there.
  bool outside(std::size_t i) const { return stretch_[i].open; }
  bool began(std::size_t i) const { return stretch_[i].open && stretch_[i].rows == 1; }
  // What a stretch that began at the last row says there, with the value there (a Stepper's: its steps have no
  // last row to wait for).
  SweepWarning beginning(std::size_t i) const;

 private:
  struct Stretch {
    bool open = false, above = false;
    Index rows = 0;
    double from = 0.0, to = 0.0, worst = 0.0, worst_t = 0.0;
  };
  void close(std::size_t i);
  std::string outside_text(std::size_t i) const;  // "NAME: WHAT is above its maximum HI" (or below its minimum)

  const std::vector<OutputLimit>& limits_;
  std::vector<Stretch> stretch_;
  std::vector<double> angle_, angle_rate_;  // a joint's unwrapped angle and its rate at the last row
  bool first_ = true;
  double last_t_ = 0.0;
  std::vector<SweepWarning> found_;
};

// Throws phiq::Error naming the limit for one the model or the plan cannot check: a coordinate the model does not
// have, an effort not computed, a rate without q̇, an empty range.
void check_limits(const Model& model, const OutputPlan& plan, const std::string& who);

}  // namespace phiq::detail
