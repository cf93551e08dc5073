// clearance_along() (phiq/clearance.hpp): each pair's distance at the rows, its minima refined where the distance's
// rate n · (v_B − v_A) changes sign, the interference intervals' ends where the distance changes sign, and the steps
// between rows proven clear by the parts' speeds (subdivided where the bound is too weak).
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "clearance/clearance_internal.hpp"
#include "phiq/part_motion.hpp"
#include "phiq/stepper.hpp"
#include "phiq/text.hpp"
#include "phiq/types.hpp"

namespace phiq {

bool ClearanceReport::interferes() const {
  for (const PairClearance& p : pairs)
    if (!p.interference.empty()) return true;
  return false;
}

bool ClearanceReport::bound_held() const {
  for (const PairClearance& p : pairs)
    if (p.unproven_intervals > 0) return false;
  return true;
}

namespace {

// A part at one time: its frame's pose and motion, and bounds on the speed and acceleration of any of its points.
struct PartState {
  PartMotion motion;
  double speed = 0.0;  // |v| + |ω| R
  double accel = 0.0;  // |a| + |α| R + |ω|² R
};

PartState part_state(const Part& part, double radius, const double* q, const double* qd, const double* qdd, double t) {
  PartState s;
  s.motion = part_motion(part.frame, q, qd, qdd, t);
  const double w = norm(s.motion.omega);
  s.speed = norm(s.motion.velocity) + w * radius;
  s.accel = norm(s.motion.acceleration) + norm(s.motion.alpha) * radius + w * w * radius;
  return s;
}

// The velocity of the world point x carried by the part.
kin3::V3 velocity_at(const PartMotion& m, kin3::V3 x) { return m.velocity + cross(m.omega, x - m.pose.at); }

// A pair at one time: the distance, its rate, and both parts' states.
struct Sample {
  double t = 0.0;
  PairDistance d;
  double rate = 0.0;
  PartState a, b;
};

// Over a step of length h from one sample to the next, the distance falls at most by the parts' speed bounds (each
// grown by its acceleration over the step): the least it can reach between them.
double lower_bound(const Sample& s0, const Sample& s1) {
  const double h = s1.t - s0.t;
  const double speed = std::max(s0.a.speed + s0.a.accel * h, s1.a.speed + s1.a.accel * h) +
                       std::max(s0.b.speed + s0.b.accel * h, s1.b.speed + s1.b.accel * h);
  return 0.5 * (s0.d.distance + s1.d.distance - speed * h);
}

// Solves positions between rows (a Stepper restarted from the row before, extrapolated) and measures pairs there.
class Tracer {
 public:
  Tracer(const Model& model, const std::vector<Part>& parts, const ClearanceGeometry& geometry,
         const ClearanceRows& rows, const ClearanceOptions& options)
      : parts_(parts), geometry_(geometry), rows_(rows), stepper_(model, stepper_options(options)) {}

  static StepperOptions stepper_options(const ClearanceOptions& o) {
    StepperOptions s;
    static_cast<SolverSettings&>(s) = o.solver;
    s.velocities = s.accelerations = true;
    return s;
  }

  Index solved() const { return solved_; }

  // The pair at row k.
  Sample at_row(Index a, Index b, std::size_t k) const {
    return measure(a, b, rows_.t[k], rows_.q[k].data(), rows_.qd[k].data(), rows_.qdd[k].data());
  }

  // The pair at time t, between rows.
  Sample at_time(Index a, Index b, double t) {
    solve(t);
    return measure(a, b, t, stepper_.q().data(), stepper_.qd().data(), stepper_.qdd().data());
  }

  // q at time t (solved from the row at or before it); the positions stay in the stepper.
  const Eigen::VectorXd& solve(double t) {
    if (stepper_.started() && stepper_.time() == t) return stepper_.q();
    auto k = static_cast<std::size_t>(std::upper_bound(rows_.t.begin(), rows_.t.end(), t) - rows_.t.begin());
    k = k == 0 ? 0 : k - 1;
    const double tau = t - rows_.t[k];
    stepper_.restart(rows_.q[k] + tau * rows_.qd[k] + 0.5 * tau * tau * rows_.qdd[k]);
    StepSummary summary;
    if (stepper_.step(t, &summary) != SolveStatus::kSuccess)
      throw Error("clearance: t = " + format_time(t) +
                  ": the position between rows cannot be solved: " + summary.message);
    ++solved_;
    return stepper_.q();
  }

 private:
  Sample measure(Index a, Index b, double t, const double* q, const double* qd, const double* qdd) const {
    Sample s;
    s.t = t;
    s.a = part_state(parts_[static_cast<std::size_t>(a)], geometry_.bounding_radius(a), q, qd, qdd, t);
    s.b = part_state(parts_[static_cast<std::size_t>(b)], geometry_.bounding_radius(b), q, qd, qdd, t);
    s.d = geometry_.distance(a, s.a.motion.pose, b, s.b.motion.pose);
    s.rate = dot(s.d.normal, velocity_at(s.b.motion, s.d.point_b) - velocity_at(s.a.motion, s.d.point_a));
    return s;
  }

  const std::vector<Part>& parts_;
  const ClearanceGeometry& geometry_;
  const ClearanceRows& rows_;
  Stepper stepper_;
  Index solved_ = 0;
};

// A root of f(t) = value(sample) in [lo, hi], whose values have opposite signs, by the Illinois method (regula
// falsi that halves the weight of a stale end), to `tol` in t. Returns the last sample evaluated nearest the root.
template <class Eval, class Value>
Sample root_between(Sample lo, Sample hi, double tol, Eval eval, Value value) {
  double flo = value(lo), fhi = value(hi);
  int side = 0;
  Sample best = std::abs(flo) < std::abs(fhi) ? lo : hi;
  for (int it = 0; it < 200 && hi.t - lo.t > tol; ++it) {
    double t = (lo.t * fhi - hi.t * flo) / (fhi - flo);
    // keep clear of the ends, and bisect when the secant stalls
    const double margin = 0.01 * (hi.t - lo.t);
    if (!(t > lo.t + margin && t < hi.t - margin) || it % 4 == 3) t = 0.5 * (lo.t + hi.t);
    const Sample s = eval(t);
    const double f = value(s);
    if (std::abs(f) <= std::abs(value(best))) best = s;
    if (f == 0.0) return s;
    if ((f < 0) == (flo < 0)) {
      lo = s, flo = f;
      if (side == -1) fhi *= 0.5;
      side = -1;
    } else {
      hi = s, fhi = f;
      if (side == 1) flo *= 0.5;
      side = 1;
    }
  }
  return best;
}

// One pair over the sweep.
class PairPass {
 public:
  PairPass(Tracer& tracer, const ClearanceRows& rows, const ClearanceOptions& options, double threshold, Index a,
           Index b)
      : tracer_(tracer), rows_(rows), options_(options), threshold_(threshold), a_(a), b_(b) {}

  // The pair over the sweep; nothing when `beyond_threshold_only` and the rows and the speed bound between them
  // prove it farther than the threshold at every time (what `pairs: all` does not report).
  std::optional<PairClearance> run(bool beyond_threshold_only) {
    PairClearance out;
    out.a = a_, out.b = b_;
    const std::size_t n = rows_.t.size();
    for (std::size_t k = 0; k < n; ++k) samples_.push_back(tracer_.at_row(a_, b_, k));
    if (beyond_threshold_only && proven_beyond_threshold()) return std::nullopt;
    for (const Sample& s : samples_) out.row_distance.push_back(s.d.distance);
    std::vector<bool> refined(n > 0 ? n - 1 : 0, false);  // steps next to a refined minimum
    for (std::size_t k = 0; k < n; ++k) {
      const bool down = k == 0 || samples_[k].d.distance < samples_[k - 1].d.distance;
      const bool up = k + 1 == n || samples_[k].d.distance <= samples_[k + 1].d.distance;
      if (down && up) minima_.push_back(refine_minimum(k, refined));
    }
    out.interference = interference();
    out.unproven_intervals = prove_steps(refined);
    std::sort(minima_.begin(), minima_.end(), [](const auto& x, const auto& y) { return x.t < y.t; });
    out.minima = minima_;
    if (!minima_.empty()) out.worst = minima_.front();
    for (const ClearanceMinimum& m : minima_)
      if (m.at.distance < out.worst.at.distance) out.worst = m;
    return out;
  }

 private:
  bool proven_beyond_threshold() const {
    for (std::size_t k = 0; k < samples_.size(); ++k) {
      if (samples_[k].d.distance <= threshold_) return false;
      if (k + 1 < samples_.size() && lower_bound(samples_[k], samples_[k + 1]) <= threshold_) return false;
    }
    return true;
  }

  double step_at(std::size_t k) const {
    const std::size_t n = rows_.t.size();
    if (n < 2) return 1.0;
    return k + 1 < n ? rows_.t[k + 1] - rows_.t[k] : rows_.t[k] - rows_.t[k - 1];
  }

  ClearanceMinimum minimum_of(const Sample& s, bool refined) {
    ClearanceMinimum m;
    m.t = s.t, m.at = s.d, m.refined = refined;
    m.local_a = in_frame(s.a.motion.pose, s.d.point_a), m.local_b = in_frame(s.b.motion.pose, s.d.point_b);
    return m;
  }
  // The world point x in the frame of `pose` (Rᵀ (x − at)).
  static kin3::V3 in_frame(const Pose& pose, kin3::V3 x) {
    const auto& r = pose.rotation;
    const kin3::V3 d = x - pose.at;
    return {r[0] * d.x + r[3] * d.y + r[6] * d.z, r[1] * d.x + r[4] * d.y + r[7] * d.z,
            r[2] * d.x + r[5] * d.y + r[8] * d.z};
  }

  // The local minimum at row k, refined where the distance's rate changes sign on one of the steps beside it.
  ClearanceMinimum refine_minimum(std::size_t k, std::vector<bool>& refined) {
    const std::size_t n = samples_.size();
    std::size_t lo = k, hi = k;
    if (samples_[k].rate < 0 && k + 1 < n && samples_[k + 1].rate > 0) hi = k + 1;
    if (samples_[k].rate > 0 && k > 0 && samples_[k - 1].rate < 0) lo = k - 1;
    if (lo == hi) return minimum_of(samples_[k], false);
    refined[lo] = true;
    const double tol = options_.time_tolerance * (rows_.t[hi] - rows_.t[lo]);
    const Sample root = root_between(
        samples_[lo], samples_[hi], tol, [&](double t) { return tracer_.at_time(a_, b_, t); },
        [](const Sample& s) { return s.rate; });
    extra_.push_back(root);
    return root.d.distance < samples_[k].d.distance ? minimum_of(root, true) : minimum_of(samples_[k], false);
  }

  // The intervals where the distance is negative: its sign changes between the rows and the refined minima.
  std::vector<InterferenceInterval> interference() {
    std::vector<Sample> all = samples_;
    all.insert(all.end(), extra_.begin(), extra_.end());
    std::sort(all.begin(), all.end(), [](const Sample& x, const Sample& y) { return x.t < y.t; });
    std::vector<InterferenceInterval> out;
    if (all.empty()) return out;
    bool inside = all[0].d.distance < 0;
    double entry = all[0].t;
    auto distance = [](const Sample& s) { return s.d.distance; };
    for (std::size_t i = 0; i + 1 < all.size(); ++i) {
      const bool next = all[i + 1].d.distance < 0;
      if (next == inside) continue;
      const double tol = options_.time_tolerance * step_at(0);
      const Sample root = root_between(
          all[i], all[i + 1], tol, [&](double t) { return tracer_.at_time(a_, b_, t); }, distance);
      if (next) {
        entry = root.t;
      } else {
        out.push_back({entry, root.t});
      }
      inside = next;
    }
    if (inside) out.push_back({entry, all.back().t});
    return out;
  }

  // Steps not beside a refined minimum: proven above min(worst, threshold) by the speed bound, halved where needed.
  Index prove_steps(const std::vector<bool>& refined) {
    double worst = std::numeric_limits<double>::infinity();
    for (const ClearanceMinimum& m : minima_) worst = std::min(worst, m.at.distance);
    Index unproven = 0;
    for (std::size_t k = 0; k + 1 < samples_.size(); ++k)
      if (!refined[k] && !prove(samples_[k], samples_[k + 1], std::min(worst, threshold_), 0)) ++unproven;
    return unproven;
  }

  bool prove(const Sample& s0, const Sample& s1, double target, int depth) {
    if (lower_bound(s0, s1) >= target) return true;
    if (depth >= options_.max_subdivision_depth) return false;
    const Sample mid = tracer_.at_time(a_, b_, 0.5 * (s0.t + s1.t));
    if (mid.d.distance < target) {  // closer than every minimum found on the rows: a minimum of its own
      minima_.push_back(minimum_of(mid, true));
      return true;
    }
    return prove(s0, mid, target, depth + 1) && prove(mid, s1, target, depth + 1);
  }

  Tracer& tracer_;
  const ClearanceRows& rows_;
  const ClearanceOptions& options_;
  double threshold_;
  Index a_, b_;
  std::vector<Sample> samples_;  // at the rows
  std::vector<Sample> extra_;    // refined minima
  std::vector<ClearanceMinimum> minima_;
};

// ∂d/∂p of each sensitivity at the minimum m (each of a pair's): n · (∂x_B/∂p − ∂x_A/∂p), each point carried by its
// part's frame.
std::vector<double> minimum_sensitivities(const Model& model, const std::vector<Part>& parts, Index a, Index b,
                                          const ClearanceMinimum& m, const Eigen::VectorXd& q,
                                          const ClearanceOptions& options) {
  StepperOptions so;
  static_cast<SolverSettings&>(so) = options.solver;
  so.velocities = so.accelerations = false;
  so.sensitivities = options.sensitivities;
  Stepper stepper(model, so);
  stepper.restart(q);
  StepSummary summary;
  if (stepper.step(m.t, &summary) != SolveStatus::kSuccess)
    throw Error("clearance: t = " + format_time(m.t) + ": the sensitivities cannot be solved: " + summary.message);
  const SensitivityLayout layout{model.num_coordinates()};
  auto moved = [&](Index part, kin3::V3 x, const double* dq) {
    const PartJacobian j = part_jacobian(parts[static_cast<std::size_t>(part)].frame, stepper.q().data(), m.t);
    const kin3::V3 origin = part_pose(parts[static_cast<std::size_t>(part)].frame, stepper.q().data(), m.t).at;
    kin3::V3 dx;
    for (std::size_t i = 0; i < j.coordinates.size(); ++i)
      dx = dx + dq[j.coordinates[i]] * (j.d_origin[i] + cross(j.d_angle[i], x - origin));
    return dx;
  };
  std::vector<double> out;
  for (std::size_t p = 0; p < options.sensitivities.size(); ++p) {
    const double* dq = stepper.sensitivities() + layout.offset(p, 0);
    out.push_back(dot(m.at.normal, moved(b, m.at.point_b, dq) - moved(a, m.at.point_a, dq)));
  }
  return out;
}

// Steps whose boxes go into one query of the broad phase: fewer updates of the tree, slightly larger boxes.
constexpr std::size_t kStepsPerQuery = 4;

// `pairs: all`: the selected pairs whose boxes, each swept over a step and grown by half the threshold, overlap on
// some step (the others are farther than the threshold at every time).
std::vector<std::pair<Index, Index>> broad_phase(const std::vector<Part>& parts, const ClearanceGeometry& geometry,
                                                 const detail::PairSelection& selection, const ClearanceRows& rows,
                                                 double threshold) {
  // each part's state and box at a row, two rows at a time: over a step, a point lies within speed · h/2 of its
  // place at the nearer row
  struct AtRow {
    std::vector<double> speed, accel;
    std::vector<std::pair<kin3::V3, kin3::V3>> box;
  };
  auto at_row = [&](std::size_t k, AtRow& r) {
    r.speed.assign(parts.size(), 0.0), r.accel.assign(parts.size(), 0.0), r.box.resize(parts.size());
    for (std::size_t p = 0; p < parts.size(); ++p) {
      if (!selection.shaped[p]) continue;
      const auto i = static_cast<Index>(p);
      const PartState s = part_state(parts[p], geometry.bounding_radius(i), rows.q[k].data(), rows.qd[k].data(),
                                     rows.qdd[k].data(), rows.t[k]);
      r.speed[p] = s.speed, r.accel[p] = s.accel;
      r.box[p] = geometry.world_box(i, s.motion.pose);
    }
  };
  const std::size_t n = rows.t.size();
  std::vector<std::pair<Index, Index>> found;
  detail::BroadPhase tree(selection.shaped);
  std::vector<detail::SweptBox> boxes(parts.size());
  AtRow r0, r1;
  at_row(0, r0);
  const double inf = std::numeric_limits<double>::infinity();
  const detail::SweptBox empty{{inf, inf, inf}, {-inf, -inf, -inf}};
  std::fill(boxes.begin(), boxes.end(), empty);
  for (std::size_t k = 0; k + (n > 1 ? 1 : 0) < n; ++k) {
    const std::size_t k1 = n > 1 ? k + 1 : k;
    at_row(k1, r1);
    const double h = rows.t[k1] - rows.t[k];
    for (std::size_t p = 0; p < parts.size(); ++p) {
      if (!selection.shaped[p]) continue;
      const double speed = std::max(r0.speed[p] + r0.accel[p] * h, r1.speed[p] + r1.accel[p] * h);
      const double r = 0.5 * speed * h + 0.5 * threshold;
      const auto &b0 = r0.box[p], &b1 = r1.box[p];
      detail::SweptBox& b = boxes[p];
      b.lo = {std::min({b.lo.x, b0.first.x - r, b1.first.x - r}), std::min({b.lo.y, b0.first.y - r, b1.first.y - r}),
              std::min({b.lo.z, b0.first.z - r, b1.first.z - r})};
      b.hi = {std::max({b.hi.x, b0.second.x + r, b1.second.x + r}),
              std::max({b.hi.y, b0.second.y + r, b1.second.y + r}),
              std::max({b.hi.z, b0.second.z + r, b1.second.z + r})};
    }
    std::swap(r0, r1);
    // one query of the tree for kStepsPerQuery steps: the boxes hold the parts over all of them
    if ((k + 1) % kStepsPerQuery != 0 && k1 + 1 < n) continue;
    for (const auto& [a, b] : tree.overlapping(boxes))
      if (selection.selects(a, b)) found.emplace_back(a, b);
    std::fill(boxes.begin(), boxes.end(), empty);
  }
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  return found;
}

}  // namespace

ClearanceReport clearance_along(const Model& model, const std::vector<Part>& parts, const ClearancePlan& plan,
                                const ClearanceRows& rows, const ClearanceOptions& options) {
  ClearanceReport report;
  report.times = rows.t;
  report.threshold = plan.threshold;
  for (const OutputSensitivity& s : options.sensitivities) report.parameters.push_back(s.name);
  if (rows.t.empty()) return report;
  const ClearanceGeometry geometry(parts);
  const detail::PairSelection selection(model, parts, plan);
  report.pairs_selected = selection.count;
  std::vector<std::pair<Index, Index>> pairs;
  if (plan.all)
    pairs = broad_phase(parts, geometry, selection, rows, plan.threshold);
  else
    for (const auto& ab : selection.listed)
      if (selection.selects(ab.first, ab.second)) pairs.push_back(ab);
  report.pairs_measured = static_cast<Index>(pairs.size());
  Tracer tracer(model, parts, geometry, rows, options);
  for (const auto& [a, b] : pairs) {
    std::optional<PairClearance> measured = PairPass(tracer, rows, options, plan.threshold, a, b).run(plan.all);
    if (!measured) continue;
    PairClearance& pc = *measured;
    // `all` reports the pairs that come within the threshold (or could not be proven not to)
    if (plan.all && pc.worst.at.distance > plan.threshold && pc.unproven_intervals == 0) continue;
    if (!options.sensitivities.empty()) {
      for (ClearanceMinimum& m : pc.minima)
        m.sensitivities = minimum_sensitivities(model, parts, a, b, m, tracer.solve(m.t), options);
      for (const ClearanceMinimum& m : pc.minima)  // the worst is a copy of one of them
        if (m.t == pc.worst.t && m.at.distance == pc.worst.at.distance) pc.worst.sensitivities = m.sensitivities;
    }
    report.pairs.push_back(std::move(pc));
  }
  report.positions_solved = tracer.solved();
  return report;
}

}  // namespace phiq
