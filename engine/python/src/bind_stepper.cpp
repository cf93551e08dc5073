// Stepper: the sweep's step at the caller's own times (stepper.hpp), for a simulator that drives its own clock
// from Python. Made from a scene (its solver settings and output points; a redundant scene's independent rows, as
// run_sweep solves it) or from a model with explicit settings.

#include "bindings.hpp"

#include <algorithm>
#include <memory>
#include <optional>

namespace phiq::python {

namespace {

// A Stepper and what it needs alive: the scene it was made from (whose model it steps, or the model without the
// redundant rows that prepare_scene made).
struct PyStepper {
  std::shared_ptr<const Scene> scene;  // null when made from a model (kept alive by keep_alive instead)
  SquareScene square;
  std::unique_ptr<Stepper> stepper;
};

std::unique_ptr<PyStepper> stepper_for_scene(std::shared_ptr<const Scene> scene, std::optional<bool> velocities,
                                             std::optional<bool> accelerations,
                                             const std::optional<std::vector<SensitivityRequest>>& sensitivities) {
  auto s = std::make_unique<PyStepper>();
  s->scene = std::move(scene);
  const Scene& sc = *s->scene;
  if (const std::string why = prepare_for_sweep(sc, sc.sweep.t_begin, sc.sweep.assembly, &s->square); !why.empty())
    throw Error(sc.path + ": " + why);
  StepperOptions o;
  static_cast<SolverSettings&>(o) = sc.sweep;
  o.velocities = velocities.value_or(sc.sweep.velocities);
  o.accelerations = accelerations.value_or(sc.sweep.accelerations);
  o.points = sc.sweep.points;
  if (sensitivities) {
    py::gil_scoped_release free;  // the scene read again along each parameter
    o.sensitivities = sensitivities_of(sc, *sensitivities);
  } else {
    o.sensitivities = sc.sweep.sensitivities;
  }
  o.efforts = sc.sweep.efforts;
  o.limits = sc.sweep.limits;
  if (sc.sweep.steps > 0) o.expected_step = (sc.sweep.t_end - sc.sweep.t_begin) / static_cast<double>(sc.sweep.steps);
  s->stepper = std::make_unique<Stepper>(s->square.model(*sc.model), std::move(o));
  s->stepper->restart(s->square.start);
  return s;
}

// The driver efforts a stepper delivers (Stepper::efforts()) by driver name: (effort, power).
py::dict efforts_of(const PyStepper& s) {
  py::dict out;
  const OutputEfforts& e = s.stepper->options().efforts;
  const double* v = s.stepper->efforts();
  if (!v) return out;
  const std::size_t n = e.constraints.size();
  for (std::size_t i = 0; i < n; ++i)
    out[py::str(s.stepper->model().constraints()[static_cast<std::size_t>(e.constraints[i])].name)] =
        py::make_tuple(v[i], v[n + i]);
  return out;
}

// The joint reactions a stepper delivers by joint name: (Fx, Fy, Mz), or (Fx, Fy, Fz, Mx, My, Mz) in space.
py::dict reactions_of(const PyStepper& s) {
  py::dict out;
  const OutputEfforts& e = s.stepper->options().efforts;
  const double* v = s.stepper->efforts();
  if (!v) return out;
  v += 2 * e.constraints.size();
  for (const OutputReaction& r : e.reactions) {
    const int n = r.spatial ? 6 : 3;
    py::tuple values(n);
    for (int k = 0; k < n; ++k) values[static_cast<std::size_t>(k)] = v[k];
    out[py::str(e.reaction_name(s.stepper->model(), r))] = values;
    v += n;
  }
  return out;
}

// The losses a stepper delivers by name: a bearing's (friction, power), a gear's (power,).
py::dict losses_of(const PyStepper& s) {
  py::dict out;
  const OutputEfforts& e = s.stepper->options().efforts;
  const double* v = s.stepper->efforts();
  if (!v) return out;
  v += e.losses_at();
  for (const OutputLoss& l : e.losses) {
    out[py::str(l.name)] = l.bearing ? py::make_tuple(v[0], v[1]) : py::make_tuple(v[0]);
    v += l.bearing ? 2 : 1;
  }
  return out;
}

}  // namespace

void bind_stepper(py::module_& m) {
  py::class_<StepSummary>(m, "StepSummary", "What one Stepper.step did.")
      .def_readonly("status", &StepSummary::status, "the outcome (SolveStatus)")
      .def_property_readonly(
          "ok", [](const StepSummary& s) { return s.status == SolveStatus::kSuccess; },
          "True when status is SolveStatus.SUCCESS")
      .def_readonly("t", &StepSummary::t, "the time asked for")
      .def_readonly("message", &StepSummary::message, "one line naming the time, the cause and the worst constraints")
      .def_readonly("assembled", &StepSummary::assembled, "the step assembled from the placement")
      .def_readonly("moved", &StepSummary::moved, "the step solved anything (False for a step of zero length)")
      .def_readonly("counters", &StepSummary::counters, "the work this step did (WorkCounters)")
      .def_readonly("subdivisions", &StepSummary::subdivisions, "sub-steps inserted after Newton failures")
      .def_readonly("warnings", &StepSummary::warnings, "the warnings this step raised (SweepWarning objects)")
      .def_readonly("limits", &StepSummary::limits,
                    "names of the scene's limits outside their range at this step (a `limit` warning where each "
                    "leaves it)")
      .def_readonly("seconds", &StepSummary::seconds, "wall time of the step")
      .def("__repr__", [](const StepSummary& s) {
        return "<StepSummary t=" + shortest(s.t) + ": " + to_string(s.status) +
               (s.message.empty() ? "" : ": " + s.message) + ">";
      });

  py::class_<PyStepper>(m, "Stepper",
                        "Solves position, velocity and acceleration at the times the caller chooses, one step at a "
                        "time, keeping a sweep's predictors and diagnostics between steps: over a sweep's grid it "
                        "gives run_sweep's rows to the bit, at a sweep's cost per step. A step that fails leaves the "
                        "stepper at its last good state.")
      .def(py::init([](std::shared_ptr<const Scene> scene, std::optional<bool> velocities,
                       std::optional<bool> accelerations, const std::optional<py::list>& sensitivities) {
             std::optional<std::vector<SensitivityRequest>> asked;
             if (sensitivities) asked = sensitivity_requests(*sensitivities, "Stepper");
             return stepper_for_scene(std::move(scene), velocities, accelerations, asked);
           }),
           py::arg("scene"), py::kw_only(), py::arg("velocities") = py::none(), py::arg("accelerations") = py::none(),
           py::arg("sensitivities") = py::none(),
           "A stepper for a scene: its solver settings, output points, efforts, limits and rough placement (a "
           "redundant scene "
           "assembled and solved on its independent rows, as run_sweep does); velocities and accelerations as the "
           "scene's output asks unless given; the sensitivities of its output.sensitivities, or of `sensitivities` "
           "(names or (name, step) tuples, as run_sweep's) at every step. ValueError when the scene cannot be "
           "prepared (inconsistent, under-driven) or names no such parameter.")
      .def(py::init([](const Model& model, bool velocities, bool accelerations, Predictor predictor,
                       std::optional<NewtonOptions> newton, std::optional<NewtonOptions> assembly, int max_subdivisions,
                       double expected_step) {
             StepperOptions o;
             o.velocities = velocities, o.accelerations = accelerations, o.predictor = predictor;
             if (newton) o.newton = *newton;
             if (assembly) o.assembly = *assembly;
             o.max_subdivisions = max_subdivisions, o.expected_step = expected_step;
             auto s = std::make_unique<PyStepper>();
             s->stepper = std::make_unique<Stepper>(model, std::move(o));
             return s;
           }),
           py::arg("model"), py::kw_only(), py::arg("velocities") = true, py::arg("accelerations") = true,
           py::arg("predictor") = Predictor::kAuto, py::arg("newton") = py::none(), py::arg("assembly") = py::none(),
           py::arg("max_subdivisions") = 8, py::arg("expected_step") = 0.01, py::keep_alive<1, 2>(),
           "A stepper for a square model with explicit settings (those of a sweep; None: the sweep's defaults); its "
           "placement is the model's initial positions (restart() sets another).")
      .def(
          "step",
          [](PyStepper& s, double t) {
            StepSummary sum;
            py::gil_scoped_release free;
            (void)s.stepper->step(t, &sum);  // the status is in the summary returned
            return sum;
          },
          py::arg("t"),
          "Solve at time t (any spacing, forward or backward; the first step assembles). Returns a StepSummary; on "
          "success q, qd, qdd and time are the solution at t, otherwise the last good state is kept.")
      .def(
          "restart",
          [](PyStepper& s, const Eigen::Ref<const Eigen::VectorXd>& placement) {
            s.stepper->restart(coordinate_vector(s.stepper->model(), placement, "placement"));
          },
          py::arg("placement"), "Forget the history (a jump of the clock): the next step assembles from placement.")
      .def_property_readonly(
          "started", [](const PyStepper& s) { return s.stepper->started(); },
          "a step has succeeded since construction or the last restart()")
      .def_property_readonly(
          "time", [](const PyStepper& s) { return s.stepper->time(); },
          "time of the current state (NaN before the first success)")
      .def_property_readonly(
          "q", [](const PyStepper& s) -> const Eigen::VectorXd& { return s.stepper->q(); },
          py::return_value_policy::reference_internal, "positions of the current state (read-only view)")
      .def_property_readonly(
          "qd", [](const PyStepper& s) -> const Eigen::VectorXd& { return s.stepper->qd(); },
          py::return_value_policy::reference_internal, "velocities (empty when not solved)")
      .def_property_readonly(
          "qdd", [](const PyStepper& s) -> const Eigen::VectorXd& { return s.stepper->qdd(); },
          py::return_value_policy::reference_internal, "accelerations (empty when not solved)")
      .def_property_readonly(
          "points",
          [](const PyStepper& s) {
            py::dict out;
            const PointMotion* p = s.stepper->point_motions();
            const auto& pts = s.stepper->options().points;
            for (std::size_t i = 0; p && i < pts.size(); ++i) {
              const int d = pts[i].dimension();
              auto vec = [d](const std::array<double, 3>& a) {
                py::array_t<double> v(d);
                std::copy(a.begin(), a.begin() + d, v.mutable_data());
                return v;
              };
              out[py::str(pts[i].name)] = py::make_tuple(vec(p[i].r), vec(p[i].v), vec(p[i].a));
            }
            return out;
          },
          "the output points' motions at the current state: name → (position, velocity, acceleration)")
      .def_property_readonly(
          "sensitivity_names", [](const PyStepper& s) { return names_of(s.stepper->options().sensitivities); },
          "parameters whose sensitivities every step delivers (sensitivity())")
      .def(
          "sensitivity",
          [](const PyStepper& s, const std::string& parameter, int order) {
            if (order < 0 || order > 2) throw py::value_error("order must be 0, 1 or 2, not " + std::to_string(order));
            const auto& asked = s.stepper->options().sensitivities;
            const auto it = std::find_if(asked.begin(), asked.end(),
                                         [&](const OutputSensitivity& p) { return p.name == parameter; });
            if (it == asked.end())
              throw py::key_error("the stepper delivers no sensitivities to '" + parameter +
                                  "' (give it in Stepper(scene, sensitivities=[...]))");
            const double* all = s.stepper->sensitivities();
            if (!all) throw py::value_error("the stepper has no state yet: step() first");
            const Index n = s.stepper->model().num_coordinates();
            const std::size_t j = static_cast<std::size_t>(it - asked.begin());
            const double* first = all + SensitivityLayout{n}.offset(j, order);
            py::array_t<double> out(n);
            std::copy(first, first + n, out.mutable_data());
            return out;
          },
          py::arg("parameter"), py::arg("order") = 0,
          "The current state's ∂q/∂p (order 0), ∂q̇/∂p (1) or ∂q̈/∂p (2) for a parameter of sensitivity_names, in the "
          "order of q (NaN where not solved, and at a singular position)")
      .def_property_readonly("efforts", &efforts_of,
                             "the scene's output.efforts at the current state: driver name → (effort, power) (NaN "
                             "at a singular position); empty without them or before the first step")
      .def_property_readonly("reactions", &reactions_of,
                             "the scene's output.reactions at the current state: joint name → (Fx, Fy, Mz), in "
                             "space (Fx, Fy, Fz, Mx, My, Mz), N and N m about the joint's point, in world axes or "
                             "output.reaction_axes' joint axes")
      .def_property_readonly("losses", &losses_of,
                             "the scene's output.losses now: a bearing's torsional spring → (friction, power), its "
                             "moment (N m; a slide's force, N) and the power it dissipates (W); a gear → (power,)")
      .def_property_readonly(
          "summary", [](const PyStepper& s) { return s.stepper->summary(); },
          "everything the steps did so far, as a sweep's SweepSummary (to_dict() for JSON)")
      .def_property_readonly(
          "model", [](const PyStepper& s) -> const Model& { return s.stepper->model(); },
          py::return_value_policy::reference_internal, "the model stepped");
}

}  // namespace phiq::python
