// phiq._phiq: the extension module of the Python package phiq (engine/python/README.md). The pure Python modules
// of the package (phiq/__init__.py) import it and add the scene builder and the results' numpy views.
//
// Errors: phiq::Error (a programming error at the API boundary: wrong sizes, unknown names, bad settings) derives
// from std::invalid_argument, which pybind11 raises as ValueError with the same one-line message; a scene that
// cannot be used raises phiq.SceneError (a ValueError); wrong argument types raise TypeError (pybind11).
// Numerical outcomes are never exceptions: they are statuses in the returned summaries (SolveStatus).

#include "bindings.hpp"

PYBIND11_MODULE(_phiq, m) {
  namespace py = pybind11;
  m.doc() = "phiq: sparse, large-scale multibody kinematics (the extension module; use the package phiq).";
  m.attr("__version__") = phiq::version();
  py::register_exception<phiq::SceneError>(m, "SceneError", PyExc_ValueError);
  phiq::python::bind_model(m);
  phiq::python::bind_parts(m);
  phiq::python::bind_scene(m);
  phiq::python::bind_solve(m);
  phiq::python::bind_sweep(m);
  phiq::python::bind_sweep_result(m);
  phiq::python::bind_batch_result(m);
  phiq::python::bind_stepper(m);
  phiq::python::bind_modes(m);
  phiq::python::bind_clearance(m);
}
