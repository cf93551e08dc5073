// Scene files: a mechanism, its drivers, the time sweep and the outputs, in YAML (format: models/README.md).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "phiq/model.hpp"
#include "phiq/sweep.hpp"

namespace phiq {

// A scene that cannot be used. what() is one line: "FILE:LINE:COL: FIELD.PATH: message".
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Scene {
  std::string path;
  std::string name;
  std::unique_ptr<Model> model;
  SweepOptions sweep;
  std::vector<Index> output_coordinates;  // columns written, in scene order (default: all coordinates)
};

// Loads and validates a scene file. Throws SceneError (never crashes) for unreadable files, YAML syntax errors,
// unknown or duplicate fields and names, wrong types, NaN or infinite numbers and impossible values.
Scene load_scene(const std::string& path);
// The same from text; `path` is used in messages only.
Scene parse_scene(const std::string& text, const std::string& path);

}  // namespace phiq
