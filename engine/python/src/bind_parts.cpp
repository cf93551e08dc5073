// Parts (phiq/parts.hpp): a scene's bodies as parts — name, the body they are on, their mass properties and shapes —
// and their poses at a position q, for a caller that draws the mechanism or computes with its masses.

#include "bindings.hpp"

#include <pybind11/numpy.h>

#include "phiq/drawn_parts.hpp"
#include "phiq/inverse_dynamics.hpp"

namespace phiq::python {

namespace {

py::array_t<double> vector3(const kin3::V3& v) {
  py::array_t<double> a(3);
  auto w = a.mutable_unchecked<1>();
  w(0) = v.x, w(1) = v.y, w(2) = v.z;
  return a;
}

py::array_t<double> matrix3(const std::array<double, 9>& m) {
  py::array_t<double> a({3, 3});
  auto w = a.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < 3; ++i)
    for (py::ssize_t j = 0; j < 3; ++j) w(i, j) = m[static_cast<std::size_t>(3 * i + j)];
  return a;
}

const char* source_name(MassSource s) {
  return s == MassSource::kStated ? "stated" : s == MassSource::kDensity ? "density" : "none";
}

}  // namespace

void bind_parts(py::module_& m) {
  py::class_<Part>(m, "Part", "A body as a part: its frame, its shapes and its mass (models/README.md, Parts).")
      .def_readonly("name", &Part::name, "the part's name")
      .def_readonly("body", &Part::body, "the body it is on, or the kind of its own frame")
      .def_readonly("derived", &Part::derived, "made by phiq from the constraints (drawn_parts), not stated")
      .def_property_readonly(
          "mass", [](const Part& p) { return p.mass.mass; }, "kg (0 without mass)")
      .def_property_readonly(
          "center_of_mass", [](const Part& p) { return vector3(p.mass.center); }, "in the part's frame (m)")
      .def_property_readonly(
          "inertia", [](const Part& p) { return matrix3(p.mass.inertia); },
          "3×3, kg·m², about the centre of mass in the part's axes")
      .def_property_readonly(
          "mass_source", [](const Part& p) { return source_name(p.mass_source); }, "'stated', 'density' or 'none'")
      .def_property_readonly(
          "shapes",
          [](const Part& p) {
            py::list out;
            for (const Shape& s : p.shapes) {
              py::dict d;
              d["type"] = to_string(s.kind);
              d["name"] = s.name;
              d["at"] = vector3(s.at);
              d["rotation"] = matrix3(s.rotation);
              out.append(d);
            }
            return out;
          },
          "each shape's type, name and placement in the part's frame (at, rotation)")
      .def(
          "pose",
          [](const Part& p, const Eigen::Ref<const Eigen::VectorXd>& q, double t) {
            if (max_coordinate(p.frame) >= q.size())
              throw Error("Part.pose: q has " + std::to_string(q.size()) + " entries; part '" + p.name +
                          "' reads coordinate " + std::to_string(max_coordinate(p.frame)));
            const Pose pose = part_pose(p.frame, q.data(), t);
            return py::make_tuple(vector3(pose.at), matrix3(pose.rotation));
          },
          py::arg("q"), py::arg("t") = 0.0,
          "(origin, rotation) of the part's frame at (q, t): a body point s is at origin + rotation @ s")
      .def("__repr__", [](const Part& p) { return "<phiq.Part '" + p.name + "' on " + p.body + ">"; });
  m.def(
      "driver_efforts",
      [](const Scene& s, const Eigen::Ref<const Eigen::VectorXd>& t, const Eigen::Ref<const Eigen::MatrixXd>& q,
         const Eigen::Ref<const Eigen::MatrixXd>& qd, const Eigen::Ref<const Eigen::MatrixXd>& qdd) {
        const Model& model = *s.model;
        const Index n = model.num_coordinates();
        if (q.cols() != n || qd.cols() != n || qdd.cols() != n || q.rows() != t.size() || qd.rows() != t.size() ||
            qdd.rows() != t.size())
          throw Error(
              "driver_efforts: q, qd and qdd need one row per time and one column per coordinate of the "
              "scene (" +
              std::to_string(n) + "): a sweep with velocities, accelerations and every coordinate");
        py::list names;
        for (Index c : rheonomic_constraints(model))
          names.append(model.constraints()[static_cast<std::size_t>(c)].name);
        Eigen::MatrixXd out(t.size(), static_cast<Index>(names.size()));
        {
          py::gil_scoped_release free;
          Workspace ws(model);
          DriverEfforts efforts(model, s.parts, s.loads, s.sweep.efforts.natural);  // (its losses set up once)
          std::vector<double> e;
          for (Index k = 0; k < t.size(); ++k) {
            ws.q = q.row(k).transpose(), ws.qd = qd.row(k).transpose(), ws.qdd = qdd.row(k).transpose();
            std::string why;
            if (efforts(t(k), ws, e, &why) != SolveStatus::kSuccess)
              throw Error("driver_efforts: at t = " + std::to_string(t(k)) + ": " + why);
            for (std::size_t j = 0; j < e.size(); ++j) out(k, static_cast<Index>(j)) = e[j];
          }
        }
        return py::make_tuple(names, out);
      },
      py::arg("scene"), py::arg("t"), py::arg("q"), py::arg("qd"), py::arg("qdd"),
      "Inverse dynamics: each driver's effort (−λ of its row: the torque or force its motor applies) at every row "
      "of a motion, under the scene's `loads` and its parts' mass (phiq/inverse_dynamics.hpp). Returns (names, "
      "rows × drivers array). phiq.driver_efforts(scene, result) takes a SweepResult.");
  m.def(
      "drawn_parts", [](const Scene& s) { return drawn_parts(s); }, py::arg("scene"),
      "The parts a drawing of the scene shows: its own, then those derived from its constraints.");
}

}  // namespace phiq::python
