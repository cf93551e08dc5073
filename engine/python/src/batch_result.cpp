// run_batch from Python: one scene swept for many sets of parameter values, as `phiq batch` sweeps them. The cases
// run in parallel on TBB's threads, each case on one: the scene read again from its parsed tree (a ParsedScene per
// thread, as the CLI's batch) with the scene's own loaded values and the case's over them, sharing the scene's
// pattern and symbolic analysis, then swept into a table of its own (the bits of run_sweep on that case's scene).
// The GIL is released for the whole batch; a case's thread takes it back only to set the case's options (run_batch's
// keyword arguments) and every 50 ms to let Python's signal handlers run, so that Ctrl-C stops every case at its
// next row.

#include "sweep_table.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <optional>

#include <phiq/parsed_scene.hpp>

namespace phiq::python {

namespace {

/// What the cases' sweeps left: each case's table, or the one line saying why its scene could not be read.
struct BatchTables {
  std::vector<std::shared_ptr<SweepTable>> tables;  // null where the case's scene could not be read
  std::vector<std::string> scene_errors;            // that line; empty for a swept case
  std::atomic<Index> shared_analyses{0};            // cases whose model shares the scene's symbolic analysis
};

/// The case's parameter values as overrides of the scene: the values the scene was loaded with (Scene::overridden),
/// those the case names replaced by the case's.
SceneOverrides case_overrides(const Scene& scene, const std::vector<std::string>& names, const double* values) {
  SceneOverrides o;
  o.parameters = scene.overridden;
  for (std::size_t j = 0; j < names.size(); ++j) {
    auto same = [&](const auto& p) { return p.first == names[j]; };
    if (auto it = std::find_if(o.parameters.begin(), o.parameters.end(), same); it != o.parameters.end())
      it->second = values[j];
    else
      o.parameters.emplace_back(names[j], values[j]);
  }
  o.parameters_source = "run_batch: cases";  // the names are the caller's, not any case's
  o.share_analysis_with = scene.model.get();
  return o;
}

py::dict batch_scene(const Scene& scene, const std::vector<std::string>& names,
                     const py::array_t<double, py::array::c_style | py::array::forcecast>& values,
                     const std::optional<py::list>& sensitivities, const py::dict& option_fields, bool identifier_names,
                     int threads) {
  if (values.ndim() != 2 || values.shape(1) != static_cast<py::ssize_t>(names.size()))
    throw Error("run_batch: the cases' values are " + std::to_string(values.ndim()) + "-dimensional with " +
                std::to_string(values.ndim() == 2 ? values.shape(1) : 0) +
                " columns; they need one column for each of the " + std::to_string(names.size()) + " parameter names");
  if (threads < 0 || threads > 1000000)  // (the engine's bound: a TBB arena of 10⁷ slots is SIGSEGV)
    throw Error("run_batch: threads must be from 0 (all cores) to 1000000, not " + std::to_string(threads));
  const std::size_t n = static_cast<std::size_t>(values.shape(0));
  const double* all_values = values.data();
  const std::vector<SensitivityRequest> asked =
      sensitivities ? sensitivity_requests(*sensitivities, "run_batch") : std::vector<SensitivityRequest>{};
  const std::vector<std::pair<std::string, py::object>> fields = [&] {
    std::vector<std::pair<std::string, py::object>> f;
    for (const auto& [name, value] : option_fields)
      f.emplace_back(name.cast<std::string>(), py::reinterpret_borrow<py::object>(value));
    return f;
  }();

  BatchTables out;
  out.tables.resize(n);
  out.scene_errors.resize(n);
  std::atomic<bool> stop{false};  // Ctrl-C: every case stops at its next check
  const int arena_threads = threads > 0 ? threads : tbb::info::default_concurrency();
  double seconds = 0.0;
  {
    py::gil_scoped_release free;
    // Names that are no parameter of the scene, and sensitivities no case could have, are the caller's error, not
    // every case's: the scene read once with the first case's names (its values' own errors are that case's).
    if (n > 0) {
      try {
        (void)parse_scene(scene.text, scene.path, SceneLimits{}, case_overrides(scene, names, all_values));
      } catch (const SceneError& e) {
        if (std::string(e.what()).rfind("run_batch: cases: ", 0) == 0) throw;
      }
    }
    if (!asked.empty()) (void)sensitivities_of(scene, asked, "run_batch: sensitivities");

    tbb::enumerable_thread_specific<std::unique_ptr<ParsedScene>> trees;  // a tree per thread (ParsedScene)
    auto keep_going = [&] {
      if (stop.load()) return false;
      py::gil_scoped_acquire hold;  // (only the main thread runs the handlers; the others find nothing to do)
      if (PyErr_CheckSignals() != 0) stop = true;  // the KeyboardInterrupt stays set on the main thread
      return !stop.load();
    };
    auto run_case = [&](std::size_t k) {
      std::unique_ptr<ParsedScene>& tree = trees.local();
      if (!tree) tree = std::make_unique<ParsedScene>(scene.text, scene.path);
      SceneOverrides o = case_overrides(scene, names, all_values + k * names.size());
      o.sensitivities = asked, o.sensitivities_source = "run_batch: sensitivities";  // (empty: the scene's own)
      std::optional<Scene> one;
      try {
        one = tree->read(o);
      } catch (const SceneError& e) {  // its values make the scene impossible (a negative length)
        out.scene_errors[k] = e.what();
        return;
      }
      SweepOptions opt = one->sweep;  // the case's own: its time range and points may depend on its values
      if (!fields.empty()) {
        py::gil_scoped_acquire hold;
        py::object o_py = py::cast(&opt, py::return_value_policy::reference);
        for (const auto& [name, value] : fields) py::setattr(o_py, name.c_str(), value);
      }
      opt.threads = 1;  // parallel over cases, not within one
      if (one->model->symbolic() && one->model->symbolic() == scene.model->symbolic()) ++out.shared_analyses;
      out.tables[k] = sweep_into_table(*one, opt, identifier_names, keep_going);
    };
    const auto start = std::chrono::steady_clock::now();
    tbb::task_arena arena(arena_threads);
    arena.execute([&] {
      tbb::parallel_for(
          tbb::blocked_range<std::size_t>(0, n, 1),
          [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t k = r.begin(); k != r.end() && !stop.load(); ++k) run_case(k);
          },
          tbb::simple_partitioner());
    });
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  if (stop.load()) throw py::error_already_set();

  py::list tables;
  for (auto& t : out.tables) tables.append(t ? py::cast(t) : py::none());
  py::dict d;
  d["tables"] = tables;
  d["scene_errors"] = out.scene_errors;
  d["threads"] = arena_threads;
  d["seconds"] = seconds;
  d["shared_analyses"] = out.shared_analyses.load();
  return d;
}

}  // namespace

void bind_batch_result(py::module_& m) {
  m.def("_batch_scene", &batch_scene, py::arg("scene"), py::arg("names"), py::arg("values"),
        py::arg("sensitivities") = py::none(), py::arg("option_fields") = py::dict(),
        py::arg("identifier_names") = false, py::arg("threads") = 0,
        "The tables of a scene's sweep for each row of `values` (cases × names): phiq.run_batch wraps it.");
}

}  // namespace phiq::python
