// Scenes: load_scene / parse_scene (the YAML format of models/README.md, with the caller's parameter values), and
// the Scene object holding the model and the sweep's options.

#include "bindings.hpp"

#include <map>
#include <memory>

namespace phiq::python {

namespace {

SceneOverrides overrides_of(const std::optional<std::map<std::string, double>>& parameters, const Model* share) {
  SceneOverrides o;
  if (parameters)
    for (const auto& [name, value] : *parameters) o.parameters.emplace_back(name, value);
  o.share_analysis_with = share;
  return o;
}

}  // namespace

void bind_scene(py::module_& m) {
  py::class_<Scene, std::shared_ptr<Scene>>(m, "Scene",
                                            "A loaded scene: the model, the time grid, the solver settings and the "
                                            "outputs (models/README.md).")
      .def_readonly("path", &Scene::path, "the file it was read from (or the name given to parse_scene)")
      .def_readonly("name", &Scene::name, "the scene's `name` field")
      .def_readonly("text", &Scene::text, "the text it was parsed from")
      .def_property_readonly(
          "parameters",
          [](const Scene& s) {
            py::dict d;  // (insertion-ordered: the file's order)
            for (const auto& [name, value] : s.parameters) d[py::str(name)] = value;
            return d;
          },
          "the scene's parameters and their values (overrides applied), in file order")
      .def_property_readonly(
          "model", [](const Scene& s) -> const Model& { return *s.model; }, py::return_value_policy::reference_internal,
          "the mechanism (a Model)")
      .def_readonly("parts", &Scene::parts, "the scene's `parts` (list of Part), in file order")
      .def_property_readonly(
          "options", [](const Scene& s) { return s.sweep; },
          "a copy of the scene's SweepOptions (time grid, solver, outputs), to change and pass "
          "to run_sweep")
      .def("__repr__", [](const Scene& s) {
        return "<phiq.Scene '" + (s.name.empty() ? s.path : s.name) +
               "': " + std::to_string(s.model->num_coordinates()) + " coordinates, " +
               std::to_string(s.model->num_equations()) + " equations>";
      });

  m.def(
      "load_scene",
      [](const std::string& path, const std::optional<std::map<std::string, double>>& parameters,
         const Scene* share_analysis_with) {
        const SceneOverrides o =
            overrides_of(parameters, share_analysis_with ? share_analysis_with->model.get() : nullptr);
        py::gil_scoped_release free;
        return std::make_shared<Scene>(load_scene(path, SceneLimits{}, o));
      },
      py::arg("path"), py::arg("parameters") = py::none(), py::arg("share_analysis_with") = py::none(),
      "Load a scene file (YAML, models/README.md). `parameters` replaces values of the scene's `parameters` "
      "section by name (a design study); `share_analysis_with`, a scene of the same structure, lends its pattern "
      "and symbolic analysis. Raises SceneError (a ValueError) with one line 'FILE:LINE:COL: field: message'.");
  m.def(
      "parse_scene",
      [](const std::string& text, const std::string& path,
         const std::optional<std::map<std::string, double>>& parameters, const Scene* share_analysis_with) {
        const SceneOverrides o =
            overrides_of(parameters, share_analysis_with ? share_analysis_with->model.get() : nullptr);
        py::gil_scoped_release free;
        return std::make_shared<Scene>(parse_scene(text, path, SceneLimits{}, o));
      },
      py::arg("text"), py::arg("path") = "<string>", py::arg("parameters") = py::none(),
      py::arg("share_analysis_with") = py::none(),
      "A scene from its text (YAML or JSON); `path` names it in messages. As load_scene otherwise.");
}

}  // namespace phiq::python
