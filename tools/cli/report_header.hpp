// The first keys of every JSON report about one scene (`run --summary`, `clearance --summary`): its format, the phiq
// that wrote it, and the scene with the parameters' values it was solved at (after `--set`), so that a report kept
// by a harness says what it is about without the command line.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "phiq/scene.hpp"

namespace phiq::tools {

// {"format": format, "phiq": version(), "scene": scene_path, "name": the scene's name or null, "parameters": {...}}.
nlohmann::ordered_json report_header(int format, const std::string& scene_path, const Scene& scene);

}  // namespace phiq::tools
