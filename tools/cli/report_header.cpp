// report_header(): the keys every scene's JSON report starts with (report_header.hpp).
#include "report_header.hpp"

#include "phiq/version.hpp"

namespace phiq::tools {

nlohmann::ordered_json report_header(int format, const std::string& scene_path, const Scene& scene) {
  nlohmann::ordered_json j;
  j["format"] = format;
  j["phiq"] = version();
  j["scene"] = scene_path;
  if (scene.name.empty())
    j["name"] = nullptr;
  else
    j["name"] = scene.name;
  nlohmann::ordered_json parameters = nlohmann::ordered_json::object();
  for (const auto& [n, v] : scene.parameters) parameters[n] = v;
  j["parameters"] = parameters;
  return j;
}

}  // namespace phiq::tools
