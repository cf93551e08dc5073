// phiq.modes(scene, t): every real assembly mode of a scene (phiq/modes.hpp) as numpy arrays.
#include "bindings.hpp"

namespace phiq::python {

namespace py = pybind11;

void bind_modes(py::module_& m) {
  m.def(
      "modes",
      [](const Scene& scene, std::optional<double> t, int threads, std::int64_t max_paths, int max_winding) {
        ModesOptions o;
        o.time = t ? *t : scene.sweep.t_begin;
        o.threads = threads;
        o.max_paths = max_paths;
        if (max_winding < 1) throw Error("modes: max_winding must be 1 or more, not " + std::to_string(max_winding));
        o.max_winding = max_winding;
        AssemblyModes r;
        {
          py::gil_scoped_release free;
          r = find_assembly_modes(*scene.model, o);
        }
        if (r.summary.status != ModesStatus::kSuccess) throw Error(r.summary.message);
        const Index n = scene.model->num_coordinates();
        const auto k = static_cast<Eigen::Index>(r.modes.size());
        Eigen::MatrixXd q(k, n);
        Eigen::VectorXd residual(k), condition(k);
        std::vector<bool> singular;
        for (Eigen::Index i = 0; i < k; ++i) {
          const AssemblyMode& a = r.modes[static_cast<std::size_t>(i)];
          q.row(i) = a.q.transpose();
          residual(i) = a.residual, condition(i) = a.condition;
          singular.push_back(a.singular);
        }
        py::dict d;
        d["q"] = q;
        d["coordinates"] = scene.model->coordinate_names();
        d["residual"] = residual;
        d["condition"] = condition;
        d["singular"] = py::array_t<bool>(py::cast(singular));
        d["time"] = o.time;
        d["paths"] = r.summary.paths;  // tracked: the start system's (block by block, all blocks')
        d["total_degree"] = r.summary.total_degree;
        d["complex"] = r.summary.complex;
        d["at_infinity"] = r.summary.at_infinity;
        d["failed_paths"] = r.summary.failed_paths;
        d["method"] = modes_method_name(r.summary.method);
        d["method_note"] = r.summary.method_note;
        d["start_system"] = r.summary.start_system;
        py::list failures;  // (path, why), numbered from 1 as `phiq modes` prints them
        for (const auto& [path, why] : r.summary.failures) failures.append(py::make_tuple(path + 1, why));
        d["failures"] = failures;
        return d;
      },
      py::arg("scene"), py::arg("t") = py::none(), py::arg("threads") = 0, py::arg("max_paths") = 100000,
      py::arg("max_winding") = ModesOptions{}.max_winding,
      "Every real assembly mode of the scene at time t (default time.start), by polynomial homotopy continuation "
      "(engine/include/phiq/modes.hpp): a dict with 'q' (modes x coordinates; a row is a placement a Workspace's q "
      "takes), 'coordinates', 'residual', 'condition', 'singular', and the homotopy's 'paths' (those tracked), "
      "'total_degree' (of the system as given, before its degrees were lowered), 'complex', "
      "'at_infinity', 'failed_paths', 'failures' (each failed path as (number from 1, why)), 'method' (whole "
      "system or block by block), 'method_note' (why not block by block) and 'start_system' (total degree or "
      "multi-homogeneous, degrees lowered or not). max_winding: the most turns round t = 0 the end game takes to "
      "close a path's cycle (ModesOptions::max_winding). Raises ValueError naming the constraint when one is not "
      "polynomial, or when the paths are more than max_paths; for a t that is not finite, threads outside 0 to "
      "1000000, max_paths or max_winding below 1.");
}

}  // namespace phiq::python
