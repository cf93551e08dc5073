// phiq.clearance(scene): the scene's `output.clearance` measured along its sweep (phiq/clearance.hpp) as numpy
// arrays: each pair's distance per row, and its worst pose, witness points, sensitivities and interference.
#include <limits>

#include "bindings.hpp"

namespace phiq::python {

namespace py = pybind11;

namespace {

// The report as the dict phiq.clearance returns (its docstring names the keys).
py::dict clearance_dict(const Scene& scene, const ClearanceReport& r, const SweepSummary& summary) {
  const auto rows = static_cast<Eigen::Index>(r.times.size());
  const auto k = static_cast<Eigen::Index>(r.pairs.size());
  const auto np = static_cast<Eigen::Index>(r.parameters.size());
  Eigen::MatrixXd distance(rows, k), point_a(k, 3), point_b(k, 3), normal(k, 3), sensitivities(k, np);
  Eigen::VectorXd worst_t(k), worst_distance(k);
  std::vector<bool> refined;
  std::vector<Index> unproven;
  py::list pairs, interference, minima, minima_sensitivities;
  for (Eigen::Index i = 0; i < k; ++i) {
    const PairClearance& p = r.pairs[static_cast<std::size_t>(i)];
    for (Eigen::Index row = 0; row < rows; ++row) distance(row, i) = p.row_distance[static_cast<std::size_t>(row)];
    const ClearanceMinimum& w = p.worst;
    worst_t(i) = w.t, worst_distance(i) = w.at.distance;
    point_a.row(i) << w.at.point_a.x, w.at.point_a.y, w.at.point_a.z;
    point_b.row(i) << w.at.point_b.x, w.at.point_b.y, w.at.point_b.z;
    normal.row(i) << w.at.normal.x, w.at.normal.y, w.at.normal.z;
    for (Eigen::Index j = 0; j < np; ++j)
      sensitivities(i, j) = static_cast<std::size_t>(j) < w.sensitivities.size()
                                ? w.sensitivities[static_cast<std::size_t>(j)]
                                : std::numeric_limits<double>::quiet_NaN();
    refined.push_back(w.refined);
    unproven.push_back(p.unproven_intervals);
    pairs.append(py::make_tuple(scene.parts[static_cast<std::size_t>(p.a)].name,
                                scene.parts[static_cast<std::size_t>(p.b)].name));
    Eigen::MatrixXd in(static_cast<Eigen::Index>(p.interference.size()), 2);
    for (Eigen::Index m = 0; m < in.rows(); ++m)
      in.row(m) << p.interference[static_cast<std::size_t>(m)].entry, p.interference[static_cast<std::size_t>(m)].exit;
    interference.append(in);
    Eigen::MatrixXd mins(static_cast<Eigen::Index>(p.minima.size()), 2), mins_d(mins.rows(), np);
    for (Eigen::Index m = 0; m < mins.rows(); ++m) {
      const ClearanceMinimum& at = p.minima[static_cast<std::size_t>(m)];
      mins.row(m) << at.t, at.at.distance;
      for (Eigen::Index j = 0; j < np; ++j)
        mins_d(m, j) = static_cast<std::size_t>(j) < at.sensitivities.size()
                           ? at.sensitivities[static_cast<std::size_t>(j)]
                           : std::numeric_limits<double>::quiet_NaN();
    }
    minima.append(mins);
    minima_sensitivities.append(mins_d);
  }
  py::dict d;
  const Eigen::VectorXd t = Eigen::Map<const Eigen::VectorXd>(r.times.data(), rows);  // a copy the array owns
  d["t"] = t;
  d["pairs"] = pairs;
  d["columns"] = clearance_pair_names(r, scene.parts);
  d["distance"] = distance;
  d["worst_t"] = worst_t;
  d["worst_distance"] = worst_distance;
  d["point_a"] = point_a;
  d["point_b"] = point_b;
  d["normal"] = normal;
  d["refined"] = py::array_t<bool>(py::cast(refined));
  d["parameters"] = r.parameters;
  d["sensitivities"] = sensitivities;
  d["interference"] = interference;
  d["minima"] = minima;
  d["minima_sensitivities"] = minima_sensitivities;
  d["unproven_intervals"] = py::array_t<Index>(py::cast(unproven));
  d["threshold"] = r.threshold;
  d["interferes"] = r.interferes();
  d["bound_held"] = r.bound_held();
  d["pairs_selected"] = r.pairs_selected;
  d["pairs_measured"] = r.pairs_measured;
  d["positions_solved"] = r.positions_solved;
  d["summary"] = summary;
  return d;
}

}  // namespace

void bind_clearance(py::module_& m) {
  m.def(
      "clearance",
      [](const Scene& scene, std::optional<double> threshold) {
        if (!scene.clearance.requested)
          throw Error(scene.path + ": output.clearance: missing: the scene names no pairs of parts to measure");
        ClearancePlan plan = scene.clearance;
        if (threshold) {
          if (!(*threshold >= 0.0))
            throw Error("clearance: threshold " + shortest(*threshold) + " must be 0 or more (m)");
          plan.threshold = *threshold;
        }
        SweepSummary summary;
        ClearanceReport r;
        {
          py::gil_scoped_release free;
          // as scene_clearance() does, with the plan's threshold given here
          SweepOptions options = scene.sweep;
          options.sensitivities.clear();  // solved at the minima only
          Workspace ws(*scene.model);
          const ClearanceRows rows = sweep_rows(*scene.model, options, ws, &summary);
          ClearanceOptions co;
          co.solver = scene.sweep;
          co.sensitivities = scene.sweep.sensitivities;
          r = clearance_along(*scene.model, scene.parts, plan, rows, co);
        }
        return clearance_dict(scene, r, summary);
      },
      py::arg("scene"), py::arg("threshold") = py::none(),
      "The distances between the scene's parts along its sweep, as `phiq clearance` measures them "
      "(output.clearance; engine/include/phiq/clearance.hpp): a dict with 't' (rows), 'pairs' ((A, B) names), "
      "'columns' ('A.B'), 'distance' (rows x pairs, m, negative: overlap depth); per pair its worst pose "
      "'worst_t', 'worst_distance', 'point_a', 'point_b', 'normal' (pairs x 3, world axes), 'refined', "
      "'sensitivities' (pairs x 'parameters': d distance / d parameter, of output.sensitivities), 'interference' "
      "(a (entry, exit) array per pair), 'minima' (a (t, distance) array per pair), 'minima_sensitivities' (a "
      "minima x 'parameters' array per pair: each minimum's own), 'unproven_intervals'; and "
      "'threshold', 'interferes', 'bound_held', 'pairs_selected', 'pairs_measured', 'positions_solved', 'summary' "
      "(the sweep's SweepSummary: a failed sweep's report holds the rows before the failure). threshold: instead "
      "of the scene's (m, 0 or more, else ValueError).");
}

}  // namespace phiq::python
