// `phiq clearance --summary FILE.json`: a ClearanceReport's summary as JSON (format phiq::kClearanceSummaryFormat,
// tools/README.md, "phiq clearance"): each pair's worst pose with its witness points and sensitivities, every local
// minimum (HDF5 /minima's), its interference intervals, and whether the bound between rows held. In the library
// phiq_cli so that the tests read it in-process.
#pragma once

#include <string>

#include "phiq/clearance_files.hpp"
#include "phiq/scene.hpp"

namespace phiq::tools {

// The summary's JSON text of `report`, measured on `scene`'s parts (scene_clearance()); `scene_path` as the command
// names the scene (`<stdin>` for `-`).
std::string clearance_summary_json(const Scene& scene, const std::string& scene_path, const ClearanceReport& report);

}  // namespace phiq::tools
