// The pieces of the extension module phiq._phiq, one file per part (module.cpp binds them), and
// what they share: the conversions of coordinate vectors, with their size checked against the model.
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include <phiq/phiq.hpp>

namespace phiq::python {

namespace py = pybind11;

void bind_model(py::module_& m);
void bind_scene(py::module_& m);
void bind_solve(py::module_& m);
void bind_sweep(py::module_& m);
void bind_sweep_result(py::module_& m);
void bind_batch_result(py::module_& m);
void bind_stepper(py::module_& m);
void bind_parts(py::module_& m);
void bind_modes(py::module_& m);
void bind_clearance(py::module_& m);

/// A vector the caller passed as `what`, checked to have the model's n entries: phiq::Error (ValueError in Python)
/// otherwise, with the sizes in the message, as the C++ pre-condition checks word it.
inline Eigen::VectorXd coordinate_vector(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& v,
                                         const char* what) {
  if (v.size() != model.num_coordinates())
    throw Error(std::string(what) + " has " + std::to_string(v.size()) + " entries; the model has " +
                std::to_string(model.num_coordinates()) + " coordinates");
  return v;
}

/// The names of a plan's outputs of one sort (points, drivers, sensitivities), in order.
template <class Items>
std::vector<std::string> names_of(const Items& items) {
  std::vector<std::string> n;
  for (const auto& item : items) n.push_back(item.name);
  return n;
}

/// The parameters a Python caller asks for sensitivities to: each a name or a (name, step) tuple (TypeError naming
/// `who` otherwise); read with the GIL held.
inline std::vector<SensitivityRequest> sensitivity_requests(const py::list& parameters, const char* who) {
  std::vector<SensitivityRequest> asked;
  for (const py::handle& p : parameters) {
    if (py::isinstance<py::str>(p)) {
      asked.push_back({p.cast<std::string>(), 0.0});
    } else if (py::isinstance<py::tuple>(p) && py::len(p) == 2) {
      asked.push_back({p[py::int_(0)].cast<std::string>(), p[py::int_(1)].cast<double>()});
    } else {
      throw py::type_error(std::string(who) + ": each parameter is a name or a (name, step) tuple, not " +
                           py::repr(p).cast<std::string>());
    }
  }
  return asked;
}

/// Prepares a scene's model for the square sweep as `phiq run` does (prepare_scene), without the GIL: "" on success,
/// else the one line the CLI prints for an inconsistent or under-driven scene ("t = T: …"), with the assembly's
/// summary in square->assembly.
inline std::string square_for_sweep(const Scene& scene, double t_begin, const NewtonOptions& assembly,
                                    SquareScene* square) {
  const SolveStatus st = prepare_scene(*scene.model, t_begin, assembly, square);
  return st == SolveStatus::kSuccess ? "" : "t = " + format_time(t_begin) + ": " + square->assembly.message;
}

/// square_for_sweep() called with the GIL held: it is released meanwhile.
inline std::string prepare_for_sweep(const Scene& scene, double t_begin, const NewtonOptions& assembly,
                                     SquareScene* square) {
  py::gil_scoped_release free;
  return square_for_sweep(scene, t_begin, assembly, square);
}

/// A copy of an Eigen vector as a new numpy array (the caller owns it).
inline py::array_t<double> to_numpy(const Eigen::VectorXd& v) {
  py::array_t<double> a(v.size());
  std::copy(v.data(), v.data() + v.size(), a.mutable_data());
  return a;
}

}  // namespace phiq::python
