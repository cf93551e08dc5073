// The sweep's options (one flat SweepOptions: time grid, solver, threads, outputs), its summary (with warnings as
// objects and to_dict() for JSON), and the predictors.

#include "bindings.hpp"

namespace phiq::python {

namespace {

py::dict counters_dict(const WorkCounters& c) {
  return py::dict(
      py::arg("newton_iterations") = c.newton_iterations, py::arg("residual_evaluations") = c.residual_evaluations,
      py::arg("jacobian_evaluations") = c.jacobian_evaluations, py::arg("factorizations") = c.factorizations,
      py::arg("pivoting_factorizations") = c.pivoting_factorizations, py::arg("velocity_solves") = c.velocity_solves,
      py::arg("acceleration_solves") = c.acceleration_solves, py::arg("phi_t_evaluations") = c.phi_t_evaluations,
      py::arg("gamma_evaluations") = c.gamma_evaluations, py::arg("point_evaluations") = c.point_evaluations,
      py::arg("sensitivity_solves") = c.sensitivity_solves,
      py::arg("sensitivity_direct_rows") = c.sensitivity_direct_rows, py::arg("effort_solves") = c.effort_solves);
}

// worst_coordinate, worst_known_to and worst_unit: the worst estimate in the coordinate's own unit (None where no
// solve said which coordinate), as the run summary's JSON has them
py::dict accuracy_dict(const RowClassAccuracy& a) {
  const bool named = !a.worst_coordinate.empty();
  return py::dict(py::arg("rows") = a.rows, py::arg("worst_error") = a.worst_error,
                  py::arg("worst_time") = a.worst_time, py::arg("unestimated") = a.unestimated,
                  py::arg("worst_coordinate") = named ? py::object(py::str(a.worst_coordinate)) : py::none(),
                  py::arg("worst_known_to") = named ? py::object(py::float_(a.worst_known_to)) : py::none(),
                  py::arg("worst_unit") = named ? py::object(py::str(unit_symbol(a.worst_unit))) : py::none());
}

}  // namespace

py::dict summary_dict(const SweepSummary& s) {
  py::list warnings;
  for (const SweepWarning& w : s.warnings)
    warnings.append(py::dict(py::arg("t") = w.t, py::arg("kind") = w.kind, py::arg("message") = w.message));
  return py::dict(py::arg("status") = to_string(s.status), py::arg("message") = s.message,
                  py::arg("steps_completed") = s.steps_completed, py::arg("failed_step") = s.failed_step,
                  py::arg("failed_time") = s.failed_time,
                  py::arg("assembly") = py::dict(py::arg("status") = to_string(s.assembly.status),
                                                 py::arg("iterations") = s.assembly.iterations,
                                                 py::arg("residual") = s.assembly.residual),
                  py::arg("counters") = counters_dict(s.counters), py::arg("subdivisions") = s.subdivisions,
                  py::arg("singular_positions") = s.singular_positions, py::arg("min_rcond") = s.min_rcond,
                  py::arg("min_rcond_time") = s.min_rcond_time, py::arg("warnings") = warnings,
                  py::arg("solve_seconds") = s.solve_seconds, py::arg("threads") = s.threads,
                  py::arg("parallel_chunks") = s.parallel_chunks, py::arg("seed_seconds") = s.seed_seconds,
                  py::arg("sensitivity_form") = to_string(s.sensitivity_form),
                  py::arg("accuracy") = py::dict(py::arg("converged") = accuracy_dict(s.accuracy.converged),
                                                 py::arg("rounding_level") = accuracy_dict(s.accuracy.rounding_level),
                                                 py::arg("singular") = accuracy_dict(s.accuracy.singular)));
}

void bind_sweep(py::module_& m) {
  py::enum_<Predictor> pred(m, "Predictor", "How successive positions are started (sweep.hpp).");
  for (Predictor p : all_predictors()) {
    std::string upper = to_string(p);
    for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    pred.value(upper.c_str(), p);
  }
  pred.def("__str__", [](Predictor p) { return to_string(p); });

  py::enum_<SensitivityForm>(m, "SensitivityForm",
                             "How sensitivities are solved (sensitivity.hpp): AUTO picks the cheaper, DIRECT solves "
                             "per parameter, ADJOINT per written coordinate.")
      .value("AUTO", SensitivityForm::kAuto)
      .value("DIRECT", SensitivityForm::kDirect)
      .value("ADJOINT", SensitivityForm::kAdjoint)
      .def("__str__", [](SensitivityForm f) { return to_string(f); });

  py::class_<SweepOptions>(m, "SweepOptions",
                           "What run_sweep computes and how: the time grid, the solver settings, the threads and "
                           "the outputs. Get the scene's with Scene.options, change fields, pass it to run_sweep.")
      .def(py::init<>())
      .def("__copy__", [](const SweepOptions& o) { return o; })
      .def(
          "__deepcopy__", [](const SweepOptions& o, py::dict) { return o; }, py::arg("memo"))
      .def_readwrite("t_begin", &SweepOptions::t_begin, "first time point (s)")
      .def_readwrite("t_end", &SweepOptions::t_end, "last time point (s)")
      .def_readwrite("steps", &SweepOptions::steps, "intervals: steps + 1 time points")
      .def("time_of", &SweepOptions::time_of, py::arg("k"), "t_k, the time of grid point k")
      .def_readwrite("predictor", &SweepOptions::predictor, "how each successive position is started (Predictor)")
      .def_readwrite("newton", &SweepOptions::newton, "NewtonOptions of the successive positions")
      .def_readwrite("assembly", &SweepOptions::assembly, "NewtonOptions of the initial position")
      .def_readwrite("max_subdivisions", &SweepOptions::max_subdivisions,
                     "a failed step is retried as 2, 4, … sub-steps, down to h / 2^this")
      .def_readwrite("threads", &SweepOptions::threads,
                     "threads for the drive steps (0: all cores); every count gives the same bits")
      .def_readwrite("memory_budget", &SweepOptions::memory_budget,
                     "bytes the process may reach when threads = 0 picks the threads (0: what the system has)")
      .def_readwrite("chunk_steps", &SweepOptions::chunk_steps,
                     "steps per parallel chunk (0: automatic; the same on every thread count)")
      .def_readwrite("row_buffer_bytes", &SweepOptions::row_buffer_bytes,
                     "bytes of rows a sweep in chunks may hold before delivering them in order")
      .def_readwrite("velocities", &SweepOptions::velocities, "solve and deliver q̇")
      .def_readwrite("accelerations", &SweepOptions::accelerations, "solve and deliver q̈")
      .def_readwrite("sensitivity_form", &SweepOptions::sensitivity_form,
                     "how the sensitivities of output.sensitivities are solved (SensitivityForm)")
      .def_readwrite("residuals", &SweepOptions::residuals, "deliver Φ at every row (residual columns)")
      .def_readwrite("condition", &SweepOptions::condition, "deliver the rcond column")
      .def_readwrite("coordinate_columns", &SweepOptions::coordinate_columns, "indices of the q columns written")
      .def_readwrite("velocity_columns", &SweepOptions::velocity_columns,
                     "indices of the q̇ columns (None: coordinate_columns)")
      .def_readwrite("acceleration_columns", &SweepOptions::acceleration_columns,
                     "indices of the q̈ columns (None: coordinate_columns)")
      .def_readwrite("every", &SweepOptions::every, "write every k-th time point")
      .def_readwrite("window_begin", &SweepOptions::window_begin, "write rows with t ≥ this")
      .def_readwrite("window_end", &SweepOptions::window_end, "write rows with t ≤ this")
      .def_readwrite("max_residual_column", &SweepOptions::max_residual_column,
                     "write the largest scaled residual of all rows (column residual)")
      .def_readwrite("residual_columns", &SweepOptions::residual_columns,
                     "constraint indices whose residual is written")
      .def_property_readonly(
          "point_names", [](const SweepOptions& o) { return names_of(o.points); },
          "output points of the scene (their columns NAME.x, NAME.y, …)")
      .def_property_readonly(
          "driver_names", [](const SweepOptions& o) { return names_of(o.driver_columns); },
          "drivers whose law is written (NAME.f, NAME.df, NAME.ddf)")
      .def(
          "rows_written", [](const SweepOptions& o) { return rows_written(o); },
          "rows a successful sweep with these options delivers")
      .def_property_readonly(
          "sensitivity_names", [](const SweepOptions& o) { return names_of(o.sensitivities); },
          "parameters whose sensitivities are delivered (columns x.d_P, x.v.d_P, x.a.d_P)")
      .def(
          "set_sensitivities",
          [](SweepOptions& o, const Scene& scene, const py::list& parameters) {
            const std::vector<SensitivityRequest> asked = sensitivity_requests(parameters, "set_sensitivities");
            std::vector<OutputSensitivity> out;
            {
              py::gil_scoped_release free;
              out = sensitivities_of(scene, asked);
            }
            o.sensitivities = std::move(out);
          },
          py::arg("scene"), py::arg("parameters"),
          "Deliver the sensitivities to these parameters of `scene` (the scene these options sweep): each a name, or "
          "a (name, step) tuple for the difference step of the data's rates (default 1e-3 |p|). As the scene's "
          "output.sensitivities: its text read again at p ± h, p ± 2h, only what p reaches kept. An empty list "
          "delivers none. Raises SceneError (a ValueError) for a name the scene has no parameter of, a name "
          "listed twice or a parameter that changes the structure.");

  py::class_<SweepWarning>(m, "SweepWarning", "Something to know about a delivered row (it is within tolerance).")
      .def_readonly("t", &SweepWarning::t, "time of the row concerned")
      .def_readonly("kind", &SweepWarning::kind,
                    "'slow_convergence', 'ill_conditioned', 'bifurcation', 'parallel_fallback', 'threads_reduced', "
                    "'no_dependence' or 'indeterminate'")
      .def_readonly("message", &SweepWarning::message, "one line")
      .def("__repr__", [](const SweepWarning& w) {
        return "SweepWarning(t=" + shortest(w.t) + ", kind='" + w.kind + "', message='" + w.message + "')";
      });

  py::class_<SweepSummary>(m, "SweepSummary", "What run_sweep did.")
      .def_readonly("status", &SweepSummary::status,
                    "the outcome (SolveStatus); SUCCESS when every time point was delivered")
      .def_readonly("message", &SweepSummary::message, "one line naming the step, time, cause and constraints")
      .def_readonly("steps_completed", &SweepSummary::steps_completed, "time points solved, in order from the first")
      .def_readonly("failed_step", &SweepSummary::failed_step, "k of the step that failed, or -1")
      .def_readonly("failed_time", &SweepSummary::failed_time, "t_k of the step that failed")
      .def_readonly("warnings", &SweepSummary::warnings, "SweepWarning objects, in time order")
      .def_readonly("counters", &SweepSummary::counters, "work done by this sweep (WorkCounters)")
      .def_readonly("threads", &SweepSummary::threads, "threads the drive steps ran on")
      .def("brief_report", &SweepSummary::BriefReport)
      .def("to_dict", &summary_dict, "Every field as plain Python values (JSON-ready).");
}

}  // namespace phiq::python
