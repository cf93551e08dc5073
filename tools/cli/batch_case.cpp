// One case of a one-file batch: swept on a worker's own parsed tree and formatted in its thread; and its message
// between ranks.
#include "batch_case.hpp"

#include <chrono>
#include <cstring>
#include <optional>

#include "command_support.hpp"
#include "run_summary.hpp"  // a case's outcome as run --summary writes it
#include "phiq/phiq.hpp"

namespace phiq::tools {

nlohmann::ordered_json initial_outcome(std::size_t k) {
  return nlohmann::ordered_json{{"case", k}, {"line", k + 2}, {"file", nullptr}};
}

CaseResult run_batch_case(const BatchCaseSetting& setting, std::size_t k, ParsedScene& tree, CaseRows rows) {
  const BatchArgs& a = setting.args;
  const bool hdf5 = setting.hdf5;
  CaseResult result;
  result.report.outcome = initial_outcome(k);
  CaseReport& report = result.report;
  auto fails = [&](const std::string& why) {
    report.complete = report.failed = true;
    report.line = a.scene + ": case " + std::to_string(k) + ": " + why + setting.left_out;
    return std::move(result);
  };
  const auto t0 = Clock::now();
  auto setup_done = [&] {
    result.setup_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0).count();
  };
  phiq::SceneOverrides o = case_overrides(setting.cases, k, a.cases);
  o.share_analysis_with = &setting.reference;
  o.sensitivities = a.sensitivities, o.sensitivities_source = "--sensitivity";
  std::optional<phiq::Scene> scene;
  try {
    scene = tree.read(o);
  } catch (const phiq::SceneError& e) {  // its parameters make the scene impossible (a negative length)
    report.outcome["status"] = "scene error";
    report.outcome["message"] = e.what();
    setup_done();
    return fails(std::string(e.what()) + " (line " + std::to_string(k + 2) + " of " + a.cases + ")");
  }
  phiq::SquareScene square;
  if (const auto why = make_square(*scene, &square)) {  // as `phiq run`: one that cannot be fails alone
    phiq::SweepSummary at_start;                        // the first position, before any sweep
    at_start.status = square.assembly.status;
    at_start.message = *why;
    at_start.failed_step = 0;
    at_start.failed_time = scene->sweep.t_begin;
    at_start.worst_rows = square.assembly.worst_rows;
    add_outcome(report.outcome, *scene->model, at_start);
    setup_done();
    return fails(*why);
  }
  const phiq::Model& model = square.model(*scene->model);
  result.on_shared_analysis = model.symbolic() && model.symbolic() == setting.reference.symbolic();
  phiq::Workspace ws(model);
  ws.q = square.start;
  phiq::SweepOptions one = scene->sweep;
  one.threads = 1;  // parallel over cases, not within one: each case computed alike on any thread or rank
  const phiq::CsvFormat rows_format(*scene->model, scene->sweep);  // the case's own output points
  const std::string prefix = std::to_string(k) + ",";
  bool last = false;
  std::vector<double> row(hdf5 ? 1 + rows_format.num_values() : 0);  // the case, then the row's values
  setup_done();
  long long format_case_ns = 0;
  phiq::SweepSummary s;
  (void)phiq::run_sweep(
      model, one, ws,
      [&](const phiq::StepView& step) {
        const auto f0 = Clock::now();
        if (hdf5) {  // the values Hdf5Writer::append_row() would store, the case first
          row[0] = static_cast<double>(k);
          rows_format.append_values(step, row.data() + 1);
          rows.values.insert(rows.values.end(), row.begin(), row.end());
        } else {
          rows.text += prefix;
          rows_format.append_row(step, rows.text);
        }
        last = step.step == one.steps;
        format_case_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - f0).count();
        return !setting.halted();
      },
      &s);
  result.format_ns = format_case_ns;
  result.sweep_ns = static_cast<long long>(s.solve_seconds * 1e9) - format_case_ns;
  add_outcome(report.outcome, model, s);
  report.outcome["steps"] = s.steps_completed;
  report.outcome["newton_iterations"] = s.counters.newton_iterations;
  // (a case whose last row was delivered is complete, even if a signal asked it to stop there)
  if (s.status == phiq::SolveStatus::kSuccess || (s.status == phiq::SolveStatus::kCancelled && last)) {
    report.complete = true;
    report.line = a.scene + ": case " + std::to_string(k) + ": " + s.BriefReport();
    rows.any = true;
    result.rows = std::move(rows);
    return result;
  }
  if (s.status != phiq::SolveStatus::kCancelled) return fails(s.message);
  return result;  // stopped before its end: it never completes, and no case after it is written
}

CaseMessage to_message(std::size_t k, const CaseResult& r, int signal) {
  CaseMessage m;
  m.kind = r.report.complete ? CaseMessage::Kind::kDone : CaseMessage::Kind::kStopped;
  m.k = static_cast<std::int64_t>(k);
  m.complete = r.report.complete, m.failed = r.report.failed, m.on_shared_analysis = r.on_shared_analysis;
  m.line = r.report.line;
  m.outcome_json = r.report.outcome.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
  m.text = r.rows.text;
  if (!r.rows.values.empty())
    m.values.assign(reinterpret_cast<const char*>(r.rows.values.data()), r.rows.values.size() * sizeof(double));
  m.setup_ns = r.setup_ns, m.sweep_ns = r.sweep_ns, m.format_ns = r.format_ns;
  m.signal = signal;
  return m;
}

CaseResult from_message(CaseMessage m) {
  CaseResult r;
  r.report.complete = m.complete, r.report.failed = m.failed;
  r.report.line = std::move(m.line);
  r.report.outcome = nlohmann::ordered_json::parse(m.outcome_json);
  r.rows.any = m.complete && !m.failed;
  r.rows.text = std::move(m.text);
  r.rows.values.resize(m.values.size() / sizeof(double));
  if (!r.rows.values.empty())  // (a CSV batch's cases carry none: memcpy to an empty vector's null is undefined)
    std::memcpy(r.rows.values.data(), m.values.data(), r.rows.values.size() * sizeof(double));
  r.on_shared_analysis = m.on_shared_analysis;
  r.setup_ns = m.setup_ns, r.sweep_ns = m.sweep_ns, r.format_ns = m.format_ns;
  return r;
}

}  // namespace phiq::tools
