// LimitWatch and check_limits() (sweep/limit_watch.hpp).
#include "sweep/limit_watch.hpp"

#include <cmath>

#include "phiq/expression.hpp"
#include "phiq/model.hpp"
#include "phiq/text.hpp"

namespace phiq::detail {

LimitWatch::LimitWatch(const std::vector<OutputLimit>& limits)
    : limits_(limits), stretch_(limits.size()), angle_(limits.size(), 0.0), angle_rate_(limits.size(), 0.0) {}

void LimitWatch::row(double t, const double* q, const double* qd, const double* efforts) {
  for (std::size_t i = 0; i < limits_.size(); ++i) {
    const OutputLimit& l = limits_[i];
    double v = 0.0;
    if (l.of) {
      if (l.rate) {
        thread_local std::vector<double> g;  // (capacity kept from row to row)
        const std::vector<Index>& c = l.of->coordinates();
        g.resize(c.size());
        l.of->gradient(q, t, g.data());
        v = l.of->partial_t(q, t);
        for (std::size_t j = 0; j < c.size(); ++j) v += g[j] * qd[c[j]];
      } else {
        v = l.of->value(q, t);
      }
    } else if (l.joint) {
      const JointMotion m = evaluate_joint(*l.joint, q, qd, nullptr);
      v = l.rate ? m.rate : m.value;
      if (!l.rate && l.joint->measure == JointMeasure::kAngle) {
        // over turns, as the joints' outputs are: the 2π-multiple nearest to the last row's plus the rates' trapezoid
        if (!first_) v = unwrap_angle(v, angle_[i], 0.5 * (angle_rate_[i] + m.rate) * (t - last_t_));
        angle_[i] = v, angle_rate_[i] = m.rate;
      }
    } else if (l.point) {
      const PointMotion m = evaluate_point(*l.point, q, l.rate ? qd : nullptr, nullptr);
      v = (l.rate ? m.v : m.r)[static_cast<std::size_t>(l.axis)];
    } else {
      if (!efforts) continue;  // (a row not written: no effort computed)
      v = efforts[l.effort];
      if (!std::isfinite(v)) continue;  // (at a singular position: said by its own warning)
    }
    Stretch& s = stretch_[i];
    const bool above = v > l.hi, outside = above || v < l.lo;
    if (s.open && (!outside || above != s.above)) close(i);
    if (!outside) continue;
    if (!s.open) s = Stretch{true, above, 0, t, t, v, t};
    ++s.rows, s.to = t;
    if (above ? v > s.worst : v < s.worst) s.worst = v, s.worst_t = t;
  }
  first_ = false, last_t_ = t;
}

std::string LimitWatch::outside_text(std::size_t i) const {
  const Stretch& s = stretch_[i];
  const OutputLimit& l = limits_[i];
  return l.name + ": " + l.what + " is " +
         (s.above ? "above its maximum " + significant(l.hi, 10) : "below its minimum " + significant(l.lo, 10));
}

void LimitWatch::close(std::size_t i) {
  Stretch& s = stretch_[i];
  std::string where = s.rows == 1 ? "at t = " + format_time(s.from)
                                  : "from t = " + format_time(s.from) + " to t = " + format_time(s.to) + " (" +
                                        std::to_string(s.rows) + " rows)";
  found_.push_back({s.from, "limit",
                    outside_text(i) + " " + where + ", " + (s.above ? "at most " : "at least ") +
                        significant(s.worst, 10) + (s.rows == 1 ? "" : " (t = " + format_time(s.worst_t) + ")")});
  s.open = false;
}

SweepWarning LimitWatch::beginning(std::size_t i) const {
  const Stretch& s = stretch_[i];
  return {s.from, "limit", outside_text(i) + " from t = " + format_time(s.from) + ": " + significant(s.worst, 10)};
}

void LimitWatch::finish(std::vector<SweepWarning>& warnings) {
  for (std::size_t i = 0; i < stretch_.size(); ++i)
    if (stretch_[i].open) close(i);
  std::stable_sort(found_.begin(), found_.end(),
                   [](const SweepWarning& a, const SweepWarning& b) { return a.t < b.t; });
  warnings.insert(warnings.end(), found_.begin(), found_.end());
  found_.clear();
}

void check_limits(const Model& model, const OutputPlan& plan, const std::string& who) {
  for (const OutputLimit& l : plan.limits) {
    const std::string at = who + ": limit '" + l.name + "': ";
    if (!(l.lo < l.hi)) throw Error(at + "its range [lo, hi] needs lo < hi");
    if (l.rate && !plan.solves_velocities()) throw Error(at + "it bounds a rate: the sweep must solve velocities");
    if (l.of) {
      for (Index c : l.of->coordinates())
        if (c >= model.num_coordinates()) throw Error(at + "it reads a coordinate the model does not have");
      if (!l.of->rate_coordinates().empty()) throw Error(at + "its expression reads rates (der())");
    } else if (l.joint) {
      if (l.joint->max_coordinate() >= model.num_coordinates())
        throw Error(at + "its joint reads a coordinate the model does not have");
    } else if (l.point) {
      if (l.point->max_coordinate() >= model.num_coordinates() || l.axis < 0 || l.axis >= l.point->dimension())
        throw Error(at + "its point reads a coordinate the model does not have, or has no such axis");
    } else if (l.rate || l.effort < 0 || l.effort >= static_cast<Index>(plan.efforts.constraints.size())) {
      throw Error(at + "its effort is not one the sweep computes (OutputEfforts::constraints)");
    }
  }
}

}  // namespace phiq::detail
