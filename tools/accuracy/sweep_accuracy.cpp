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
        model_, o, ws, [&](const StepView& s) {
      if (stopped(stop_)) return false;
      if (s.step % substeps_ != 0) return true;
      r.q.insert(r.q.end(), s.q.data(), s.q.data() + s.q.size());
      if (s.qd) r.v.insert(r.v.end(), s.qd->data(), s.qd->data() + s.qd->size());
      if (s.qdd) r.a.insert(r.a.end(), s.qdd->data(), s.qdd->data() + s.qdd->size());
      return true;
    }, &sum);
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

  // The grid, defaults filled in.
  std::vector<double> tols = opt.tolerances;
  if (tols.empty())
    for (int e = 4; e <= 14; ++e) tols.push_back(std::pow(10.0, -e));
  std::vector<Index> steps = opt.steps;
  if (steps.empty()) {
    for (Index s : {std::max<Index>(1, (so.steps + 2) / 4), so.steps, 4 * so.steps})
      if (std::find(steps.begin(), steps.end(), s) == steps.end()) steps.push_back(s);
  }
  std::vector<Predictor> preds = opt.predictors;
  if (preds.empty())  // every predictor but auto, which resolves to one of them
    for (Predictor p : all_predictors())
      if (p != Predictor::kAuto) preds.push_back(p);
  std::vector<JacobianUpdate> newtons = opt.newton;
  if (newtons.empty()) newtons = {JacobianUpdate::kWhenSlow, JacobianUpdate::kEveryIteration};
  std::vector<LinearSolverKind> lus = opt.linear_solvers;
  if (lus.empty()) lus = {LinearSolverKind::kKlu, LinearSolverKind::kUmfpack};

  // Every run starts from the assembled position at t_begin (tight, full Newton), so that the time per step is the
  // drive steps' and not the assembly from the scene's rough placement.
  Workspace ws0(model);
  ws0.q = square.start;
  {
    NewtonOptions a = so.assembly;
    a.tolerance = kReferenceTolerance;
    a.max_iterations = std::max(a.max_iterations, 100);
    PositionSummary ps;
    if (solve_position(model, so.t_begin, a, ws0, &ps) != SolveStatus::kSuccess) {
      ws0.q = square.start;
      if (solve_position(model, so.t_begin, so.assembly, ws0, &ps) != SolveStatus::kSuccess)
        throw std::runtime_error("assembly at t = " + format_time(so.t_begin) + " failed: " + ps.message);
    }
  }
  const Eigen::VectorXd start = ws0.q;

  // The reference.
  std::unique_ptr<Reference> ref;
  std::string spec = opt.reference;
  const bool automatic = spec == "auto";
  if (automatic) {
    const std::string kind = closed_form_for_scene_name(scene.name);
    spec = kind.empty() ? "numerical" : "closed-form:" + kind;
  }
  if (spec.rfind("closed-form:", 0) == 0) {
    std::unique_ptr<ClosedForm> f = make_closed_form(spec.substr(12));  // throws invalid_argument
    std::string misfit;
    try {
      f->bind(model.coordinate_names());
      const double r = fit_residual(model, *f, so);
      if (!(r <= kFitResidual))
        misfit = f->describe() + " does not satisfy the scene's constraints (scaled residual " + significant_or_empty(r, 3) +
                 "): another mechanism or drive; give its parameters, e.g. closed-form:crank-slider:omega=1";
      // Both assembly branches satisfy the constraints: the scene's is the one it assembles into at t_begin.
      else if (const double d = branch_distance(model, *f, so.t_begin, start); !(d <= kFitBranch))
        misfit = f->describe() + " is another assembly branch than the scene's (scaled distance " + significant_or_empty(d, 3) +
                 " at t = " + significant_or_empty(so.t_begin, 6) + "), e.g. closed-form:fourbar:branch=-1";
    } catch (const std::invalid_argument& e) {
      misfit = e.what();
    }
    if (!misfit.empty() && !automatic) throw std::invalid_argument("--reference: " + misfit);
    if (misfit.empty()) {
      rep.reference = "closed-form:" + f->describe();
      rep.reference_kind = "closed-form:" + f->describe().substr(0, f->describe().find(':'));
      ref = std::make_unique<ClosedFormReference>(std::move(f));
    } else {
      rep.notes.push_back("the scene's name suggests " + spec + ", but " + misfit + "; using the numerical reference");
      spec = "numerical";
    }
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

  // One numeric LU per linear solver: the model's own analysis, or the same pattern analysed for the other library
  // (exactly what the scene's solver.linear_solver would have built).
  std::map<LinearSolverKind, std::shared_ptr<const SparseLuSymbolic>> analyses;
  auto numeric = [&](LinearSolverKind k) {
    if (k == model.linear_solver()) return model.symbolic()->make_numeric();
    auto& a = analyses[k];
    if (!a) a = analyse(k, std::make_shared<CscPattern>(model.solve_pattern()));  // the square system solved
    return a->make_numeric();
  };

  const auto n = static_cast<std::size_t>(model.num_coordinates());
  const Eigen::VectorXd& scale = model.tolerance_scales().coordinate_scale;
  std::vector<double> rq(n), rv(n), ra(n);
  std::size_t total = tols.size() * steps.size() * preds.size() * newtons.size() * lus.size(), done = 0;
  struct Timed {
    std::size_t row;     // index into rep.rows
    SweepOptions options;
  };
  std::vector<Timed> timed;  // the settings whose sweep succeeded, timed after all the error runs
  // Step counts outermost: the numerical reference is computed once per step count.
  for (Index st : steps)
    for (Predictor p : preds)
      for (JacobianUpdate nu : newtons)
        for (LinearSolverKind lu : lus)
          for (double tol : tols) {
            ++done;
            const AccuracySetting set{tol, st, p, nu, lu};
            if ((predictor_needs_accelerations(p) && !so.accelerations) ||
                (predictor_needs_velocities(p) && !(so.velocities || so.accelerations))) {
              const std::string note = std::string("predictor ") + to_string(p) +
                                       " skipped: the scene does not output the derivatives it extrapolates with";
              if (std::find(rep.notes.begin(), rep.notes.end(), note) == rep.notes.end()) rep.notes.push_back(note);
              continue;
            }
            SweepOptions o = so;
            o.threads = 1;
            o.steps = st;
            o.predictor = p;
            o.newton.tolerance = o.assembly.tolerance = tol;
            o.newton.jacobian_update = nu;
            AccuracyRow row;
            row.setting = set;
            row.is_default = tol == rep.scene_default.tolerance && st == rep.scene_default.steps &&
                             resolved(p, so) == rep.scene_default.predictor && nu == rep.scene_default.newton &&
                             lu == rep.scene_default.linear_solver;
            // First run: errors and counts (not timed: the comparison with the reference is the callback's work).
            double eq = 0, ev = 0, ea = 0;
            SweepSummary sum;
            {
              Workspace ws(model);
              ws.lu = numeric(lu);
              ws.q = start;
              (void)run_sweep(  // its status is sum.status, read below
                  model, o, ws, [&](const StepView& s) {
                ref->at(st, s.step, s.t, rq.data(), rv.data(), ra.data());
                for (std::size_t j = 0; j < n; ++j) {
                  const auto jj = static_cast<Index>(j);
                  double d = s.q(jj) - rq[j];
                  if (ref->is_angle(jj)) d = std::remainder(d, kTwoPi);
                  worst(eq, std::fabs(d) / scale(jj));
                  if (s.qd) worst(ev, std::fabs((*s.qd)(jj) - rv[j]) / scale(jj));
                  if (s.qdd) worst(ea, std::fabs((*s.qdd)(jj) - ra[j]) / scale(jj));
                }
                return !stopped(opt.stop);
              }, &sum);
            }
            if (sum.status == SolveStatus::kCancelled) throw AccuracyCancelled();
            if (sum.status != SolveStatus::kSuccess) {
              row.status = to_string(sum.status);
              row.err_q = row.err_v = row.err_a = NAN;
              row.iterations_per_step = row.factorizations_per_step = row.us_per_step = NAN;
              if (progress) progress(setting_text(set) + ": " + sum.message);
              rep.rows.push_back(row);
              continue;
            }
            const double steps_d = static_cast<double>(st);
            row.err_q = eq;
            row.err_v = o.velocities ? ev : NAN;
            row.err_a = o.accelerations ? ea : NAN;
            row.iterations_per_step =
                static_cast<double>(sum.counters.newton_iterations - sum.assembly.iterations) / steps_d;
            row.factorizations_per_step =
                static_cast<double>(sum.counters.factorizations - sum.assembly.factorizations) / steps_d;
            if (progress) {
              // a stream: GCC 12 warns (-Wrestrict, a false positive) on "/" + std::to_string(...)
              std::ostringstream line;
              line << done << "/" << total << " " << setting_text(set) << ": err_q " << significant_or_empty(row.err_q, 2)
                   << ", " << significant_or_empty(row.iterations_per_step, 3) << " iterations per step";
              progress(line.str());
            }
            timed.push_back({rep.rows.size(), o});
            rep.rows.push_back(row);
          }

  // Timing: `repeat` rounds over all the settings, each setting's best kept. Rounds rather than back-to-back
  // repetitions, so that a burst of load on a shared machine hits one sample of many settings instead of every
  // sample of one. Within a round a sweep of a few microseconds (the seed models) is repeated until 10 ms have
  // been timed, so that one preemption is not the whole sample. The workspace is made outside the clock and the
  // callback is empty.
  for (auto& t : timed) rep.rows[t.row].us_per_step = INFINITY;
  for (int round = 0; round < opt.repeat; ++round) {
    if (progress) progress("timing round " + std::to_string(round + 1) + " of " + std::to_string(opt.repeat));
    for (const auto& t : timed) {
      AccuracyRow& row = rep.rows[t.row];
      double spent = 0.0;
      for (int r = 0; r == 0 || (spent < 0.01 && r < 1000); ++r) {
        Workspace ws(model);
        ws.lu = numeric(row.setting.linear_solver);
        ws.q = start;
        SweepSummary s2;
        const auto t0 = Clock::now();
        (void)run_sweep(  // its status is s2.status, read below
            model, t.options, ws, [&](const StepView&) { return !stopped(opt.stop); }, &s2);
        if (s2.status == SolveStatus::kCancelled) throw AccuracyCancelled();
        const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
        spent += dt;
        row.us_per_step = std::min(row.us_per_step, dt / static_cast<double>(row.setting.steps) * 1e6);
      }
    }
  }
  return rep;
}

}  // namespace phiq::tools
