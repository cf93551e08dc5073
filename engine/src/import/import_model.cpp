// The formats phiq reads besides its own scenes, by the file's extension, and the file-reading entry point of the
// robot descriptions (phiq/import_model.hpp).
#include "phiq/import_model.hpp"

#include <algorithm>
#include <cctype>

#include "phiq/scene.hpp"
#include "scene/read_scene_file.hpp"

namespace phiq {

ModelFormat model_format(const std::string& path) {
  const std::size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || path.find('/', dot) != std::string::npos) return ModelFormat::kScene;
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == "asmt") return ModelFormat::kAsmt;
  if (ext == "urdf") return ModelFormat::kUrdf;
  if (ext == "mjcf" || ext == "xml") return ModelFormat::kMjcf;
  if (ext == "sdf") return ModelFormat::kSdf;
  return ModelFormat::kScene;
}

ModelImport import_model_file(const std::string& path, const ImportOptions& options) {
  const ModelFormat format = model_format(path);
  if (format != ModelFormat::kUrdf && format != ModelFormat::kMjcf && format != ModelFormat::kSdf)
    throw SceneError(path + ": not a URDF (.urdf), MJCF (.mjcf, .xml) or SDF (.sdf) file");
  const std::string text = detail::scene::read_scene_file(path, SceneLimits{});
  if (format == ModelFormat::kSdf) return import_sdf(text, path, options);
  return format == ModelFormat::kUrdf ? import_urdf(text, path, options) : import_mjcf(text, path, options);
}

}  // namespace phiq
