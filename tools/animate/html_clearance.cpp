#include "html_clearance.hpp"

namespace phiq::tools {

nlohmann::json viewer_clearance(const Scene& scene, const ClearanceReport& report) {
  nlohmann::json pairs = nlohmann::json::array();
  for (const PairClearance& p : report.pairs) {
    const ClearanceMinimum& w = p.worst;
    std::string near;  // a character per row: compact for long sweeps
    near.reserve(p.row_distance.size());
    for (double d : p.row_distance) near += d < report.threshold ? '1' : '0';
    pairs.push_back({{"a", p.a},
                     {"b", p.b},
                     {"name", scene.parts[static_cast<std::size_t>(p.a)].name + " / " +
                                  scene.parts[static_cast<std::size_t>(p.b)].name},
                     {"worst_t", w.t},
                     {"distance", w.at.distance},
                     {"point_a", {w.at.point_a.x, w.at.point_a.y, w.at.point_a.z}},
                     {"point_b", {w.at.point_b.x, w.at.point_b.y, w.at.point_b.z}},
                     {"near", near}});
  }
  return {{"threshold", report.threshold}, {"t", report.times}, {"pairs", pairs}};
}

}  // namespace phiq::tools
