// run_sweep(): a sweep's checks of its options and time domain, the assembly and row 0, the choice between the
// drive steps in order (Run::sequential) and in parallel chunks (parallel_sweep.cpp) with the threads and chunk size
// that fit (resources.hpp), and the summary's work counters and time. The task arena that keeps the sweep on
// its threads is made here.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include <tbb/info.h>
#include <tbb/task_arena.h>

#include "phiq/applied_loads.hpp"
#include "phiq/inverse_dynamics.hpp"
#include "phiq/joint_reactions.hpp"
#include "phiq/parts.hpp"
#include "phiq/sweep.hpp"
#include "phiq/text.hpp"
#include "sweep/parallel_sweep.hpp"
#include "sweep/resources.hpp"
#include "sweep/sweep_run.hpp"
#include "sweep/sweeper.hpp"
#include "sweep/time_grid.hpp"
#include "sweep/warning_stretches.hpp"

namespace phiq {

namespace {

using detail::add_counters;
using detail::Run;
using detail::Sweeper;

// A parameter of OutputPlan::sensitivities that changes no constraint (its reach is empty: every constraint of its
// models along p equals the swept model's, datum by datum): its sensitivities are zero, exactly, which the summary
// says once, not as an error (a zero column is an answer). Pre-condition: every reach was found (run_sweep()).
void note_parameters_nothing_reads(const SweepOptions& opt, SweepSummary& sum) {
  for (const OutputSensitivity& p : opt.sensitivities)
    if (p.reach && p.reach->spans.empty())
      sum.warnings.push_back(
          {opt.t_begin, "no_dependence",
           "no constraint or driver reads the parameter '" + p.name + "': its sensitivities are zero"});
}

// run_sweep's body, run inside a task arena of `threads` (run_sweep's count: opt.threads, or all cores for 0).
SolveStatus sweep_in_arena(const Model& model, const SweepOptions& opt, Workspace& ws,
                           const std::function<bool(const StepView&)>& on_step, RowWriter* writer,
                           SweepSummary* summary, int threads) {
  if (&ws.model() != &model) throw Error("workspace was made for another model");
  if (opt.steps < 0) throw Error("SweepOptions: steps must be >= 0");
  if (!std::isfinite(opt.t_begin) || !std::isfinite(opt.t_end)) throw Error("SweepOptions: times must be finite");
  if (const std::string why = detail::time_grid_problem(opt.t_begin, opt.t_end, opt.steps); !why.empty())
    throw Error("SweepOptions: " + why);
  if (opt.chunk_steps < 0) throw Error("SweepOptions: chunk_steps must be >= 0 (0: automatic)");
  if (opt.row_buffer_bytes == 0) throw Error("SweepOptions: row_buffer_bytes must be > 0");
  detail::check_solver_settings(model, opt, opt.points, opt.sensitivities, "SweepOptions");
  detail::check_efforts(model, opt, "SweepOptions");
  detail::check_limits(model, opt, "SweepOptions");
  for (const OutputJoint& j : opt.joints)
    if (j.max_coordinate() >= model.num_coordinates())
      throw Error("SweepOptions: output joint '" + j.name + "' reads a coordinate the model does not have");
  for (const OutputOrientation& o : opt.orientations)
    for (const Slot& e : o.e)
      if (e.is_coordinate() && e.coord() >= model.num_coordinates())
        throw Error("SweepOptions: output orientation '" + o.name + "' reads a coordinate the model does not have");
  if (opt.orientation_form.form != "matrix" && opt.orientation_form.form != "axis_angle" &&
      !is_euler_sequence(opt.orientation_form.form))
    throw Error("SweepOptions: orientation_form '" + opt.orientation_form.form +
                "' is not matrix, axis_angle or an "
                "Euler sequence");
  if (opt.sensitivity_form != SensitivityForm::kAuto && opt.sensitivity_form != SensitivityForm::kDirect &&
      opt.sensitivity_form != SensitivityForm::kAdjoint)
    throw Error("SweepOptions: sensitivity_form is not a SensitivityForm");
  SweepSummary local;
  SweepSummary& sum = summary ? *summary : local;
  sum = SweepSummary{};
  if (!opt.sensitivities.empty())
    sum.sensitivity_form = detail::sweep_sensitivity_form(opt, opt.sensitivity_outputs().size());
  const auto start = std::chrono::steady_clock::now();
  const WorkCounters before = ws.counters;
  WorkCounters others;  // work done in the seeding and chunk workspaces
  // Work done in the caller's workspace between these two counts is counted in `others` already (the parallel
  // part's chunks and seeds): left out of the workspace's share.
  WorkCounters counted_begin{}, counted_end{};
  detail::LimitWatch limits(opt.limits);
  auto done = [&](SolveStatus st) {
    limits.finish(sum.warnings);  // (the stretches up to the last row delivered, a failed sweep's too)
    detail::once_per_stretch(sum.warnings, "slow_convergence", opt);
    detail::once_per_stretch(sum.warnings, "belt_slack", opt);
    detail::once_per_stretch(sum.warnings, "gear_centres", opt);
    detail::once_per_stretch(sum.warnings, "friction_lock", opt);
    sum.status = st;
    sum.counters = others;
    add_counters(sum.counters, ws.counters, before);
    add_counters(sum.counters, counted_begin, counted_end);  // − (counted_end − counted_begin)
    sum.solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return st;
  };

  const double lo = std::min(opt.t_begin, opt.t_end), hi = std::max(opt.t_begin, opt.t_end);
  if (lo < model.time_domain_begin() || hi > model.time_domain_end()) {
    const double bad = lo < model.time_domain_begin() ? lo : hi;
    sum.failed_step = lo < model.time_domain_begin() ? (opt.t_begin <= opt.t_end ? 0 : opt.steps)
                                                     : (opt.t_begin <= opt.t_end ? opt.steps : 0);
    sum.failed_time = bad;
    sum.message = "t = " + format_time(bad) + ": driver '" + model.time_domain_limiter() + "' is defined on [" +
                  format_time(model.time_domain_begin()) + ", " + format_time(model.time_domain_end()) +
                  "] only; the sweep runs over [" + format_time(lo) + ", " + format_time(hi) + "]";
    return done(SolveStatus::kOutsideTimeDomain);
  }

  ws.start_afresh();  // the sweep's results depend on the model, the options and ws.q only
  Run run{opt, on_step, sum, writer};
  run.limits = &limits;
  Sweeper sw(model, opt, ws, sum);
  if (!sw.assemble(run.time_of(0))) {
    run.failed(0);
    return done(sum.status);
  }
  note_parameters_nothing_reads(opt, sum);
  if (!sw.row_outputs(0)) {
    run.failed(0);
    return done(sum.status);
  }
  if (!run.deliver(0, sw.state().q, sw.state().qd, sw.state().qdd, sw.motions(), ws.phi, sw.rcond(), sw.det_sign(),
                   sw.det_sign_time(), sw.row_quality())) {
    sw.leave_state_in_workspace();
    return done(sum.status);
  }

  if (opt.threads == 0 && threads > 1 && ws.lu && opt.steps > 0)
    threads = detail::threads_that_fit(opt, ws, threads, run.time_of(0), sum.warnings);
  // The chunks are cut alike for every thread count (automatic_chunk_steps), and a chunk computes the same rows
  // whichever thread runs it (each starts from a workspace started afresh): one thread runs them in order, with
  // their seeds, so that its rows are, to the bit, those of any other thread count.
  // (a writer reads every row as a step callback does: the chunks are cut as for one)
  const detail::HeldRows rows =
      detail::held_rows(model, opt, static_cast<bool>(on_step) || writer || run.delivery_reads_rows(),
                        run.chunks_encode() ? writer->max_row_bytes() : 0);
  const Index chunk = opt.chunk_steps > 0 ? opt.chunk_steps
                                          : detail::automatic_chunk_steps(opt, rows.row_bytes, rows.caller_reads_rows);
  const Index n_chunks = (opt.steps + chunk - 1) / chunk;  // chunk c: rows 1 + c·chunk … min(steps, (c+1)·chunk)
  if (ws.lu)
    threads = detail::threads_with_room_for_rows(opt, rows.row_bytes, rows.held_bytes(chunk), rows.caller_reads_rows,
                                                 chunk, threads, run.time_of(0), sum.warnings);
  if (n_chunks < 2 || !ws.lu) {
    run.sequential(sw, ws, 1);
    sw.leave_state_in_workspace();
    return done(sum.status);
  }

  detail::parallel_sweep(model, opt, ws, run, sw, rows, chunk, n_chunks, threads, others, counted_begin, counted_end);
  return done(sum.status);
}

}  // namespace

void detail::check_efforts(const Model& model, const OutputPlan& plan, const std::string& who) {
  const OutputEfforts& e = plan.efforts;
  if (!e.active()) return;
  if (!e.parts || !e.loads) throw Error(who + ": efforts need the parts and the loads");
  for (const OutputReaction& r : e.reactions) {
    if (r.natural >= 0) {
      if (!e.natural || static_cast<std::size_t>(r.natural) >= e.natural->joints.size() ||
          r.spatial != e.natural->spatial)
        throw Error(who + ": a reaction's natural joint " + std::to_string(r.natural) + " is not one of the efforts'");
      continue;
    }
    if (r.constraint < 0 || r.constraint >= static_cast<Index>(model.constraints().size()))
      throw Error(who + ": a reaction's constraint " + std::to_string(r.constraint) + " is not one of the model's");
    const ConstraintInfo& c = model.constraints()[static_cast<std::size_t>(r.constraint)];
    const int width = reaction_width(model, r.constraint);
    if (width == 0)
      throw Error(who + ": '" + c.name + "' (" + std::string(c.kind) + ") states no joint point: it has no reaction");
    if (r.spatial != (width == 6)) throw Error(who + ": reaction '" + c.name + "': `spatial` does not match its kind");
  }
  for (Index c : e.constraints) {
    if (c < 0 || c >= static_cast<Index>(model.constraints().size()))
      throw Error(who + ": an effort's constraint " + std::to_string(c) + " is not one of the model's");
    const ConstraintInfo& info = model.constraints()[static_cast<std::size_t>(c)];
    if (!has_effort(info))
      throw Error(who + ": '" + info.name + "' does not depend on time: no motor drives it, it has no effort");
  }
  for (const Part& p : *e.parts)
    if (max_coordinate(p.frame) >= model.num_coordinates())
      throw Error(who + ": part '" + p.name + "' reads a coordinate the model does not have");
  std::vector<const BearingFriction*> bearings;  // OutputLoss::index's order: the bearings, then the gear losses
  if (const AppliedLoads* a = e.loads->applied.get())
    for (const TorsionalSpring& s : a->torsional_springs)
      if (s.bearing) bearings.push_back(&*s.bearing);
  const std::size_t gears = e.loads->applied ? e.loads->applied->gear_losses.size() : 0;
  for (const OutputLoss& l : e.losses)
    if (l.bearing ? l.index >= bearings.size() || l.slide != bearings[l.index]->slide
                  : l.index < bearings.size() || l.index >= bearings.size() + gears)
      throw Error(who + ": loss '" + l.name + "' (" + std::to_string(l.index) + ") is not one of the loads' " +
                  (l.bearing ? (l.slide ? "slides" : "bearings") : "gear losses"));
}

void detail::check_solver_settings(const Model& model, const SolverSettings& s, const std::vector<OutputPoint>& points,
                                   const std::vector<OutputSensitivity>& sensitivities, const std::string& who) {
  for (const OutputSensitivity& p : sensitivities)
    if (const std::string why = check_sensitivity_models(model, p); !why.empty()) throw Error(who + ": " + why);
  if (s.max_subdivisions < 0) throw Error(who + ": max_subdivisions must be >= 0");
  const std::vector<Predictor>& predictors = all_predictors();
  if (std::find(predictors.begin(), predictors.end(), s.predictor) == predictors.end())
    throw Error(who + ": predictor is not a Predictor");
  detail::check_newton_options(s.assembly, (who + "::assembly").c_str());
  detail::check_newton_options(s.newton, (who + "::newton").c_str());
  for (const OutputPoint& p : points)
    if (p.max_coordinate() >= model.num_coordinates())
      throw Error(who + ": output point '" + p.name + "' reads a coordinate the model does not have");
}

namespace {

SolveStatus run_sweep_with(const Model& model, const SweepOptions& opt, Workspace& ws,
                           const std::function<bool(const StepView&)>& on_step, RowWriter* writer,
                           SweepSummary* summary) {
  if (opt.threads < 0 || opt.threads > detail::kMaxThreads)
    throw Error("SweepOptions: threads must be from 0 (all cores) to 1000000, not " + std::to_string(opt.threads));
  // Everything the sweep runs, the model's parallel evaluation of large models included, stays on its threads:
  // threads = 1 is one thread.
  const int threads = opt.threads == 0 ? tbb::info::default_concurrency() : opt.threads;
  tbb::task_arena arena(threads);
  // Each parameter's reach, found once here when the caller did not give it: every row then evaluates along p only
  // the constraints p reaches.
  if (std::any_of(opt.sensitivities.begin(), opt.sensitivities.end(), [](const auto& p) { return !p.reach; })) {
    SweepOptions with_reach = opt;
    for (OutputSensitivity& p : with_reach.sensitivities)
      if (!p.reach) p.reach = std::make_shared<const ParameterReach>(parameter_reach(model, p));
    return arena.execute([&] { return sweep_in_arena(model, with_reach, ws, on_step, writer, summary, threads); });
  }
  return arena.execute([&] { return sweep_in_arena(model, opt, ws, on_step, writer, summary, threads); });
}

}  // namespace

SolveStatus run_sweep(const Model& model, const SweepOptions& opt, Workspace& ws,
                      const std::function<bool(const StepView&)>& on_step, SweepSummary* summary) {
  return run_sweep_with(model, opt, ws, on_step, nullptr, summary);
}

SolveStatus run_sweep(const Model& model, const SweepOptions& opt, Workspace& ws, RowWriter& writer,
                      SweepSummary* summary) {
  return run_sweep_with(model, opt, ws, {}, &writer, summary);
}

Index rows_written(const SweepOptions& o) {
  if (std::isinf(o.window_begin) && std::isinf(o.window_end)) return o.steps / o.every + 1;
  Index n = 0;
  for (Index k = 0; k <= o.steps; k += o.every) n += o.writes_row(k, o.time_of(k)) ? 1 : 0;
  return n;
}

}  // namespace phiq
