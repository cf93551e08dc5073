// The public entry points of the scene loader (phiq/scene.hpp): parse_scene and load_scene. Before the YAML tree
// is built, ShapeGuard walks the parser's events and refuses what could exhaust memory or stack; then SceneReader
// (scene_reader.hpp) reads the tree. YAML syntax errors become SceneErrors located in the file.
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>

#include "phiq/import_asmt.hpp"
#include "phiq/import_model.hpp"
#include "phiq/parsed_scene.hpp"
#include "phiq/scene.hpp"
#include "phiq/text.hpp"
#include "scene/read_scene_file.hpp"
#include "scene/scene_reader.hpp"
#include "parts/same_forces.hpp"
#include "solve/models_along.hpp"

namespace phiq {

namespace {

// First pass over the YAML events, before any node tree is built: refuses what a scene never needs and what
// could exhaust memory or stack (deep nesting, aliases, several documents, too many nodes, huge values).
class ShapeGuard final : public YAML::EventHandler {
 public:
  ShapeGuard(const std::string& path, const SceneLimits& limits) : path_(path), limits_(limits) {}
  void OnDocumentStart(const YAML::Mark& m) override {
    if (++documents_ > 1) fail(m, "a scene is one YAML document (found a second '---')");
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& m, YAML::anchor_t) override { count(m); }
  void OnAlias(const YAML::Mark& m, YAML::anchor_t) override {
    fail(m, "YAML aliases (*name) are not supported in scenes");
  }
  void OnScalar(const YAML::Mark& m, const std::string&, YAML::anchor_t, const std::string& value) override {
    count(m);
    if (value.size() > limits_.max_scalar_bytes)
      fail(m, "a value of " + std::to_string(value.size()) + " bytes; the limit is " +
                  std::to_string(limits_.max_scalar_bytes));
  }
  void OnSequenceStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    enter(m);
  }
  void OnSequenceEnd() override { --depth_; }
  void OnMapStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    enter(m);
  }
  void OnMapEnd() override { --depth_; }

 private:
  void count(const YAML::Mark& m) {
    if (++nodes_ > limits_.max_nodes)  // families are the way out of a scene written by hand, not of a converted one
      fail(m, "more than " + std::to_string(limits_.max_nodes) + " values; the scene is too large " +
                  (model_format(path_) == ModelFormat::kScene
                       ? "(write repeated entries as families, `for i in A..B`)"
                       : "for phiq to read (SceneLimits::max_nodes; its YAML tree takes about 0.5 KB a value)"));
  }
  void enter(const YAML::Mark& m) {
    count(m);
    if (++depth_ > limits_.max_depth) fail(m, "nested more than " + std::to_string(limits_.max_depth) + " levels deep");
  }
  [[noreturn]] void fail(const YAML::Mark& m, const std::string& what) const {
    throw SceneError(path_ + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1) + ": " + what);
  }
  const std::string& path_;
  const SceneLimits& limits_;
  int documents_ = 0, depth_ = 0;
  std::size_t nodes_ = 0;
};

std::string yaml_error(const std::string& path, const YAML::Exception& e) {
  std::ostringstream s;
  s << path;
  if (e.mark.line >= 0) s << ":" << e.mark.line + 1 << ":" << e.mark.column + 1;
  s << ": YAML syntax error: " << e.msg;
  return s.str();
}

// A scene is UTF-8 (or ASCII). UTF-16 and UTF-32 — what some editors save as "Unicode" — are recognised by their
// byte order mark or by the NUL bytes of their ASCII characters and named, with the conversion; any other NUL byte
// is located. (A UTF-8 byte order mark is accepted: YAML allows it.)
void refuse_non_utf8_encoding(const std::string& text, const std::string& path) {
  const auto starts = [&](const char* bom, std::size_t n) { return text.compare(0, n, bom, n) == 0; };
  const char* encoding = nullptr;
  if (starts("\xff\xfe\0\0", 4))
    encoding = "UTF-32 (little-endian, with a byte order mark)";
  else if (starts("\0\0\xfe\xff", 4))
    encoding = "UTF-32 (big-endian, with a byte order mark)";
  else if (starts("\xff\xfe", 2))
    encoding = "UTF-16 (little-endian, with a byte order mark)";
  else if (starts("\xfe\xff", 2))
    encoding = "UTF-16 (big-endian, with a byte order mark)";
  else if (text.size() >= 2 && text[0] != '\0' && text[1] == '\0')
    encoding = "UTF-16 (little-endian)";
  else if (text.size() >= 2 && text[0] == '\0' && text[1] != '\0')
    encoding = "UTF-16 (big-endian)";
  if (encoding)
    throw SceneError(path + ": the scene is " + encoding + "; phiq reads UTF-8: convert it (iconv -f " +
                     (std::string(encoding).rfind("UTF-32", 0) == 0 ? "UTF-32" : "UTF-16") + " -t UTF-8)");
  const std::size_t nul = text.find('\0');
  if (nul == std::string::npos) return;
  const std::size_t line_start = text.rfind('\n', nul);
  const std::size_t line =
      1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(nul), '\n'));
  const std::size_t column = nul - (line_start == std::string::npos ? 0 : line_start + 1) + 1;
  throw SceneError(path + ":" + std::to_string(line) + ":" + std::to_string(column) +
                   ": the scene is not text (a NUL byte)");
}

// The caller's requests checked against the scene — a parameter of it, asked for once, a step 0 or positive and
// finite — as sensitivities without their models (their values the scene's, their steps the default for 0).
std::vector<OutputSensitivity> requested(const Scene& scene, const std::vector<SensitivityRequest>& requests,
                                         const std::string& source) {
  std::vector<OutputSensitivity> out;
  for (const SensitivityRequest& r : requests) {
    if (std::any_of(out.begin(), out.end(), [&](const OutputSensitivity& s) { return s.name == r.name; }))
      throw SceneError(source + ": parameter '" + r.name + "' is asked for twice");
    if (!(r.step >= 0.0) || !std::isfinite(r.step))
      throw SceneError(source + ": the step of '" + r.name + "' must be a positive finite number (0: the default)");
    const auto it = std::find_if(scene.parameters.begin(), scene.parameters.end(),
                                 [&](const auto& nv) { return nv.first == r.name; });
    if (it == scene.parameters.end()) {
      std::vector<std::string> names;
      for (const auto& nv : scene.parameters) names.push_back(nv.first);
      throw SceneError(source + ": '" + r.name + "' is not a parameter of " + scene.path +
                       detail::scene::parameters_note(names));
    }
    OutputSensitivity s;
    s.name = r.name, s.value = it->second, s.step = r.step > 0.0 ? r.step : default_sensitivity_step(it->second);
    out.push_back(std::move(s));
  }
  return out;
}

// The scene read again with other overrides: from the tree it was read from, so that the four models along a
// parameter cost four reads, not four parses of its text.
using ReadScene = std::function<Scene(const SceneOverrides&)>;

// sensitivity_along(), its models read by `read`.
OutputSensitivity along(const Scene& scene, const std::string& name, double value, double step,
                        const SceneOverrides& overrides, const ReadScene& read) {
  OutputSensitivity s;
  s.name = name, s.value = value, s.step = step > 0.0 ? step : default_sensitivity_step(value);
  auto read_at = [&](std::size_t k) {
    SceneOverrides moved = overrides;
    moved.sensitivity_models = false;
    moved.sensitivities.clear();  // (the models along p need no sensitivities of their own)
    moved.share_analysis_with = scene.model.get();
    moved.parameters_source.clear();
    const double at = value + detail::kShift[k] * s.step;
    bool replaced = false;
    for (auto& [n, v] : moved.parameters)
      if (n == name) v = at, replaced = true;
    if (!replaced) moved.parameters.emplace_back(name, at);
    try {
      Scene at_k = read(moved);
      // the masses, centres and loads at p + kh where p moves them, which the efforts' sensitivities difference
      // (effort_sensitivity.hpp); left null where they are the scene's own, so that no Q is differenced along a
      // parameter that reaches the constraints only
      const OutputEfforts& own = scene.sweep.efforts;
      const OutputEfforts& moved_efforts = at_k.sweep.efforts;
      if (moved_efforts.parts && !(own.parts && detail::same_inertia(*own.parts, *moved_efforts.parts)))
        s.parts_along[k] = moved_efforts.parts;
      if (moved_efforts.loads && !(own.loads && detail::same_loads(*own.loads, *moved_efforts.loads)))
        s.loads_along[k] = moved_efforts.loads;
      return std::shared_ptr<const Model>(std::move(at_k.model));
    } catch (const SceneError& e) {
      throw SceneError("with " + name + " = " + shortest(at) + " (the difference step " + shortest(s.step) + " from " +
                       shortest(value) + ") the scene cannot be read: " + e.what());
    }
  };
  // The models along p are the whole model again, and only what p reaches is read of them (complete_along()).
  detail::complete_along(*scene.model, s, overrides.keep_sensitivity_models, read_at,
                         [](const std::string& why) { throw SceneError(why); });
  return s;
}

// The models along each of `sensitivities` (the scene read again by `read` with `overrides`), refused naming
// `source`.
void build_models_along(const Scene& scene, std::vector<OutputSensitivity>& sensitivities,
                        const SceneOverrides& overrides, const std::string& source, const ReadScene& read) {
  for (OutputSensitivity& s : sensitivities) {
    try {
      s = along(scene, s.name, s.value, s.step, overrides, read);
    } catch (const SceneError& e) {
      throw SceneError(source + ": " + e.what());
    }
  }
}

// The scene's sensitivities: the caller's requests in place of its `output.sensitivities`, when it made any, and
// the models along each parameter when asked for.
void build_sensitivity_models(Scene& scene, const SceneOverrides& overrides, const ReadScene& read) {
  const bool requests = !overrides.sensitivities.empty();
  if (requests) scene.sweep.sensitivities = requested(scene, overrides.sensitivities, overrides.sensitivities_source);
  if (!overrides.sensitivity_models) return;
  build_models_along(scene, scene.sweep.sensitivities, overrides,
                     requests ? overrides.sensitivities_source : scene.path + ": output.sensitivities", read);
}

// The checks and the parse of parse_scene(), before the tree is read: what a ParsedScene does once.
YAML::Node parse_tree(const std::string& text, const std::string& path, const SceneLimits& limits) {
  if (text.size() > limits.max_file_bytes)
    throw SceneError(path + ": the scene is " + std::to_string(text.size() >> 20) + " MiB; the limit is " +
                     std::to_string(limits.max_file_bytes >> 20) + " MiB");
  refuse_non_utf8_encoding(text, path);
  try {
    std::istringstream in(text);
    YAML::Parser parser(in);
    ShapeGuard guard(path, limits);
    while (parser.HandleNextDocument(guard)) {
    }
  } catch (const YAML::Exception& e) {
    throw SceneError(yaml_error(path, e));
  }
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw SceneError(yaml_error(path, e));
  }
}

// The Scene of a parsed tree (parse_scene() after parse_tree()).
Scene read_tree(const YAML::Node& root, const std::string& text, const std::string& path, const SceneLimits& limits,
                const SceneOverrides& overrides) {
  detail::scene::SceneReader reader(path, limits);
  reader.overrides_ = &overrides;
  Scene scene = reader.read(root);
  scene.text = text;
  scene.overridden = overrides.parameters;
  // A predictor that needs derivatives the scene does not output would compute extra work silently: refuse.
  if (reader.predictor_given()) {
    const Predictor p = scene.sweep.predictor;
    if ((predictor_needs_accelerations(p) && !scene.sweep.accelerations) ||
        (predictor_needs_velocities(p) && !(scene.sweep.velocities || scene.sweep.accelerations)))
      throw SceneError(path + ": solver.predictor: '" + to_string(p) +
                       "' needs the derivatives it extrapolates with in the output (velocities / accelerations)");
  }
  build_sensitivity_models(scene, overrides,
                           [&](const SceneOverrides& o) { return read_tree(root, text, path, limits, o); });
  return scene;
}

// The scene's text: the file's, or the phiq scene an `.asmt`, URDF or MJCF file converts to (phiq/import_asmt.hpp,
// phiq/import_model.hpp).
std::string scene_text(const std::string& path, const SceneLimits& limits) {
  std::string text = detail::scene::read_scene_file(path, limits);
  switch (model_format(path)) {
    case ModelFormat::kAsmt:
      return import_asmt(text, path).yaml;
    case ModelFormat::kUrdf:
      return import_urdf(text, path).yaml;
    case ModelFormat::kMjcf:
      return import_mjcf(text, path).yaml;
    case ModelFormat::kSdf:
      return import_sdf(text, path).yaml;
    case ModelFormat::kScene:
      break;
  }
  return text;
}

}  // namespace

Scene parse_scene(const std::string& text, const std::string& path, const SceneLimits& limits,
                  const SceneOverrides& overrides) {
  return read_tree(parse_tree(text, path, limits), text, path, limits, overrides);
}

struct ParsedScene::Tree {
  std::string text, path;
  SceneLimits limits;
  YAML::Node root;
};

ParsedScene ParsedScene::load(const std::string& path, const SceneLimits& limits) {
  return ParsedScene(scene_text(path, limits), path, limits);
}

ParsedScene::ParsedScene(std::string text, std::string path, const SceneLimits& limits)
    : tree_(std::make_unique<Tree>()) {
  tree_->root = parse_tree(text, path, limits);
  tree_->text = std::move(text), tree_->path = std::move(path), tree_->limits = limits;
}

ParsedScene::ParsedScene(const ParsedScene& other) : ParsedScene(other.text(), other.path(), other.tree_->limits) {}
ParsedScene::ParsedScene(ParsedScene&&) noexcept = default;
ParsedScene::~ParsedScene() = default;

Scene ParsedScene::read(const SceneOverrides& overrides) {
  return read_tree(tree_->root, tree_->text, tree_->path, tree_->limits, overrides);
}
const std::string& ParsedScene::text() const { return tree_->text; }
const std::string& ParsedScene::path() const { return tree_->path; }

Scene parse_scene(const std::string& text, const std::string& path, const SceneLimits& limits) {
  return parse_scene(text, path, limits, SceneOverrides{});
}

OutputSensitivity sensitivity_along(const Scene& scene, const std::string& name, double value, double step,
                                    const SceneLimits& limits, const SceneOverrides& overrides) {
  const YAML::Node root = parse_tree(scene.text, scene.path, limits);  // parsed once for the four models
  return along(scene, name, value, step, overrides,
               [&](const SceneOverrides& o) { return read_tree(root, scene.text, scene.path, limits, o); });
}

std::vector<OutputSensitivity> sensitivities_of(const Scene& scene, const std::vector<SensitivityRequest>& requests,
                                                const std::string& source, const SceneLimits& limits) {
  SceneOverrides as_read;  // the scene read again as it was: the parameters its reader was given
  as_read.parameters = scene.overridden;
  std::vector<OutputSensitivity> out = requested(scene, requests, source);
  if (out.empty()) return out;
  const YAML::Node root = parse_tree(scene.text, scene.path, limits);  // parsed once for every model along them
  build_models_along(scene, out, as_read, source,
                     [&](const SceneOverrides& o) { return read_tree(root, scene.text, scene.path, limits, o); });
  return out;
}

Scene load_scene(const std::string& path, const SceneLimits& limits) {
  return load_scene(path, limits, SceneOverrides{});
}

Scene load_scene(const std::string& path, const SceneLimits& limits, const SceneOverrides& overrides) {
  return parse_scene(scene_text(path, limits), path, limits, overrides);
}

}  // namespace phiq
