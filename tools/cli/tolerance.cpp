// `phiq tolerance SCENE --sd P=σ ... -o OUT.csv`: the spread of the scene's outputs over toleranced parameters,
// first order from the exact sensitivities of one nominal sweep, and Monte Carlo from sampled parameter sets swept in
// parallel on the nominal model's symbolic analysis (run_cases: over this process's threads and, under mpirun, the
// ranks), with their agreement. The numbers are tools/tolerance/; what is written, tolerance_report.*; the format,
// tools/README.md.
#include <signal.h>
#include <tbb/info.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <memory>
#include <new>
#include <optional>
#include <set>

#include "batch_ranks.hpp"  // run_cases: the samples on the threads (and MPI ranks)
#include "cli_support.hpp"
#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "host_info.hpp"  // memory_available: --samples refused when their outputs cannot fit
#include "tolerance_input.hpp"
#include "tolerance_report.hpp"
#include "tolerance_spread.hpp"
#include "phiq/parsed_scene.hpp"  // the cases, read from one parse per thread
#include "phiq/phiq.hpp"

namespace phiq::tools {

namespace {

using tolerance::OutputSpread;
using tolerance::ParameterSpread;

struct ToleranceArgs {
  std::string scene, out, summary, plot, plot_column, covariance;
  std::vector<std::string> sd, limit, columns, sets;
  long samples = 1000;
  std::uint64_t seed = 1;
  int threads = 0;
  double threshold = 4.0;
  std::string names = "dotted";
  bool quiet = false;
};

// An output: coordinate `coordinate`'s value (order 0), velocity (1) or acceleration (2).
struct OutputColumn {
  std::string name;  // dotted
  Index coordinate = 0;
  int order = 0;
};

// The coordinate columns the scene writes (with `.v` / `.a` when it writes them), the outputs by default.
std::vector<OutputColumn> written_columns(const Scene& scene) {
  std::vector<OutputColumn> cols;
  const auto& names = scene.model->coordinate_names();
  for (Index j : scene.sweep.coordinate_columns) cols.push_back({names[static_cast<std::size_t>(j)], j, 0});
  for (Index j : scene.sweep.written_velocities()) cols.push_back({names[static_cast<std::size_t>(j)] + ".v", j, 1});
  for (Index j : scene.sweep.written_accelerations()) cols.push_back({names[static_cast<std::size_t>(j)] + ".a", j, 2});
  return cols;
}

// The outputs asked for by --columns (dotted or identifier names): a coordinate, with `.v` / `.a` when the scene
// solves velocities / accelerations. Throws phiq::Error naming the first that is none.
std::vector<OutputColumn> asked_columns(const Scene& scene, const std::vector<std::string>& asked) {
  std::vector<OutputColumn> all;
  const auto& names = scene.model->coordinate_names();
  for (std::size_t j = 0; j < names.size(); ++j) {
    const Index i = static_cast<Index>(j);
    all.push_back({names[j], i, 0});
    if (scene.sweep.velocities) all.push_back({names[j] + ".v", i, 1});
    if (scene.sweep.accelerations) all.push_back({names[j] + ".a", i, 2});
  }
  std::vector<OutputColumn> cols;
  for (const std::string& a : asked) {
    const OutputColumn* found = nullptr;
    for (const OutputColumn& c : all)
      if (c.name == a || identifier_column_name(c.name) == a) found = &c;
    if (!found) {
      std::vector<std::string> listed;
      for (const OutputColumn& c : written_columns(scene)) listed.push_back(c.name);
      throw Error("--columns: '" + a + "' is not an output of " + scene.path +
                  " (a coordinate, with .v / .a when the scene solves velocities / accelerations; its columns: " +
                  joined(listed) + ")");
    }
    for (const OutputColumn& c : cols)
      if (c.name == found->name) throw Error("--columns: '" + a + "' is listed twice");
    cols.push_back(*found);
  }
  return cols;
}

// The sweep of a sampled case computes the outputs' coordinates and derivatives only: no points, joints,
// orientations, residuals, rcond or sensitivities (they cost time and nothing here reads them).
SweepOptions case_sweep(SweepOptions o) {
  o.sensitivities.clear();
  o.points.clear(), o.joints.clear(), o.orientations.clear();
  o.residuals = false, o.condition = false;
  o.residual_columns.clear(), o.max_residual_column = false, o.driver_columns.clear();
  return o;
}

// One sampled case: built from its worker's own parsed tree, made square and swept on one thread (so the same
// values, bit for bit, on whichever thread or rank it runs); `values` its outputs row after row, or `why` it failed.
struct SampledCase {
  std::vector<double> values;
  std::string why;
};
SampledCase sample_case(ParsedScene& tree, const SceneOverrides& o, const std::vector<double>& t,
                        const std::vector<OutputColumn>& columns, const std::atomic<bool>& stop) {
  SampledCase c;
  Scene scene;
  try {
    scene = tree.read(o);
  } catch (const SceneError& e) {
    c.why = e.what();
    return c;
  }
  SquareScene square;
  if (const auto why = make_square(scene, &square)) {
    c.why = *why;
    return c;
  }
  const Model& model = square.model(*scene.model);
  Workspace ws(model);
  ws.q = square.start;
  SweepOptions one = case_sweep(scene.sweep);
  one.threads = 1;
  std::size_t rows = 0;
  const char* grid = "its time grid differs from the nominal scene's (a parameter sets the sweep's time range)";
  SweepSummary s;
  (void)run_sweep(
      model, one, ws,
      [&](const StepView& step) {
        const std::size_t r = rows++;
        if (r >= t.size() || std::fabs(step.t - t[r]) > 1e-12 * (1.0 + std::fabs(t[r]))) {
          c.why = grid;
          c.values.clear();
          return false;
        }
        for (const OutputColumn& col : columns)
          c.values.push_back((col.order == 0 ? step.q : col.order == 1 ? *step.qd : *step.qdd)(col.coordinate));
        return !stop.load();
      },
      &s);
  if (c.why.empty() && s.status != SolveStatus::kSuccess) c.why = s.message;
  if (c.why.empty() && rows != t.size()) c.why = grid;
  if (!c.why.empty()) c.values.clear();
  return c;
}

// Why the outputs of `samples` cases (each `rows` × `outputs` values kept to the end, with its parameters' and its
// bookkeeping) cannot fit in the memory this process may still take; nothing when they can, or it is unknown.
std::optional<std::string> samples_out_of_memory(const ToleranceArgs& a, std::size_t rows, std::size_t outputs,
                                                 std::size_t parameters) {
  const double per_case = 8.0 * static_cast<double>(rows * outputs + 2 * parameters) + 96.0;
  const double need = per_case * static_cast<double>(a.samples), have = memory_available();
  if (!(have > 0.0) || need <= have) return std::nullopt;
  auto gb = [](double bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g GB", bytes / 1e9);
    return std::string(text);
  };
  return a.scene + ": --samples " + std::to_string(a.samples) + " would keep " + gb(need) + " of outputs (" +
         std::to_string(rows) + " rows × " + std::to_string(outputs) + " outputs a case) and " + gb(have) +
         " are available: fewer --samples or --columns; no output written";
}

// What the command reads before it sweeps: the toleranced parameters, the scene at their nominal values, the
// outputs and the plotted one. `status` is non-zero when the command stops (its line printed).
struct ToleranceSetup {
  int status = 0;
  ParameterSpread spread;
  SceneOverrides settings;  // --set: the nominal point's other parameters (a toleranced one's nominal value too)
  Scene scene;
  std::vector<double> nominal;
  std::vector<OutputColumn> columns;
  std::size_t plotted = 0;
  bool identifiers = false;
};

// The parameters, their covariance and the scene (with each toleranced parameter's model for its sensitivities).
ToleranceSetup read_tolerance_setup(const ToleranceArgs& a) {
  ToleranceSetup u;
  auto stop = [&](const std::string& line, int code) {
    u.status = fail(line, code);
    return std::move(u);
  };
  std::vector<tolerance::Tolerance> given;
  std::optional<tolerance::Covariance> covariance;
  try {
    u.settings = parameter_settings(a.sets);
    for (const std::string& s : a.sd) given.push_back(tolerance::parse_tolerance("--sd", s));
    for (const std::string& s : a.limit) given.push_back(tolerance::parse_tolerance("--limit", s));
    if (!a.covariance.empty()) covariance = tolerance::read_covariance(a.covariance);
    if (given.empty() && !covariance)
      throw Error("no toleranced parameter: give --sd NAME=SD, --limit NAME=L or --covariance FILE");
    u.spread = tolerance::parameter_spread(given, covariance ? &*covariance : nullptr);
  } catch (const Error& e) {
    return stop("tolerance: " + std::string(e.what()), 2);
  }
  set_interrupt_subject(a.scene, "; no output written");
  try {
    SceneOverrides o = u.settings;
    o.sensitivity_models = false;  // the scene's own output.sensitivities are not swept here
    u.scene = load_scene(a.scene, SceneLimits{}, o);
  } catch (const SceneError& e) {
    return stop(e.what(), 2);
  }
  for (const tolerance::Tolerance& t : u.spread.parameters) {
    const auto it = std::find_if(u.scene.parameters.begin(), u.scene.parameters.end(),
                                 [&](const auto& p) { return p.first == t.name; });
    if (it == u.scene.parameters.end()) {
      std::vector<std::string> names;
      for (const auto& p : u.scene.parameters) names.push_back(p.first);
      const std::string where = t.from_covariance                                     ? a.covariance
                                : t.distribution == tolerance::Distribution::kUniform ? "tolerance: --limit"
                                                                                      : "tolerance: --sd";
      return stop(where + ": '" + t.name + "' is not a parameter of " + a.scene +
                      (names.empty() ? " (it has none)" : " (its parameters: " + joined(names) + ")"),
                  2);
    }
    u.nominal.push_back(it->second);
  }
  try {
    u.columns = a.columns.empty() ? written_columns(u.scene) : asked_columns(u.scene, a.columns);
  } catch (const Error& e) {
    return stop("tolerance: " + std::string(e.what()), 2);
  }
  if (u.columns.empty()) return stop("tolerance: " + a.scene + " writes no coordinate column: give --columns", 2);
  if (!a.plot_column.empty()) {
    auto it = std::find_if(u.columns.begin(), u.columns.end(), [&](const OutputColumn& c) {
      return c.name == a.plot_column || identifier_column_name(c.name) == a.plot_column;
    });
    if (it == u.columns.end())
      return stop("tolerance: --plot-column: '" + a.plot_column + "' is not one of the outputs (--columns)", 2);
    u.plotted = static_cast<std::size_t>(it - u.columns.begin());
  }
  u.identifiers = a.names == "identifiers";
  if (u.identifiers) {  // names that would collide as identifiers: the scene's to change
    std::set<std::string> seen{"t"};
    for (const OutputColumn& c : u.columns)
      for (const char* suffix : {"", ".sd_linear", ".sd_mc", ".mean_mc"})
        if (!seen.insert(identifier_column_name(c.name + suffix)).second)
          return stop(
              "tolerance: --names identifiers: two columns would be named " + identifier_column_name(c.name + suffix),
              2);
  }

  // the models along each parameter (sensitivities), sharing the nominal model's analysis
  u.scene.sweep.sensitivities.clear();  // the scene's own (read without their models)
  for (std::size_t j = 0; j < u.spread.parameters.size(); ++j) {
    SceneOverrides o = u.settings;
    o.sensitivity_models = false;  // (as the nominal scene was read)
    try {
      u.scene.sweep.sensitivities.push_back(
          sensitivity_along(u.scene, u.spread.parameters[j].name, u.nominal[j], 0.0, {}, o));
    } catch (const SceneError& e) {
      return stop(a.scene + ": " + e.what(), 2);
    }
  }
  // The nominal sweep's written coordinates are the outputs' (--columns may name coordinates the scene does not
  // write): the adjoint form, which the sweep takes when the parameters outnumber them, solves for exactly those.
  std::vector<Index> outs;
  for (const OutputColumn& c : u.columns) outs.push_back(c.coordinate);
  std::sort(outs.begin(), outs.end());
  outs.erase(std::unique(outs.begin(), outs.end()), outs.end());
  u.scene.sweep.coordinate_columns = outs;
  u.scene.sweep.velocity_columns = u.scene.sweep.acceleration_columns = outs;
  return u;
}

// The nominal sweep: the outputs' values and first-order spreads at every row, and each parameter's largest
// sensitivity (zero: no output depends on it).
struct NominalSweep {
  std::vector<double> t;
  std::vector<OutputSpread> spreads;
  std::vector<double> largest_sensitivity;
  SweepSummary summary;
};
NominalSweep nominal_sweep(const ToleranceSetup& u, const Model& model, const Eigen::VectorXd& start,
                           const std::atomic<bool>& stop) {
  const std::size_t np = u.spread.parameters.size();
  const SensitivityLayout layout{model.num_coordinates()};
  NominalSweep n;
  n.spreads.resize(u.columns.size());
  for (std::size_t o = 0; o < u.columns.size(); ++o) n.spreads[o].name = u.columns[o].name;
  n.largest_sensitivity.assign(np, 0.0);
  Workspace ws(model);
  ws.q = start;
  Eigen::VectorXd g(static_cast<Eigen::Index>(np));
  (void)run_sweep(
      model, u.scene.sweep, ws,
      [&](const StepView& step) {
        n.t.push_back(step.t);
        for (std::size_t o = 0; o < u.columns.size(); ++o) {
          const OutputColumn& c = u.columns[o];
          const Eigen::VectorXd& v = c.order == 0 ? step.q : c.order == 1 ? *step.qd : *step.qdd;
          n.spreads[o].nominal.push_back(v(c.coordinate));
          for (std::size_t j = 0; j < np; ++j) {
            g(static_cast<Eigen::Index>(j)) = step.sensitivities[layout.offset(j, c.order) + c.coordinate];
            if (std::isfinite(g(static_cast<Eigen::Index>(j))))
              n.largest_sensitivity[j] = std::max(n.largest_sensitivity[j], std::fabs(g(static_cast<Eigen::Index>(j))));
          }
          n.spreads[o].sd_linear.push_back(tolerance::linear_sd(g, u.spread.sigma));
        }
        return !stop.load();
      },
      &n.summary);
  return n;
}

// The sampled cases, handed out one at a time to this process's threads (and, under mpirun, to every rank's: rank 0
// gathers their values), each read from a parsed tree of its thread's own (no YAML parse per case) and swept on one
// thread: the same values wherever it runs. Each built from its parameter values (offsets from the nominal ones),
// sharing the nominal model's analysis. Returns the status (non-zero: its line printed; every rank but 0 returns 0
// when its cases are done).
struct SampledCases {
  tolerance::CaseValues cases;
  std::vector<std::string> why_failed;
  int threads_used = 0;
};
int sample_cases(const ToleranceArgs& a, const ToleranceSetup& u, const std::vector<double>& t,
                 const Eigen::MatrixXd& offsets, BatchRanks& ranks, const std::atomic<bool>& stop, SampledCases& out) {
  const std::size_t np = u.spread.parameters.size(), n_cases = static_cast<std::size_t>(a.samples);
  out.why_failed.assign(n_cases, "");
  out.cases.rows = t.size(), out.cases.outputs = u.columns.size();
  out.cases.values.resize(n_cases);
  out.threads_used = a.threads <= 0 ? tbb::info::default_concurrency() : a.threads;
  auto overrides_of = [&](std::size_t k) {
    SceneOverrides o;
    for (std::size_t j = 0; j < np; ++j)
      o.parameters.emplace_back(u.spread.parameters[j].name,
                                u.nominal[j] + offsets(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j)));
    for (const auto& set : u.settings.parameters)  // the sampled values replace a toleranced one's
      if (std::none_of(o.parameters.begin(), o.parameters.end(), [&](const auto& p) { return p.first == set.first; }))
        o.parameters.push_back(set);
    o.share_analysis_with = u.scene.model.get();
    o.sensitivity_models = false;
    return o;
  };
  std::vector<ParsedScene> trees(static_cast<std::size_t>(out.threads_used), ParsedScene(u.scene.text, u.scene.path));
  CaseHandlers h;
  h.run_here = [&](std::size_t k, int w) {
    SampledCase c = sample_case(trees[static_cast<std::size_t>(w)], overrides_of(k), t, u.columns, stop);
    out.cases.values[k] = std::move(c.values), out.why_failed[k] = std::move(c.why);
  };
  h.run_for_0 = [&](std::size_t k, int w) {
    const SampledCase c = sample_case(trees[static_cast<std::size_t>(w)], overrides_of(k), t, u.columns, stop);
    CaseMessage m;
    m.kind = stop.load() ? CaseMessage::Kind::kStopped : CaseMessage::Kind::kDone;
    m.k = static_cast<std::int64_t>(k);
    m.complete = true, m.failed = !c.why.empty();
    m.line = c.why;
    if (!c.values.empty())
      m.values.assign(reinterpret_cast<const char*>(c.values.data()), c.values.size() * sizeof(double));
    return m;
  };
  std::atomic<bool> remote_stop{false};
  h.deliver = [&](CaseMessage m) {
    if (m.kind == CaseMessage::Kind::kStopped) remote_stop = true;
    if (m.kind != CaseMessage::Kind::kDone) return;
    const auto k = static_cast<std::size_t>(m.k);
    out.why_failed[k] = std::move(m.line);
    std::vector<double>& v = out.cases.values[k];
    v.resize(m.values.size() / sizeof(double));
    if (!v.empty()) std::memcpy(v.data(), m.values.data(), v.size() * sizeof(double));
  };
  h.halted = [&] { return stop.load() || remote_stop.load(); };
  try {
    out.threads_used = run_cases(ranks, 0, n_cases, out.threads_used, h);
  } catch (const std::bad_alloc& e) {  // a worker's, any rank's: the cases' outputs and models took what there was
    return fail(a.scene + ": out of memory with " + std::to_string(n_cases) + " samples " +
                    out_of_memory_where(e, out.threads_used) +
                    " (fewer --samples, --columns or --threads); no output written",
                1);
  }
  if (ranks.rank() != 0) return 0;  // (rank 0 reports)
  if (stop.load() || remote_stop.load())
    return fail(
        a.scene + ": interrupted (" + signal_name(stop.load() ? interrupt_signal() : SIGTERM) + "); no output written",
        128 + (stop.load() ? interrupt_signal() : SIGTERM));
  return 0;
}

// The report on standard error: failures always, the rest unless --quiet.
void report_tolerance(const ToleranceArgs& a, const ToleranceRun& run, const ParameterSpread& spread,
                      const std::vector<OutputSpread>& spreads, std::size_t succeeded, bool summary_written,
                      const BatchRanks& ranks) {
  const auto& failed = run.failed;
  const auto n_cases = static_cast<std::size_t>(a.samples);
  const std::size_t shown = std::min<std::size_t>(failed.size(), 20);
  for (std::size_t i = 0; i < shown; ++i)
    std::cerr << "phiq: " << printable(a.scene + ": " + case_label(failed[i], spread) + ": " + failed[i].message)
              << "\n";
  if (failed.size() > shown)
    std::cerr << "phiq: " << printable(a.scene) << ": and " << failed.size() - shown << " more failed cases"
              << (summary_written ? " (all named in the summary)" : " (--summary names them all)") << "\n";
  if (!failed.empty())
    std::cerr << "phiq: " << printable(a.scene) << ": " << failed.size() << " of " << n_cases
              << " sampled cases failed (left out of the Monte Carlo spread)\n";
  for (const std::string& p : run.independent)
    std::cerr << "phiq: " << printable(a.scene) << ": note: no output depends on " << p
              << " (its sensitivities are zero at every row)\n";
  std::size_t disagreeing = 0;
  for (const OutputSpread& s : spreads) {
    if (!s.agreement.disagrees) continue;
    ++disagreeing;
    std::cerr << "phiq: " << printable(a.scene + ": " + s.name)
              << ": linear and Monte Carlo spreads disagree: " << significant(s.agreement.worst, 3)
              << " standard errors at t = " << format_time(s.agreement.worst_t) << " (sd_linear "
              << significant(s.agreement.sd_linear_at_worst, 4) << ", sd_mc "
              << significant(s.agreement.sd_mc_at_worst, 4)
              << "; expected near a singular position, where the first-order model fails)\n";
  }
  if (a.quiet) return;
  double worst = 0.0;
  std::string where;
  for (const OutputSpread& s : spreads)
    if (s.agreement.worst >= worst) worst = s.agreement.worst, where = s.name;
  std::cerr << "phiq: " << printable(a.scene) << ": " << succeeded << " of " << n_cases << " cases on "
            << (ranks.size() > 1 ? ranks.describe() + ", " : "") << run.threads << " threads, " << spreads.size()
            << " outputs, " << disagreeing << " disagreeing (worst " << significant(worst, 3) << " standard errors, "
            << printable(where) << "; threshold " << significant(a.threshold, 3) << "), "
            << scientific(run.solve_seconds, 3) << " s; wrote " << printable(a.out) << "\n";
}

int cmd_tolerance(const ToleranceArgs& a, BatchRanks& ranks) {
  const bool writer = ranks.rank() == 0;  // under mpirun, rank 0 alone writes and prints
  std::vector<NamedPath> outs{{"-o", a.out}};
  if (!a.summary.empty()) outs.push_back({"--summary", a.summary});
  if (!a.plot.empty()) outs.push_back({"--plot", a.plot});
  if (const auto clash = output_clash(outs, {{"the scene", a.scene}, {"the covariance", a.covariance}}))
    return fail("tolerance: " + *clash, 2);
  ToleranceSetup u = read_tolerance_setup(a);
  if (u.status != 0) return u.status;
  const ParameterSpread& spread = u.spread;

  // Every output exists before the sweeps: an unwritable path fails now; all are committed together at the end.
  OutputSet outputs;
  AtomicOutputFile *csv_file = nullptr, *summary_file = nullptr, *plot_file = nullptr;
  int status = 0;
  if (writer) {
    if (const auto why = samples_out_of_memory(a, static_cast<std::size_t>(rows_written(u.scene.sweep)),
                                               u.columns.size(), spread.parameters.size()))
      status = fail(*why, 1);
  }
  if (writer && status == 0) {
    try {
      csv_file = &outputs.add(a.out);
      if (!a.summary.empty()) summary_file = &outputs.add(a.summary);
      if (!a.plot.empty()) plot_file = &outputs.add(a.plot);
    } catch (const Error& e) {
      status = fail(e.what(), 3);
    }
  }
  if ((status = ranks.agree(status)) != 0) return status;  // every rank stops where rank 0 could not go on
  const auto start = Clock::now();
  StopOnSignal stop_on_signal;
  const std::atomic<bool>& stop = stop_flag();

  SquareScene square;
  if (const auto why = make_square(u.scene, &square)) return fail(a.scene + ": the nominal scene: " + *why, 1);
  const Model& model = square.model(*u.scene.model);
  NominalSweep n = nominal_sweep(u, model, square.start, stop);
  if (stop.load()) return fail(a.scene + ": " + interrupt_message() + "; no output written", interrupt_exit_status());
  if (n.summary.status != SolveStatus::kSuccess)
    return fail(a.scene + ": the nominal scene: " + n.summary.message + "; no output written", 1);

  const Eigen::MatrixXd offsets = tolerance::sample_offsets(spread, a.samples, a.seed);
  SampledCases sampled;
  if (const int s = sample_cases(a, u, n.t, offsets, ranks, stop, sampled); s != 0 || !writer) return s;
  const auto n_cases = static_cast<std::size_t>(a.samples);
  tolerance::CaseValues& cases = sampled.cases;
  ToleranceRun run;
  for (std::size_t k = 0; k < n_cases; ++k)
    if (!sampled.why_failed[k].empty()) {
      cases.values[k].clear();
      std::vector<double> v(spread.parameters.size());
      for (std::size_t j = 0; j < v.size(); ++j)
        v[j] = u.nominal[j] + offsets(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j));
      run.failed.push_back({k, v, sampled.why_failed[k]});
    }
  const std::size_t succeeded = cases.succeeded();

  // ---- the Monte Carlo moments and the agreement
  std::vector<OutputSpread>& spreads = n.spreads;
  tolerance::monte_carlo_moments(cases, spreads);
  // a spread at the solver's tolerance is its noise, not the tolerances' (tolerance_spread.hpp)
  run.floor = 10.0 * u.scene.sweep.newton.tolerance * std::max(model.length_scale(), 1.0);
  for (OutputSpread& s : spreads) {
    double scale = 1.0;
    for (double y : s.nominal) scale = std::max(scale, std::fabs(y));
    s.agreement = tolerance::agreement(s, n.t, succeeded, run.floor * scale, a.threshold);
  }
  run.scene_path = a.scene, run.scene_name = u.scene.name, run.spread = &spread, run.nominal = u.nominal;
  run.covariance_file = a.covariance, run.samples = a.samples, run.seed = a.seed, run.threshold = a.threshold;
  run.threads = sampled.threads_used, run.solve_seconds = since(start);
  run.sensitivity_form = to_string(n.summary.sensitivity_form);
  for (std::size_t j = 0; j < spread.parameters.size(); ++j)
    if (n.largest_sensitivity[j] == 0.0) run.independent.push_back(spread.parameters[j].name);
  if (succeeded < 2)
    return fail(a.scene + ": " + std::to_string(succeeded) + " of " + std::to_string(n_cases) +
                    " sampled cases succeeded: no Monte Carlo spread (first failure: " +
                    (run.failed.empty() ? std::string("none")
                                        : case_label(run.failed.front(), spread) + ": " + run.failed.front().message) +
                    "); no output written",
                1);

  // ---- the outputs, committed together
  try {
    csv_file->write(tolerance_csv(n.t, spreads, u.identifiers));
    if (summary_file) summary_file->write(json_text(tolerance_summary(run, spreads), 2) + "\n");
    if (plot_file) plot_file->write(tolerance_svg(u.scene, n.t, spreads[u.plotted], succeeded));
    outputs.commit();
  } catch (const Error& e) {
    return fail(e.what(), 3);
  }
  report_tolerance(a, run, spread, spreads, succeeded, summary_file != nullptr, ranks);
  return 0;
}

}  // namespace

Command register_tolerance(CLI::App& app) {
  auto a = std::make_shared<ToleranceArgs>();
  CLI::App* tol = app.add_subcommand(
      "tolerance", "Spread of the outputs over toleranced parameters: first order (sensitivities) and Monte Carlo");
  tol->add_option("scene", a->scene, "Scene file (YAML)")->required();
  tol->add_option("-o,--output", a->out,
                  "CSV to write: t, then per output y, y.sd_linear, y.sd_mc, y.mean_mc "
                  "('-': standard output)")
      ->required()
      ->transform(output_path("", false));
  tol->add_option("--sd", a->sd, "NAME=SD: the parameter is normal with this standard deviation (repeat per parameter)")
      ->allow_extra_args(false);  // one NAME=SD an occurrence: the scene after it stays the scene
  tol->add_option("--limit", a->limit,
                  "NAME=L: the parameter is uniform on [p - L, p + L] (standard deviation L/sqrt(3))")
      ->allow_extra_args(false);
  tol->add_option("--covariance", a->covariance,
                  "CSV: a header of parameter names and their covariance matrix (symmetric positive definite), one "
                  "row per parameter; normal, correlated");
  tol->add_option("--samples", a->samples, "Monte Carlo parameter sets")
      ->capture_default_str()
      ->check(whole_number(2, 10'000'000));
  tol->add_option("--seed", a->seed, "Seed of the samples (std::mt19937_64, Box-Muller): the same seed, the same bytes")
      ->capture_default_str()
      ->check(any_whole_number());
  tol->add_option("--columns", a->columns,
                  "Outputs: coordinates, with .v/.a (default: every coordinate column the scene writes)")
      ->delimiter(',');
  tol->add_option("--threshold", a->threshold,
                  "Standard errors beyond which the linear and Monte Carlo spreads of an output disagree")
      ->capture_default_str()
      ->check(number(0.0, 1e6, false, "a positive number of standard errors"));
  tol->add_option("--summary", a->summary,
                  "Write the JSON summary (parameters, covariance, failed cases, agreement) "
                  "to this file ('-': standard output)")
      ->transform(output_path("", false));
  tol->add_option("--plot", a->plot, "Write an SVG of one output with its nominal curve and both ±2σ bands")
      ->transform(output_path("", false));
  tol->add_option("--plot-column", a->plot_column, "The output --plot draws (default: the first)");
  tol->add_option("--threads", a->threads, "Threads for the cases (0: all cores)")
      ->capture_default_str()
      ->check(thread_count());
  tol->add_option("--names", a->names, "Column names: dotted (xB.sd_mc) or identifiers (xB__sd_mc), as run's")
      ->capture_default_str()
      ->check(one_of({"dotted", "identifiers"}));
  tol->add_flag("-q,--quiet", a->quiet, "Print only failed cases and disagreements on standard error");
  add_set_option(tol, &a->sets);
  return {tol, [a] {
            a->threads = cap_threads("tolerance", a->threads, a->quiet);
            int status = 0;
            const std::unique_ptr<BatchRanks> ranks = BatchRanks::join_command("tolerance", "study", &status);
            if (!ranks) return status;
            return ranks->finish(with_stdout_checked(cmd_tolerance(*a, *ranks)));
          }};
}

}  // namespace phiq::tools
