// Model (read-only: structure, names, the Jacobian's pattern, and Φ, Φq, Φt, γ at any q), Workspace (one thread's
// q, q̇, q̈ and factors, as numpy views), the statuses, and the registry of constraint kinds.

#include "bindings.hpp"

#include <vector>

namespace phiq::python {

namespace {

// Φq(q, t) as a scipy.sparse.csc_matrix (m × n) on the model's fixed pattern: fresh arrays, owned by the matrix.
py::object jacobian_matrix(const Model& model, const Eigen::VectorXd& q, double t) {
  const CscPattern& p = model.jacobian_pattern();
  py::array_t<double> data(p.nnz());
  py::array_t<std::int64_t> indices(p.nnz()), indptr(p.cols + 1);
  std::copy(p.row_idx.begin(), p.row_idx.end(), indices.mutable_data());
  std::copy(p.col_ptr.begin(), p.col_ptr.end(), indptr.mutable_data());
  {
    double* values = data.mutable_data();
    py::gil_scoped_release free;
    model.jacobian(q.data(), t, values);
  }
  py::object csc = py::module_::import("scipy.sparse").attr("csc_matrix");
  return csc(py::make_tuple(data, indices, indptr), py::arg("shape") = py::make_tuple(p.rows, p.cols));
}

// A vector of the model's m rows that `evaluate` fills (Φ, Φt or γ), the GIL released meanwhile.
template <class Evaluate>
Eigen::VectorXd rows_of(const Model& model, Evaluate&& evaluate) {
  Eigen::VectorXd out(model.num_equations());
  py::gil_scoped_release free;
  evaluate(out.data());
  return out;
}

// One of the workspace's state vectors, writable in place (a numpy view whose base keeps the workspace alive), or
// replaced by a copy of the same size.
template <Eigen::VectorXd Workspace::*member>
void state_property(py::class_<Workspace>& c, const char* name, const char* doc) {
  c.def_property(
      name, [](Workspace& w) -> Eigen::VectorXd& { return w.*member; },
      [name](Workspace& w, const Eigen::Ref<const Eigen::VectorXd>& v) {
        w.*member = coordinate_vector(w.model(), v, name);
      },
      py::return_value_policy::reference_internal, doc);
}

// Unit, SolveStatus and ConstraintInfo: what the model's and the solves' answers are made of.
void bind_vocabulary(py::module_& m) {
  py::enum_<Unit>(m, "Unit", "What a coordinate or a constraint row measures.")
      .value("NONE", Unit::kNone, "unknown or unitless: compared with the tolerance itself")
      .value("LENGTH", Unit::kLength, "metres: compared with the tolerance times its length scale")
      .value("ANGLE", Unit::kAngle, "radians: compared with the tolerance")
      .def("__str__", [](Unit u) { return to_string(u); });

  py::enum_<SolveStatus>(m, "SolveStatus",
                         "Outcome of a solve. Only SUCCESS leaves a valid solution; the others come with a one-line "
                         "message in their summary.")
      .value("SUCCESS", SolveStatus::kSuccess, "solved to tolerance")
      .value("NOT_CONVERGED", SolveStatus::kNotConverged, "Newton reached its limit or stopped decreasing Φ")
      .value("SINGULAR_JACOBIAN", SolveStatus::kSingularJacobian, "Φq is singular here")
      .value("LINEAR_SOLVER_FAILED", SolveStatus::kLinearSolverFailed, "the sparse library failed")
      .value("NON_FINITE", SolveStatus::kNonFinite, "NaN or Inf in Φ, Φq or a solution")
      .value("NOT_SQUARE", SolveStatus::kNotSquare, "equations and coordinates differ in number")
      .value("OUTSIDE_TIME_DOMAIN", SolveStatus::kOutsideTimeDomain, "a driver's law is not defined at t")
      .value("CANCELLED", SolveStatus::kCancelled, "stopped by the caller (Ctrl-C in Python)")
      .value("INCONSISTENT", SolveStatus::kInconsistent, "redundant constraints that cannot hold together")
      .value("POSITION_NOT_SOLVED", SolveStatus::kPositionNotSolved,
             "a velocity or acceleration asked at a q that does not solve the position problem")
      .value("OUTSIDE_DOMAIN", SolveStatus::kOutsideDomain, "a curve parameter left its open curve")
      .def("__str__", [](SolveStatus s) { return to_string(s); });

  py::class_<ConstraintInfo>(m, "ConstraintInfo", "One constraint of a model, as diagnostics name it.")
      .def_readonly("name", &ConstraintInfo::name, "as given in the scene")
      .def_property_readonly(
          "kind", [](const ConstraintInfo& c) { return std::string(c.kind); },
          "its kind (the registry's name, e.g. 'distance')")
      .def_readonly("first_row", &ConstraintInfo::first_row, "its first row in Φ")
      .def_readonly("rows", &ConstraintInfo::rows, "how many rows of Φ it owns")
      .def_readonly("depends_on_time", &ConstraintInfo::depends_on_time, "rheonomic (a driver, an equation in t)")
      .def("__repr__", [](const ConstraintInfo& c) {
        return "ConstraintInfo(name='" + c.name + "', kind='" + std::string(c.kind) +
               "', first_row=" + std::to_string(c.first_row) + ", rows=" + std::to_string(c.rows) + ")";
      });
}

void bind_model_class(py::module_& m) {
  py::class_<Model>(m, "Model",
                    "An immutable mechanism: coordinates, constraints, the fixed pattern of Φq and its symbolic "
                    "analysis. Obtained from a Scene (load_scene, parse_scene, SceneBuilder.build); it lives as "
                    "long as any object made from it.")
      .def_property_readonly("num_coordinates", &Model::num_coordinates, "n, the size of q")
      .def_property_readonly("num_equations", &Model::num_equations, "m, the rows of Φ")
      .def_property_readonly("coordinate_names", &Model::coordinate_names, "names of q's entries, in order")
      .def("coordinate_index", &Model::coordinate_index, py::arg("name"),
           "Index in q of the coordinate `name`; ValueError for an unknown name.")
      .def(
          "constraint_index", [](const Model& md, const std::string& name) { return md.constraint_index(name); },
          py::arg("name"), "Index in constraints of the constraint `name`; ValueError for an unknown name.")
      .def(
          "constraint", [](const Model& md, const std::string& name) { return md.constraint(name); }, py::arg("name"),
          "The ConstraintInfo of constraint `name` (its first_row and rows); ValueError if unknown.")
      .def(
          "row_index", [](const Model& md, const std::string& name) { return md.row_index(name); }, py::arg("row_name"),
          "The row of Φ named 'name' or 'name[k]' (row_name's inverse); ValueError if unknown.")
      .def_property_readonly(
          "coordinate_units",
          [](const Model& md) {
            std::vector<Unit> u;
            for (Index j = 0; j < md.num_coordinates(); ++j) u.push_back(md.coordinate_unit(j));
            return u;
          },
          "Unit of every coordinate")
      .def_property_readonly("constraints", &Model::constraints, "every constraint (ConstraintInfo), in row order")
      .def("row_name", &Model::row_name, py::arg("row"),
           "'name' for a one-row constraint, 'name[k]' for row k of a multi-row one")
      .def_property_readonly("body_names", &Model::body_names, "bodies of the scene, in order")
      .def_property_readonly("grubler", &Model::grubler,
                             "Grübler–Kutzbach count of the joints, or None where it is not defined")
      .def_property_readonly("length_scale", &Model::length_scale, "the model's characteristic length (m)")
      .def_property_readonly(
          "nonzeros", [](const Model& md) { return md.jacobian_pattern().nnz(); }, "entries of Φq's fixed pattern")
      .def_property_readonly(
          "linear_solver", [](const Model& md) { return to_string(md.linear_solver()); }, "'klu', 'umfpack' or 'dense'")
      .def_property_readonly(
          "time_domain", [](const Model& md) { return py::make_tuple(md.time_domain_begin(), md.time_domain_end()); },
          "(begin, end): where every driver is defined")
      .def_property_readonly(
          "initial_positions", [](const Model& md) { return to_numpy(md.initial_positions()); },
          "the rough placement of the scene (a new array)")
      .def(
          "residual",
          [](const Model& md, const Eigen::Ref<const Eigen::VectorXd>& q, double t) {
            const Eigen::VectorXd x = coordinate_vector(md, q, "q");
            return rows_of(md, [&](double* out) { md.residual(x.data(), t, out); });
          },
          py::arg("q"), py::arg("t"), "Φ(q, t), an array of m entries")
      .def(
          "jacobian",
          [](const Model& md, const Eigen::Ref<const Eigen::VectorXd>& q, double t) {
            return jacobian_matrix(md, coordinate_vector(md, q, "q"), t);
          },
          py::arg("q"), py::arg("t"), "Φq(q, t) as a scipy.sparse.csc_matrix (m × n) on the model's fixed pattern")
      .def(
          "phi_t",
          [](const Model& md, const Eigen::Ref<const Eigen::VectorXd>& q, double t) {
            const Eigen::VectorXd x = coordinate_vector(md, q, "q");
            return rows_of(md, [&](double* out) { md.phi_t(x.data(), t, out); });
          },
          py::arg("q"), py::arg("t"), "Φt = ∂Φ/∂t at (q, t): the velocity equation is Φq q̇ = −Φt")
      .def(
          "gamma",
          [](const Model& md, const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& qd,
             double t) {
            const Eigen::VectorXd x = coordinate_vector(md, q, "q"), v = coordinate_vector(md, qd, "qd");
            return rows_of(md, [&](double* out) { md.gamma(x.data(), v.data(), t, out); });
          },
          py::arg("q"), py::arg("qd"), py::arg("t"),
          "γ = −(Φq q̇)q q̇ − 2Φqt q̇ − Φtt: the acceleration equation is Φq q̈ = γ")
      .def("__repr__", [](const Model& md) {
        return "<phiq.Model: " + std::to_string(md.num_coordinates()) + " coordinates, " +
               std::to_string(md.num_equations()) + " equations, " + std::to_string(md.constraints().size()) +
               " constraints>";
      });
}

// The Workspace with its counters, and the registry's list of kinds.
void bind_workspace(py::module_& m) {
  py::class_<WorkCounters>(m, "WorkCounters", "Work done, counted where it happens.")
      .def_readonly("newton_iterations", &WorkCounters::newton_iterations, "Newton steps")
      .def_readonly("residual_evaluations", &WorkCounters::residual_evaluations,
                    "evaluations of Φ (line-search trials included)")
      .def_readonly("jacobian_evaluations", &WorkCounters::jacobian_evaluations, "evaluations of Φq values")
      .def_readonly("factorizations", &WorkCounters::factorizations, "numeric LU factorisations")
      .def_readonly("pivoting_factorizations", &WorkCounters::pivoting_factorizations,
                    "of them, those that searched for pivots")
      .def_readonly("velocity_solves", &WorkCounters::velocity_solves, "solves of Φq q̇ = −Φt")
      .def_readonly("acceleration_solves", &WorkCounters::acceleration_solves, "solves of Φq q̈ = γ")
      .def_readonly("phi_t_evaluations", &WorkCounters::phi_t_evaluations, "evaluations of Φt")
      .def_readonly("gamma_evaluations", &WorkCounters::gamma_evaluations, "evaluations of γ")
      .def_readonly("point_evaluations", &WorkCounters::point_evaluations, "output point motions evaluated")
      .def_readonly("sensitivity_solves", &WorkCounters::sensitivity_solves,
                    "solves for sensitivities to design parameters")
      .def_readonly("sensitivity_direct_rows", &WorkCounters::sensitivity_direct_rows,
                    "rows of an adjoint-form sweep solved in the direct form (Φq not smooth along the motion)")
      .def_readonly("effort_solves", &WorkCounters::effort_solves,
                    "transposed solves for driver efforts (output.efforts), one per written row");

  py::class_<Workspace> ws(m, "Workspace",
                           "One thread's state for the solves: q, qd, qdd (numpy views, writable in place), the "
                           "numeric factors and the work counters. Keeps its model alive.");
  ws.def(py::init<const Model&>(), py::arg("model"), py::keep_alive<1, 2>(),
         "A workspace for `model`, with q at its initial positions and q̇ = q̈ = 0.")
      .def_property_readonly("model", &Workspace::model, py::return_value_policy::reference_internal,
                             "the model it was made for")
      .def_readonly("counters", &Workspace::counters, "work done with this workspace so far")
      .def("start_afresh", &Workspace::start_afresh,
           "Forget the factorisation and pivot order the last solves left: the next solve computes what it would "
           "in a fresh workspace with the same q.");
  state_property<&Workspace::q>(ws, "q", "positions q (a view; assign an array of n entries to replace them)");
  state_property<&Workspace::qd>(ws, "qd", "velocities q̇ (written by solve_velocity)");
  state_property<&Workspace::qdd>(ws, "qdd", "accelerations q̈ (written by solve_acceleration)");

  m.def(
      "constraint_kinds",
      [] {
        py::list kinds;
        auto names = [](const JointTraits::Coordinates& c) {
          py::list l;
          if (c.angle) l.append("angle");
          if (c.distance) l.append("distance");
          return l;
        };
        ConstraintKinds::for_each([&]<class K>() {
          const JointTraits joint = joint_traits<K>();
          for (const SceneForm& f : K::kScene)
            kinds.append(py::dict(py::arg("kind") = K::kKind, py::arg("section") = f.section, py::arg("type") = f.type,
                                  py::arg("dimension") = f.dimension, py::arg("example") = f.example,
                                  py::arg("measures") = names(joint.measures), py::arg("drives") = names(joint.drives),
                                  py::arg("shaft") = joint.shaft));
        });
        return kinds;
      },
      "Every scene form of every constraint kind in phiq's registry: dicts of kind, section ('constraints', "
      "'drivers', 'bodies', 'vectors'), type, dimension (2 or 3), a one-line example of the scene entry, and for a "
      "named spatial joint its JointTraits: what `output.joints` measures of it and a joint driver may drive "
      "('angle', 'distance'), and whether it is a shaft.");
}

}  // namespace

// In this order: a type is bound before the signatures that name it.
void bind_model(py::module_& m) {
  bind_vocabulary(m);
  bind_model_class(m);
  bind_workspace(m);
}

}  // namespace phiq::python
