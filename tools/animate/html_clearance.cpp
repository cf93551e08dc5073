#include "html_clearance.hpp"

#include <algorithm>

namespace phiq::tools {

std::string viewer_near_rows(const ClearanceReport& report, const PairClearance& pair) {
  const std::vector<double>& t = report.times;
  std::string near(pair.row_distance.size(), '0');  // a character per row: compact for long sweeps
  // the row whose span holds time s: the rows' midpoints split the time between them
  auto row_of = [&](double s) {
    const auto above = std::upper_bound(t.begin(), t.end(), s);
    std::size_t r = above == t.begin() ? 0 : static_cast<std::size_t>(above - t.begin()) - 1;
    if (r + 1 < t.size() && t[r + 1] - s < s - t[r]) ++r;
    return std::min(r, near.size() - 1);
  };
  if (near.empty() || t.empty()) return near;
  for (std::size_t r = 0; r < near.size(); ++r)
    if (pair.row_distance[r] < report.threshold) near[r] = '1';
  // between the rows: a refined minimum within the threshold, an interference interval that starts and ends there
  for (const ClearanceMinimum& m : pair.minima)
    if (m.at.distance < report.threshold) near[row_of(m.t)] = '1';
  for (const InterferenceInterval& i : pair.interference)
    for (std::size_t r = row_of(i.entry), last = row_of(i.exit); r <= last; ++r) near[r] = '1';
  return near;
}

nlohmann::json viewer_clearance(const Scene& scene, const ClearanceReport& report) {
  nlohmann::json pairs = nlohmann::json::array();
  for (const PairClearance& p : report.pairs) {
    const ClearanceMinimum& w = p.worst;
    const std::string near = viewer_near_rows(report, p);
    nlohmann::json interference = nlohmann::json::array();
    for (const InterferenceInterval& i : p.interference) interference.push_back({i.entry, i.exit});
    pairs.push_back({{"a", p.a},
                     {"b", p.b},
                     {"name", scene.parts[static_cast<std::size_t>(p.a)].name + " / " +
                                  scene.parts[static_cast<std::size_t>(p.b)].name},
                     {"worst_t", w.t},
                     {"distance", w.at.distance},
                     {"point_a", {w.at.point_a.x, w.at.point_a.y, w.at.point_a.z}},
                     {"point_b", {w.at.point_b.x, w.at.point_b.y, w.at.point_b.z}},
                     {"near", near},
                     {"interference", interference}});
  }
  return {{"threshold", report.threshold}, {"t", report.times}, {"pairs", pairs}};
}

}  // namespace phiq::tools
