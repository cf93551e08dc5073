// run_sweep from Python: a scene swept as `phiq run` sweeps it (prepare_scene: the redundant rows of a consistent
// model left out), its rows written straight into one rows × columns table of doubles — the CSV's columns and
// doubles, bit for bit — that numpy views without a copy. The GIL is released during the sweep; the row callback
// takes it back every 50 ms only, to let Python's signal handlers run, so that Ctrl-C stops a long sweep at its
// next delivered row (KeyboardInterrupt).

#include "sweep_table.hpp"

#include <chrono>
#include <memory>

namespace phiq::python {

std::shared_ptr<SweepTable> sweep_into_table(const Scene& scene, const SweepOptions& opt, bool identifier_names,
                                             const std::function<bool()>& keep_going) {
  auto table = std::make_shared<SweepTable>();
  // Options hold indices into the model they were made for: another scene's name coordinates or constraints this
  // one may not have (CsvFormat's own words would not say why).
  try {
    (void)CsvFormat(*scene.model, opt);
  } catch (const Error&) {
    throw SceneError(scene.path + ": the options name coordinates or constraints this scene does not have (" +
                     std::to_string(scene.model->num_coordinates()) + " coordinates, " +
                     std::to_string(scene.model->constraints().size()) +
                     " constraints): they were made for another scene; start from this scene's .options");
  }
  // The columns from the scene's model and these options, as `phiq run` names them.
  CsvFormat format(*scene.model, opt);
  format.set_naming(identifier_names ? ColumnNaming::kIdentifiers : ColumnNaming::kDotted);
  table->columns = format.column_names();
  table->q_columns = static_cast<Index>(opt.coordinate_columns.size());
  table->v_columns = static_cast<Index>(opt.written_velocities().size());
  table->a_columns = static_cast<Index>(opt.written_accelerations().size());
  table->output_columns = static_cast<Index>(format.num_output_values());
  const Index width = table->width();
  const Index capacity = rows_written(opt);
  table->data.reset(new double[static_cast<std::size_t>(std::max<Index>(capacity, 1) * width)]);

  SquareScene square;
  if (std::string why = square_for_sweep(scene, opt.t_begin, opt.assembly, &square); !why.empty()) {
    // inconsistent or under-driven: nothing is swept
    table->summary.status = square.assembly.status;
    table->summary.message = std::move(why);
    table->summary.failed_step = 0;
    table->summary.failed_time = opt.t_begin;
    table->summary.worst_rows = square.assembly.worst_rows;
    return table;
  }
  const Model& model = square.model(*scene.model);
  Workspace ws(model);
  ws.q = square.start;

  auto next_check = std::chrono::steady_clock::now() + std::chrono::milliseconds(50);
  (void)run_sweep(
      model, opt, ws,
      [&](const StepView& step) {  // the status is in the summary
        if (table->rows >= capacity) throw Error("run_sweep delivered more rows than rows_written() counts");
        format.append_values(step, table->data.get() + table->rows * width);
        ++table->rows;
        if (const auto now = std::chrono::steady_clock::now(); now >= next_check) {
          next_check = now + std::chrono::milliseconds(50);
          return keep_going();
        }
        return true;
      },
      &table->summary);
  return table;
}

namespace {

std::shared_ptr<SweepTable> sweep_scene(const Scene& scene, const SweepOptions& opt, bool identifier_names) {
  bool interrupted = false;
  std::shared_ptr<SweepTable> table;
  {
    py::gil_scoped_release free;
    table = sweep_into_table(scene, opt, identifier_names, [&] {
      py::gil_scoped_acquire hold;
      return !(interrupted = PyErr_CheckSignals() != 0);  // the exception stays set for below
    });
  }
  if (interrupted) throw py::error_already_set();
  return table;
}

}  // namespace

void bind_sweep_result(py::module_& m) {
  py::class_<SweepTable, std::shared_ptr<SweepTable>>(m, "_SweepTable", py::buffer_protocol(),
                                                      "The rows of a sweep (numpy.asarray views them).")
      .def_buffer([](SweepTable& t) {
        return py::buffer_info(t.data.get(), sizeof(double), py::format_descriptor<double>::format(), 2,
                               {t.rows, t.width()},
                               {static_cast<Index>(sizeof(double)) * t.width(), static_cast<Index>(sizeof(double))});
      })
      .def_readonly("columns", &SweepTable::columns)
      .def_readonly("q_columns", &SweepTable::q_columns)
      .def_readonly("v_columns", &SweepTable::v_columns)
      .def_readonly("a_columns", &SweepTable::a_columns)
      .def_readonly("output_columns", &SweepTable::output_columns)
      .def_readonly("summary", &SweepTable::summary);
  m.def("_sweep_scene", &sweep_scene, py::arg("scene"), py::arg("options"), py::arg("identifier_names") = false,
        "The table of a scene's sweep with these options (phiq.run_sweep wraps it).");
}

}  // namespace phiq::python
