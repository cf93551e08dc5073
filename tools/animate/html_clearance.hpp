// What `phiq animate SCENE -o OUT.html` shows of the scene's `output.clearance` (phiq/clearance.hpp): each pair's
// witness points at its worst pose, and at every row which parts come within the threshold, as the JSON field
// `clearance` of the viewer's data (tools/animate/viewer/viewer.js documents it).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "phiq/clearance.hpp"
#include "phiq/scene.hpp"

namespace phiq::tools {

// The viewer's `clearance` of `report`, measured on `scene`'s parts (the first of the drawn parts, in order):
// {threshold, t: the report's rows' times, pairs: [{a, b: part indices, name: "A / B", worst_t, distance, point_a,
// point_b: world x, y, z, near: viewer_near_rows(), interference: [[entry, exit], …]}]}.
nlohmann::json viewer_clearance(const Scene& scene, const ClearanceReport& report);

// A character per row of `report`, 1 where `pair` comes below the threshold in the row's span (the times nearer
// that row than any other): on the row, at a minimum refined between rows, or in an interference interval, so that
// parts which interfere only between two rows are coloured at the row nearest.
std::string viewer_near_rows(const ClearanceReport& report, const PairClearance& pair);

}  // namespace phiq::tools
