// The three problems of the notes on (Model, Workspace) — solve_position, solve_velocity, solve_acceleration —,
// the minimum-norm assembly and the rank analysis, with their options and summaries. The GIL is released while
// phiq works.

#include "bindings.hpp"

namespace phiq::python {

namespace {

py::list worst_rows(const Model& model, const std::vector<std::pair<Index, double>>& rows) {
  py::list out;
  for (const auto& [row, value] : rows) out.append(py::make_tuple(model.row_name(row), value));
  return out;
}

void check_workspace(const Model& model, const Workspace& ws) {
  if (&ws.model() != &model) throw Error("workspace was made for another model");
}

// The three problems: their options, summaries and solves.
void bind_kinematics(py::module_& m) {
  py::enum_<JacobianUpdate>(m, "JacobianUpdate", "Which matrix each Newton iteration solves with.")
      .value("EVERY_ITERATION", JacobianUpdate::kEveryIteration, "full Newton: Φq factorised at every iterate")
      .value("WHEN_SLOW", JacobianUpdate::kWhenSlow,
             "modified Newton: the factorisation is reused while it contracts well");

  py::class_<NewtonOptions>(m, "NewtonOptions", "Newton-Raphson settings of solve_position (kinematics.hpp).")
      .def(py::init([](double tolerance, int max_iterations, bool line_search, int max_backtracks,
                       JacobianUpdate jacobian_update) {
             return NewtonOptions{tolerance, max_iterations, line_search, max_backtracks, jacobian_update};
           }),
           py::arg("tolerance") = 1e-10, py::arg("max_iterations") = 20, py::arg("line_search") = true,
           py::arg("max_backtracks") = 12, py::arg("jacobian_update") = JacobianUpdate::kEveryIteration)
      .def_readwrite("tolerance", &NewtonOptions::tolerance,
                     "every row |Φ_i| ≤ tol · scale_i and the estimated error of q within tol · scale_j")
      .def_readwrite("max_iterations", &NewtonOptions::max_iterations,
                     "Newton iterations before giving up (NOT_CONVERGED)")
      .def_readwrite("line_search", &NewtonOptions::line_search, "backtracking on ½‖Φ/scale‖²")
      .def_readwrite("max_backtracks", &NewtonOptions::max_backtracks,
                     "halvings of a step before the line search gives up")
      .def_readwrite("jacobian_update", &NewtonOptions::jacobian_update,
                     "full Newton (EVERY_ITERATION) or modified Newton (WHEN_SLOW)")
      .def_readwrite("max_contraction", &NewtonOptions::max_contraction,
                     "modified Newton refactorises when the observed contraction exceeds this")
      .def_readwrite("start_error", &NewtonOptions::start_error,
                     "estimated error of the start in units of the tolerance test (negative: unknown)")
      .def_readwrite("known_to", &NewtonOptions::known_to,
                     "how well q can be known here, in tolerances (0: no limit measured)")
      .def("__repr__", [](const NewtonOptions& o) {
        return "NewtonOptions(tolerance=" + shortest(o.tolerance) +
               ", max_iterations=" + std::to_string(o.max_iterations) +
               ", jacobian_update=" + to_string(o.jacobian_update) + ")";
      });

  py::class_<PositionSummary>(m, "PositionSummary", "What solve_position did.")
      .def_readonly("status", &PositionSummary::status, "the outcome (SolveStatus)")
      .def_property_readonly(
          "ok", [](const PositionSummary& s) { return s.status == SolveStatus::kSuccess; },
          "True when status is SolveStatus.SUCCESS")
      .def_readonly("iterations", &PositionSummary::iterations, "Newton steps taken")
      .def_readonly("factorizations", &PositionSummary::factorizations, "Newton steps with a fresh factorisation of Φq")
      .def_readonly("backtracks", &PositionSummary::backtracks, "step halvings by the line search")
      .def_readonly("residual", &PositionSummary::residual, "max_i |Φ_i| / scale_i at the end")
      .def_readonly("rcond", &PositionSummary::rcond, "of the last factorisation")
      .def_readonly("slow_convergence", &PositionSummary::slow_convergence,
                    "converged only linearly (a singular position) or stopped at the rounding level")
      .def_readonly("error_estimate", &PositionSummary::error_estimate,
                    "estimated error of q in units of the tolerance test (≤ 1: within it; negative: unknown)")
      .def_readonly("error_coordinate", &PositionSummary::error_coordinate,
                    "index of the coordinate least well known when error_estimate is above 2 (or rows were left at "
                    "their rounding), else -1")
      .def_readonly("error_size", &PositionSummary::error_size,
                    "how far q at error_coordinate may be from the solution, in that coordinate's own unit (m, rad)")
      .def(
          "known_to",
          [](const PositionSummary& s, const Model& model) -> py::object {
            if (s.error_coordinate < 0 || s.error_coordinate >= model.num_coordinates()) return py::none();
            return py::str(known_to_text(model, s.error_coordinate, s.error_size));
          },
          py::arg("model"), "\"'yB' known to ±2e-10 m\": error_size at error_coordinate in its unit, or None")
      .def_readonly("message", &PositionSummary::message, "one line; empty on a clean success")
      .def("brief_report", &PositionSummary::BriefReport)
      .def("__repr__", [](const PositionSummary& s) { return "<PositionSummary: " + s.BriefReport() + ">"; });

  py::class_<LinearSummary>(m, "LinearSummary", "What solve_velocity or solve_acceleration did.")
      .def_readonly("status", &LinearSummary::status, "the outcome (SolveStatus)")
      .def_property_readonly(
          "ok", [](const LinearSummary& s) { return s.status == SolveStatus::kSuccess; },
          "True when status is SolveStatus.SUCCESS")
      .def_readonly("rcond", &LinearSummary::rcond, "reciprocal condition estimate of the factorisation used")
      .def_readonly("message", &LinearSummary::message, "one line; empty on success")
      .def("__repr__", [](const LinearSummary& s) {
        return std::string("<LinearSummary: ") + to_string(s.status) + (s.message.empty() ? "" : ": " + s.message) +
               ">";
      });

  m.def(
      "solve_position",
      [](const Model& model, double t, Workspace& ws, const NewtonOptions& options) {
        check_workspace(model, ws);
        PositionSummary s;
        py::gil_scoped_release free;
        (void)solve_position(model, t, options, ws, &s);  // the status is in the summary returned
        return s;
      },
      py::arg("model"), py::arg("t"), py::arg("workspace"), py::arg("options") = NewtonOptions{},
      "Solve Φ(q, t) = 0 by Newton-Raphson from workspace.q; on success workspace.q holds the solution. Returns a "
      "PositionSummary (its status says whether it succeeded).");
  m.def(
      "solve_velocity",
      [](const Model& model, double t, Workspace& ws, double tolerance) {
        check_workspace(model, ws);
        LinearSummary s;
        py::gil_scoped_release free;
        (void)solve_velocity(model, t, DerivativeOptions{tolerance}, ws, &s);  // the status is in the summary
        return s;
      },
      py::arg("model"), py::arg("t"), py::arg("workspace"), py::arg("tolerance") = DerivativeOptions{}.tolerance,
      "Solve Φq q̇ = −Φt at workspace.q into workspace.qd. workspace.q must solve the position problem at t to "
      "`tolerance` (solve_position's residual test; math.inf: no test), else the status is POSITION_NOT_SOLVED "
      "with the worst constraint named and qd is left as it was.");
  m.def(
      "solve_acceleration",
      [](const Model& model, double t, Workspace& ws, double tolerance) {
        check_workspace(model, ws);
        LinearSummary s;
        py::gil_scoped_release free;
        (void)solve_acceleration(model, t, DerivativeOptions{tolerance}, ws, &s);  // the status is in the summary
        return s;
      },
      py::arg("model"), py::arg("t"), py::arg("workspace"), py::arg("tolerance") = DerivativeOptions{}.tolerance,
      "Solve Φq q̈ = γ at workspace.q, workspace.qd into workspace.qdd (q checked as in solve_velocity).");
}

// The rank analysis and the minimum-norm assembly.
void bind_rank_and_assembly(py::module_& m) {
  py::class_<RankReport>(m, "RankReport", "Rank and redundancy of the constraint equations at one configuration.")
      .def_readonly("coordinates", &RankReport::coordinates, "n")
      .def_readonly("equations", &RankReport::equations, "m, all rows (kinematic and rheonomic)")
      .def_readonly("kinematic_equations", &RankReport::kinematic_equations,
                    "rows of constraints that do not depend on t")
      .def_readonly("driver_equations", &RankReport::driver_equations,
                    "rows of rheonomic constraints (drivers, equations in t)")
      .def_readonly("rank", &RankReport::rank, "rank of the kinematic rows")
      .def_readonly("dof", &RankReport::dof, "n − rank: degrees of freedom (drivers not counted)")
      .def_readonly("driven_rank", &RankReport::driven_rank, "rank of all rows")
      .def_readonly("driven_dof", &RankReport::driven_dof, "freedoms the drivers leave (0: fully driven)")
      .def_readonly("grubler", &RankReport::grubler, "Grübler–Kutzbach count, or None")
      .def_readonly("independent_rows", &RankReport::independent_rows, "a maximal independent set of rows, ascending")
      .def_readonly("redundant_rows", &RankReport::redundant_rows, "the other rows, ascending")
      .def_readonly("redundant", &RankReport::redundant, "names of the constraints owning redundant rows")
      .def_readonly("uncertain", &RankReport::uncertain,
                    "a pivot or singular value near the tolerance, or the sparse and dense ranks disagree")
      .def_readonly("message", &RankReport::message, "one line; empty when nothing is uncertain")
      .def("brief_report", &RankReport::BriefReport)
      .def("__repr__", [](const RankReport& r) { return "<RankReport: " + r.BriefReport() + ">"; });

  py::class_<AssemblySummary>(m, "AssemblySummary", "What assemble() did.")
      .def_readonly("status", &AssemblySummary::status, "the outcome (SolveStatus)")
      .def_property_readonly(
          "ok", [](const AssemblySummary& s) { return s.status == SolveStatus::kSuccess; },
          "True when status is SolveStatus.SUCCESS")
      .def_readonly("iterations", &AssemblySummary::iterations, "Gauss-Newton steps")
      .def_readonly("residual", &AssemblySummary::residual, "max_i |Φ_i| / scale_i over all rows at the end")
      .def_readonly("moved", &AssemblySummary::moved, "max_j |q_j − q0_j| / scale_j")
      .def_readonly("rank", &AssemblySummary::rank, "the RankReport at the final configuration")
      .def_readonly("consistent", &AssemblySummary::consistent,
                    "False when redundant equations cannot hold where the independent ones do")
      .def_readonly("conflicts", &AssemblySummary::conflicts, "constraints that cannot hold together")
      .def_readonly("message", &AssemblySummary::message, "one line; empty on a clean success")
      .def("brief_report", &AssemblySummary::BriefReport)
      .def("__repr__", [](const AssemblySummary& s) { return "<AssemblySummary: " + s.BriefReport() + ">"; });

  m.def(
      "assemble",
      [](const Model& model, double t, const Eigen::Ref<const Eigen::VectorXd>& q0, const NewtonOptions& options) {
        Eigen::VectorXd q = coordinate_vector(model, q0, "q");
        AssemblySummary s;
        {
          py::gil_scoped_release free;
          (void)assemble(model, t, assembly_options(options), q, &s);
        }
        return py::make_tuple(to_numpy(q), s);
      },
      py::arg("model"), py::arg("t"), py::arg("q"), py::arg("options") = NewtonOptions{1e-10, 100, true, 30},
      "Minimum-norm assembly of any model (square, redundant, under-driven) from the rough placement q at t. "
      "Returns (q, AssemblySummary): the assembled position (or the last iterate) and what happened, the rank "
      "analysis there included.");
  m.def(
      "analyse_rank",
      [](const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q, double t) {
        const Eigen::VectorXd x = coordinate_vector(model, q, "q");
        py::gil_scoped_release free;
        return analyse_rank(model, x, t);
      },
      py::arg("model"), py::arg("q"), py::arg("t"), "Rank analysis of Φq(q, t): a RankReport.");
  m.def(
      "worst_rows", [](const Model& model, const PositionSummary& s) { return worst_rows(model, s.worst_rows); },
      py::arg("model"), py::arg("summary"),
      "The worst rows at the end of a position solve: (row name, |Φ_i| / scale_i), largest first.");
}

}  // namespace

void bind_solve(py::module_& m) {
  bind_kinematics(m);
  bind_rank_and_assembly(m);
}

}  // namespace phiq::python
