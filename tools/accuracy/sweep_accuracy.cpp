// measure_accuracy(): the grid of `phiq sweep-accuracy` run against its reference (a closed form that fits the
// scene, or the scene itself solved tightly), the errors and Newton counts measured, then the settings timed.
#include "sweep_accuracy.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

#include "accuracy_text.hpp"
#include "closed_forms.hpp"

namespace phiq::tools {

namespace {

constexpr double kTwoPi = 6.283185307179586;
// The numerical reference's tolerance: the tightest the convergence test reaches (its floor is a few ulps of |q|).
constexpr double kReferenceTolerance = 1e-14;
// A closed form fits a scene when the scene's own constraints hold at its positions to this scaled residual (the
// closed forms are exact to rounding, ~1e-15): a wrong mechanism, drive or branch misses by far more.
constexpr double kFitResidual = 1e-8;
// ... and its positions at the first time are the scene's assembly (to 1e-14) within this scaled distance: the other
// branch of a four-bar is a finite distance away.
constexpr double kFitBranch = 1e-6;

using Clock = std::chrono::steady_clock;
using detail::newton_name;
using detail::significant_or_empty;

// The sweep's own choice for Predictor::kAuto, so that the scene's default can be found in the grid.
Predictor resolved(Predictor p, const SweepOptions& o) {
  return effective_predictor(p, o.velocities || o.accelerations, o.accelerations);
}

bool stopped(const std::atomic<bool>* stop) { return stop && stop->load(); }

// Largest of the errors seen; NaN (a non-finite result) counts as infinitely large.
void worst(double& e, double x) { e = std::isnan(x) ? INFINITY : std::max(e, x); }

// Positions, velocities and accelerations of the reference at time point k of a sweep of `steps` steps.
class Reference {
 public:
  virtual ~Reference() = default;
  virtual void at(Index steps, Index k, double t, double* q, double* v, double* a) = 0;
  virtual bool is_angle(Index j) const = 0;
};

class ClosedFormReference final : public Reference {
 public:
  ClosedFormReference(std::unique_ptr<ClosedForm> f) : f_(std::move(f)) {}
  void at(Index, Index, double t, double* q, double* v, double* a) override { f_->evaluate(t, q, v, a); }
  bool is_angle(Index j) const override { return f_->is_angle(static_cast<std::size_t>(j)); }

 private:
  std::unique_ptr<ClosedForm> f_;
};

// The same scene at kReferenceTolerance with full Newton and `substeps` sub-steps per step, computed once per step
// count at exactly the setting's time points (t_k of the sub-stepped sweep at k · substeps is the same double only
// up to rounding of the step; the reference is taken at its own t, which differs from the setting's by an ulp).
class NumericalReference final : public Reference {
 public:
  NumericalReference(const Model& m, const SweepOptions& scene, const Eigen::VectorXd& start, int substeps,
                     const std::atomic<bool>* stop)
      : model_(m), scene_(scene), start_(start), substeps_(substeps), stop_(stop) {}
  void at(Index steps, Index k, double, double* q, double* v, double* a) override {
    const Rows& r = rows(steps);
    const auto n = static_cast<std::size_t>(model_.num_coordinates()), row = static_cast<std::size_t>(k) * n;
    std::copy_n(r.q.data() + row, n, q);
    if (!r.v.empty()) std::copy_n(r.v.data() + row, n, v);
    if (!r.a.empty()) std::copy_n(r.a.data() + row, n, a);
  }
  bool is_angle(Index j) const override { return model_.coordinate_unit(j) == Unit::kAngle; }

 private:
  struct Rows {
    std::vector<double> q, v, a;
  };
  const Rows& rows(Index steps) {
    auto it = cache_.find(steps);
    if (it != cache_.end()) return it->second;
    if (cache_.size() >= 2) cache_.erase(cache_.begin());  // at most two step counts in memory
    SweepOptions o = scene_;
    o.threads = 1;
    o.steps = steps * substeps_;
    o.newton.tolerance = o.assembly.tolerance = kReferenceTolerance;
    o.newton.jacobian_update = JacobianUpdate::kEveryIteration;
    o.newton.max_iterations = std::max(o.newton.max_iterations, 50);
    Workspace ws(model_);
    ws.q = start_;
    Rows r;
    SweepSummary sum;
    (void)run_sweep(  // its status is sum.status, read below
        model_, o, ws,
        [&](const StepView& s) {
          if (stopped(stop_)) return false;
          if (s.step % substeps_ != 0) return true;
          r.q.insert(r.q.end(), s.q.data(), s.q.data() + s.q.size());
          if (s.qd) r.v.insert(r.v.end(), s.qd->data(), s.qd->data() + s.qd->size());
          if (s.qdd) r.a.insert(r.a.end(), s.qdd->data(), s.qdd->data() + s.qdd->size());
          return true;
        },
        &sum);
    if (sum.status == SolveStatus::kCancelled) throw AccuracyCancelled();
    if (sum.status != SolveStatus::kSuccess)
      throw std::runtime_error("the numerical reference (tolerance 1e-14, full Newton, " + std::to_string(o.steps) +
                               " steps) failed: " + sum.message);
    return cache_.emplace(steps, std::move(r)).first->second;
  }
  const Model& model_;
  SweepOptions scene_;
  Eigen::VectorXd start_;
  int substeps_;
  const std::atomic<bool>* stop_;
  std::map<Index, Rows> cache_;
};

// Largest scaled residual of the scene's constraints at the closed form's positions, over five times of the sweep.
double fit_residual(const Model& m, ClosedForm& f, const SweepOptions& o) {
  const auto n = static_cast<std::size_t>(m.num_coordinates());
  std::vector<double> q(n), v(n), a(n);
  Eigen::VectorXd phi(m.num_equations());
  double worst_r = 0.0;
  for (double s : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    const double t = o.t_begin + s * (o.t_end - o.t_begin);
    f.evaluate(t, q.data(), v.data(), a.data());
    m.residual(q.data(), t, phi.data());
    worst(worst_r, scaled_residual(m, phi));
  }
  return worst_r;
}

// Largest scaled difference between the closed form's positions at t and q (angles modulo 2π).
double branch_distance(const Model& m, const ClosedForm& f, double t, const Eigen::VectorXd& q) {
  const auto n = static_cast<std::size_t>(m.num_coordinates());
  std::vector<double> rq(n), rv(n), ra(n);
  f.evaluate(t, rq.data(), rv.data(), ra.data());
  const Eigen::VectorXd& scale = m.tolerance_scales().coordinate_scale;
  double d = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    const auto jj = static_cast<Index>(j);
    double x = q(jj) - rq[j];
    if (f.is_angle(j)) x = std::remainder(x, kTwoPi);
    worst(d, std::fabs(x) / scale(jj));
  }
  return d;
}

std::string setting_text(const AccuracySetting& s) {
  return "tolerance " + significant_or_empty(s.tolerance, 3) + ", " + std::to_string(s.steps) + " steps, " +
         to_string(s.predictor) + ", " + newton_name(s.newton) + " Newton, " + to_string(s.linear_solver);
}

// The settings of the grid, defaults filled in.
struct AccuracyGrid {
  std::vector<double> tolerances;
  std::vector<Index> steps;
  std::vector<Predictor> predictors;
  std::vector<JacobianUpdate> newtons;
  std::vector<LinearSolverKind> linear_solvers;
  std::size_t size() const {
    return tolerances.size() * steps.size() * predictors.size() * newtons.size() * linear_solvers.size();
  }
};

AccuracyGrid grid_of(const AccuracyOptions& opt, const SweepOptions& so) {
  AccuracyGrid g{opt.tolerances, opt.steps, opt.predictors, opt.newton, opt.linear_solvers};
  if (g.tolerances.empty())
    for (int e = 4; e <= 14; ++e) g.tolerances.push_back(std::pow(10.0, -e));
  if (g.steps.empty()) {
    for (Index s : {std::max<Index>(1, (so.steps + 2) / 4), so.steps, 4 * so.steps})
      if (std::find(g.steps.begin(), g.steps.end(), s) == g.steps.end()) g.steps.push_back(s);
  }
  if (g.predictors.empty())  // every predictor but auto, which resolves to one of them
    for (Predictor p : all_predictors())
      if (p != Predictor::kAuto) g.predictors.push_back(p);
  if (g.newtons.empty()) g.newtons = {JacobianUpdate::kWhenSlow, JacobianUpdate::kEveryIteration};
  if (g.linear_solvers.empty()) g.linear_solvers = {LinearSolverKind::kKlu, LinearSolverKind::kUmfpack};
  return g;
}

// Every run starts from the assembled position at t_begin (tight, full Newton), so that the time per step is the
// drive steps' and not the assembly from the scene's rough placement.
Eigen::VectorXd assembled_start(const Model& model, const SweepOptions& so, const Eigen::VectorXd& rough) {
  Workspace ws0(model);
  ws0.q = rough;
  NewtonOptions a = so.assembly;
  a.tolerance = kReferenceTolerance;
  a.max_iterations = std::max(a.max_iterations, 100);
  PositionSummary ps;
  if (solve_position(model, so.t_begin, a, ws0, &ps) != SolveStatus::kSuccess) {
    ws0.q = rough;
    if (solve_position(model, so.t_begin, so.assembly, ws0, &ps) != SolveStatus::kSuccess)
      throw std::runtime_error("assembly at t = " + format_time(so.t_begin) + " failed: " + ps.message);
  }
  return ws0.q;
}

// The closed form `spec` names ("closed-form:KIND..."), or none with a note when `automatic` chose one that does not
// fit the scene (a given one that does not fit is refused).
std::unique_ptr<Reference> closed_form_reference(const std::string& spec, bool automatic, const Model& model,
                                                 const SweepOptions& so, const Eigen::VectorXd& start,
                                                 AccuracyReport& rep) {
  std::unique_ptr<ClosedForm> f = make_closed_form(spec.substr(12));  // throws invalid_argument
  std::string misfit;
  try {
    f->bind(model.coordinate_names());
    const double r = fit_residual(model, *f, so);
    if (!(r <= kFitResidual))
      misfit = f->describe() + " does not satisfy the scene's constraints (scaled residual " +
               significant_or_empty(r, 3) +
               "): another mechanism or drive; give its parameters, e.g. closed-form:crank-slider:omega=1";
    // Both assembly branches satisfy the constraints: the scene's is the one it assembles into at t_begin.
    else if (const double d = branch_distance(model, *f, so.t_begin, start); !(d <= kFitBranch))
      misfit = f->describe() + " is another assembly branch than the scene's (scaled distance " +
               significant_or_empty(d, 3) + " at t = " + significant_or_empty(so.t_begin, 6) +
               "), e.g. closed-form:fourbar:branch=-1";
  } catch (const std::invalid_argument& e) {
    misfit = e.what();
  }
  if (!misfit.empty() && !automatic) throw std::invalid_argument("--reference: " + misfit);
  if (!misfit.empty()) {
    rep.notes.push_back("the scene's name suggests " + spec + ", but " + misfit + "; using the numerical reference");
    return nullptr;
  }
  rep.reference = "closed-form:" + f->describe();
  rep.reference_kind = "closed-form:" + f->describe().substr(0, f->describe().find(':'));
  return std::make_unique<ClosedFormReference>(std::move(f));
}

// The reference of AccuracyOptions::reference: a closed form that fits the scene, or the scene solved tightly.
std::unique_ptr<Reference> make_reference(const Scene& scene, const AccuracyOptions& opt, const Model& model,
                                          const Eigen::VectorXd& start, AccuracyReport& rep) {
  const SweepOptions& so = scene.sweep;
  std::unique_ptr<Reference> ref;
  std::string spec = opt.reference;
  const bool automatic = spec == "auto";
  if (automatic) {
    const std::string kind = closed_form_for_scene_name(scene.name);
    spec = kind.empty() ? "numerical" : "closed-form:" + kind;
  }
  if (spec.rfind("closed-form:", 0) == 0) {
    ref = closed_form_reference(spec, automatic, model, so, start, rep);
    if (!ref) spec = "numerical";
  }
  if (!ref) {
    if (spec != "numerical")
      throw std::invalid_argument("--reference: '" + opt.reference +
                                  "' is auto, numerical or closed-form:KIND[:NAME=VALUE,...]");
    if (opt.reference_substeps < 1) throw std::invalid_argument("reference sub-steps must be at least 1");
    rep.reference = "numerical: the same scene at tolerance 1e-14, full Newton, " +
                    std::to_string(opt.reference_substeps) + " sub-steps per step";
    rep.reference_kind = "numerical";
    ref = std::make_unique<NumericalReference>(model, so, start, opt.reference_substeps, opt.stop);
  }
  return ref;
}

// The runs of the grid: each setting's errors against the reference and its counts, then the timing rounds.
class AccuracyRuns {
 public:
  AccuracyRuns(const Model& model, const SweepOptions& so, const AccuracyOptions& opt, Eigen::VectorXd start,
               Reference& ref, const std::function<void(const std::string&)>& progress, AccuracyReport& rep)
      : model_(model), so_(so), opt_(opt), start_(std::move(start)), ref_(ref), progress_(progress), rep_(rep) {}
  void errors(const AccuracySetting& set, std::size_t done, std::size_t total);
  void time_rounds();

 private:
  // One numeric LU per linear solver: the model's own analysis, or the same pattern analysed for the other library
  // (exactly what the scene's solver.linear_solver would have built).
  std::unique_ptr<SparseLuNumeric> numeric(LinearSolverKind k) {
    if (k == model_.linear_solver()) return model_.symbolic()->make_numeric();
    auto& a = analyses_[k];
    if (!a) a = analyse(k, std::make_shared<CscPattern>(model_.solve_pattern()));  // the square system solved
    return a->make_numeric();
  }
  struct Timed {
    std::size_t row;  // index into rep.rows
    SweepOptions options;
  };

  const Model& model_;
  const SweepOptions& so_;
  const AccuracyOptions& opt_;
  const Eigen::VectorXd start_;
  Reference& ref_;
  const std::function<void(const std::string&)>& progress_;
  AccuracyReport& rep_;
  std::map<LinearSolverKind, std::shared_ptr<const SparseLuSymbolic>> analyses_;
  std::vector<Timed> timed_;  // the settings whose sweep succeeded, timed after all the error runs
};

void AccuracyRuns::errors(const AccuracySetting& set, std::size_t done, std::size_t total) {
  // (not a structured binding: the callback below captures st, which clang 14 does not allow of a binding)
  const double tol = set.tolerance;
  const Index st = set.steps;
  const Predictor p = set.predictor;
  const JacobianUpdate nu = set.newton;
  const LinearSolverKind lu = set.linear_solver;
  if ((predictor_needs_accelerations(p) && !so_.accelerations) ||
      (predictor_needs_velocities(p) && !(so_.velocities || so_.accelerations))) {
    const std::string note = std::string("predictor ") + to_string(p) +
                             " skipped: the scene does not output the derivatives it extrapolates with";
    if (std::find(rep_.notes.begin(), rep_.notes.end(), note) == rep_.notes.end()) rep_.notes.push_back(note);
    return;
  }
  SweepOptions o = so_;
  o.threads = 1;
  o.steps = st;
  o.predictor = p;
  o.newton.tolerance = o.assembly.tolerance = tol;
  o.newton.jacobian_update = nu;
  AccuracyRow row;
  row.setting = set;
  const AccuracySetting& d = rep_.scene_default;
  row.is_default =
      tol == d.tolerance && st == d.steps && resolved(p, so_) == d.predictor && nu == d.newton && lu == d.linear_solver;
  // First run: errors and counts (not timed: the comparison with the reference is the callback's work).
  const auto n = static_cast<std::size_t>(model_.num_coordinates());
  const Eigen::VectorXd& scale = model_.tolerance_scales().coordinate_scale;
  std::vector<double> rq(n), rv(n), ra(n);
  double eq = 0, ev = 0, ea = 0;
  SweepSummary sum;
  {
    Workspace ws(model_);
    ws.lu = numeric(lu);
    ws.q = start_;
    (void)run_sweep(  // its status is sum.status, read below
        model_, o, ws,
        [&](const StepView& s) {
          ref_.at(st, s.step, s.t, rq.data(), rv.data(), ra.data());
          for (std::size_t j = 0; j < n; ++j) {
            const auto jj = static_cast<Index>(j);
            double e = s.q(jj) - rq[j];
            if (ref_.is_angle(jj)) e = std::remainder(e, kTwoPi);
            worst(eq, std::fabs(e) / scale(jj));
            if (s.qd) worst(ev, std::fabs((*s.qd)(jj)-rv[j]) / scale(jj));
            if (s.qdd) worst(ea, std::fabs((*s.qdd)(jj)-ra[j]) / scale(jj));
          }
          return !stopped(opt_.stop);
        },
        &sum);
  }
  if (sum.status == SolveStatus::kCancelled) throw AccuracyCancelled();
  if (sum.status != SolveStatus::kSuccess) {
    row.status = to_string(sum.status);
    row.err_q = row.err_v = row.err_a = NAN;
    row.iterations_per_step = row.factorizations_per_step = row.us_per_step = NAN;
    if (progress_) progress_(setting_text(set) + ": " + sum.message);
    rep_.rows.push_back(row);
    return;
  }
  const double steps_d = static_cast<double>(st);
  row.err_q = eq;
  row.err_v = o.velocities ? ev : NAN;
  row.err_a = o.accelerations ? ea : NAN;
  row.iterations_per_step = static_cast<double>(sum.counters.newton_iterations - sum.assembly.iterations) / steps_d;
  row.factorizations_per_step =
      static_cast<double>(sum.counters.factorizations - sum.assembly.factorizations) / steps_d;
  if (progress_) {
    // a stream: GCC 12 warns (-Wrestrict, a false positive) on "/" + std::to_string(...)
    std::ostringstream line;
    line << done << "/" << total << " " << setting_text(set) << ": err_q " << significant_or_empty(row.err_q, 2) << ", "
         << significant_or_empty(row.iterations_per_step, 3) << " iterations per step";
    progress_(line.str());
  }
  timed_.push_back({rep_.rows.size(), o});
  rep_.rows.push_back(row);
}

// Timing: `repeat` rounds over all the settings, each setting's best kept. Rounds rather than back-to-back
// repetitions, so that a burst of load on a shared machine hits one sample of many settings instead of every
// sample of one. Within a round a sweep of a few microseconds (the seed models) is repeated until 10 ms have
// been timed, so that one preemption is not the whole sample. The workspace is made outside the clock and the
// callback is empty.
void AccuracyRuns::time_rounds() {
  for (auto& t : timed_) rep_.rows[t.row].us_per_step = INFINITY;
  for (int round = 0; round < opt_.repeat; ++round) {
    if (progress_) progress_("timing round " + std::to_string(round + 1) + " of " + std::to_string(opt_.repeat));
    for (const auto& t : timed_) {
      AccuracyRow& row = rep_.rows[t.row];
      double spent = 0.0;
      for (int r = 0; r == 0 || (spent < 0.01 && r < 1000); ++r) {
        Workspace ws(model_);
        ws.lu = numeric(row.setting.linear_solver);
        ws.q = start_;
        SweepSummary s2;
        const auto t0 = Clock::now();
        (void)run_sweep(  // its status is s2.status, read below
            model_, t.options, ws, [&](const StepView&) { return !stopped(opt_.stop); }, &s2);
        if (s2.status == SolveStatus::kCancelled) throw AccuracyCancelled();
        const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
        spent += dt;
        row.us_per_step = std::min(row.us_per_step, dt / static_cast<double>(row.setting.steps) * 1e6);
      }
    }
  }
}

}  // namespace

AccuracyReport measure_accuracy(const Scene& scene, const AccuracyOptions& opt,
                                const std::function<void(const std::string&)>& progress) {
  if (opt.repeat < 1) throw std::invalid_argument("--repeat must be at least 1");
  const SweepOptions& so = scene.sweep;
  // The model `phiq run` sweeps: a scene with consistent redundant constraints is assembled by minimum norm and
  // solved on its independent rows (every row is still evaluated and checked); an inconsistent or under-driven one
  // is refused with prepare_scene()'s reason.
  SquareScene square;
  if (prepare_scene(*scene.model, so.t_begin, so.assembly, &square) != SolveStatus::kSuccess)
    throw std::runtime_error("t = " + format_time(so.t_begin) + ": " + square.assembly.message);
  const Model& model = square.model(*scene.model);
  AccuracyReport rep;
  rep.scene_path = scene.path;
  rep.scene_name = scene.name;
  rep.coordinates = model.num_coordinates();
  rep.length_scale = model.length_scale();
  rep.scene_default = {so.newton.tolerance, so.steps, resolved(so.predictor, so), so.newton.jacobian_update,
                       model.linear_solver()};
  const AccuracyGrid grid = grid_of(opt, so);
  const Eigen::VectorXd start = assembled_start(model, so, square.start);
  const std::unique_ptr<Reference> ref = make_reference(scene, opt, model, start, rep);
  AccuracyRuns runs(model, so, opt, start, *ref, progress, rep);
  std::size_t done = 0;
  // Step counts outermost: the numerical reference is computed once per step count.
  for (Index st : grid.steps)
    for (Predictor p : grid.predictors)
      for (JacobianUpdate nu : grid.newtons)
        for (LinearSolverKind lu : grid.linear_solvers)
          for (double tol : grid.tolerances) runs.errors({tol, st, p, nu, lu}, ++done, grid.size());
  runs.time_rounds();
  return rep;
}

}  // namespace phiq::tools
