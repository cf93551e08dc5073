/// @file
/// A scene file parsed once and read many times, each time with other overrides: the cases of a batch (`phiq
/// batch`), which differ only in parameter values. Its own header (not phiq/scene.hpp, not phiq/phiq.hpp) so that
/// the batch's needs rebuild only the batch.
#pragma once

#include <memory>
#include <string>

#include "phiq/scene.hpp"

namespace phiq {

/// The text of a scene, checked (size, encoding, the YAML shape limits of SceneLimits) and parsed into its YAML
/// tree once. read() then builds the Scene from that tree, as parse_scene() with the same overrides would from the
/// text: the same Scene, field for field, without reading the file or parsing the YAML again (2 000 cases of the
/// seed's crank-slider loaded in 0.92 s read and parsed each, 0.23 s from one tree; bench/README.md, "Batches").
/// Not thread-safe: reading a yaml-cpp tree may change it (a missing key is added as an undefined node), so each
/// thread reads its own ParsedScene (copies share nothing: the copy constructor parses the text again).
class ParsedScene {
 public:
  /// Reads the file (as load_scene()) and parses it. Throws SceneError as load_scene() does for the file and the
  /// YAML; the scene's fields are read, and their errors thrown, by read().
  static ParsedScene load(const std::string& path, const SceneLimits& limits = {});
  /// Parses `text`; `path` is used in messages only (as parse_scene()).
  ParsedScene(std::string text, std::string path, const SceneLimits& limits = {});
  /// A tree of its own for another thread: `other`'s text parsed again (nothing shared).
  ParsedScene(const ParsedScene& other);
  ParsedScene& operator=(const ParsedScene&) = delete;
  /// Takes `other`'s tree; `other` may then only be destroyed.
  ParsedScene(ParsedScene&& other) noexcept;
  ~ParsedScene();

  /// The scene with these overrides: parse_scene(text(), path(), limits, overrides). Throws what it throws.
  Scene read(const SceneOverrides& overrides = {});
  /// The scene's text (what Scene::text holds).
  const std::string& text() const;
  /// The path messages name (Scene::path).
  const std::string& path() const;

 private:
  struct Tree;
  std::unique_ptr<Tree> tree_;
};

}  // namespace phiq
