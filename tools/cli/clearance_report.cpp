// The summary of `phiq clearance --summary` (clearance_report.hpp).
#include "clearance_report.hpp"

#include <nlohmann/json.hpp>

#include "report_header.hpp"

namespace phiq::tools {

namespace {

nlohmann::ordered_json clearance_point_json(kin3::V3 p) { return nlohmann::ordered_json::array({p.x, p.y, p.z}); }

// {P: ∂d/∂P} of a minimum whose sensitivities were solved; {} otherwise.
nlohmann::ordered_json clearance_sensitivities_json(const ClearanceReport& r, const ClearanceMinimum& m) {
  nlohmann::ordered_json sensitivities = nlohmann::ordered_json::object();
  for (std::size_t k = 0; k < m.sensitivities.size() && k < r.parameters.size(); ++k)
    sensitivities[r.parameters[k]] = m.sensitivities[k];
  return sensitivities;
}

// Each of the pair's local minima (HDF5 /minima's t, distance, refined, in its order) with its witness points and,
// where the scene asks for sensitivities, its own ∂d/∂p.
nlohmann::ordered_json clearance_minima_json(const ClearanceReport& r, const PairClearance& p) {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const ClearanceMinimum& m : p.minima) {
    nlohmann::ordered_json j = {{"t", m.t},
                                {"distance", m.at.distance},
                                {"refined", m.refined},
                                {"point_a", clearance_point_json(m.at.point_a)},
                                {"point_b", clearance_point_json(m.at.point_b)},
                                {"normal", clearance_point_json(m.at.normal)}};
    if (!m.sensitivities.empty()) j["sensitivities"] = clearance_sensitivities_json(r, m);
    list.push_back(std::move(j));
  }
  return list;
}

nlohmann::ordered_json clearance_pair_json(const ClearanceReport& r, const PairClearance& p, const std::string& a,
                                           const std::string& b) {
  nlohmann::ordered_json j;
  j["a"] = a;
  j["b"] = b;
  const ClearanceMinimum& w = p.worst;
  j["worst"] = {{"t", w.t},
                {"distance", w.at.distance},
                {"refined", w.refined},
                {"below_threshold", w.at.distance < r.threshold},
                {"point_a", clearance_point_json(w.at.point_a)},
                {"point_b", clearance_point_json(w.at.point_b)},
                {"normal", clearance_point_json(w.at.normal)},
                {"sensitivities", clearance_sensitivities_json(r, w)}};
  j["minima"] = p.minima.size();
  j["local_minima"] = clearance_minima_json(r, p);
  j["interference"] = nlohmann::ordered_json::array();
  for (const InterferenceInterval& i : p.interference)
    j["interference"].push_back({{"entry", i.entry}, {"exit", i.exit}});
  j["unproven_intervals"] = p.unproven_intervals;
  return j;
}

}  // namespace

std::string clearance_summary_json(const Scene& scene, const std::string& scene_path, const ClearanceReport& r) {
  nlohmann::ordered_json j = report_header(kClearanceSummaryFormat, scene_path, scene);
  j["threshold"] = r.threshold;
  j["rows"] = r.times.size();
  j["pairs_selected"] = r.pairs_selected;
  j["pairs_measured"] = r.pairs_measured;
  j["positions_solved"] = r.positions_solved;
  j["interferes"] = r.interferes();
  j["bound_held"] = r.bound_held();
  j["pairs"] = nlohmann::ordered_json::array();
  for (const PairClearance& p : r.pairs)
    j["pairs"].push_back(clearance_pair_json(r, p, scene.parts[static_cast<std::size_t>(p.a)].name,
                                             scene.parts[static_cast<std::size_t>(p.b)].name));
  // names and paths with bytes that are not UTF-8 get U+FFFD rather than losing the report (json_text's choice)
  return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

}  // namespace phiq::tools
