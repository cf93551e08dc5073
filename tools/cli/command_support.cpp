// The helpers every phiq command shares (command_support.hpp).
#include "command_support.hpp"

#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <optional>

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>

#include "phiq/text.hpp"

#include "cli_support.hpp"
#include "tolerance_input.hpp"  // parse_named_value: NAME=VALUE as --sd reads it

namespace phiq::tools {

int fail(const std::string& msg, int code) {
  std::cerr << "phiq: " << printable(msg) << "\n";
  settle_interrupts(code);  // the line said why it stops: a signal while it leaves adds no second one
  return code;
}

std::string printable(const std::string& text) {
  const std::string line = phiq::single_line(text);
  std::string out;
  out.reserve(line.size());
  for (std::size_t i = 0; i < line.size();) {
    const auto b = static_cast<unsigned char>(line[i]);
    const int len = b < 0x80 ? 1 : (b >> 5) == 0x6 ? 2 : (b >> 4) == 0xE ? 3 : (b >> 3) == 0x1E ? 4 : 0;
    bool valid = len > 0 && i + len <= line.size();
    unsigned cp = len == 1 ? b : b & (0x7Fu >> len);
    for (int k = 1; valid && k < len; ++k) {
      const auto c = static_cast<unsigned char>(line[i + k]);
      valid = (c >> 6) == 0x2;
      cp = (cp << 6) | (c & 0x3Fu);
    }
    // overlong forms, surrogates and code points past U+10FFFF are not UTF-8 either
    if (valid && ((len == 2 && cp < 0x80) || (len == 3 && cp < 0x800) ||
                  (len == 4 && (cp < 0x10000 || cp > 0x10FFFF)) || (cp >= 0xD800 && cp <= 0xDFFF)))
      valid = false;
    if (valid) {
      out.append(line, i, static_cast<std::size_t>(len));
      i += static_cast<std::size_t>(len);
    } else {
      const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[b >> 4];
      out += hex[b & 15];
      ++i;
    }
  }
  return out;
}

std::string json_text(const nlohmann::ordered_json& value, int indent) {
  return value.dump(indent, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

namespace {
// The text of the scene piped to standard input, named kStdinScene in its errors. Read up to one byte past the size
// limit, so that parse_scene() refuses an oversized one as load_scene() does, without reading it all. A terminal is
// refused as load_scene() refuses one given as /dev/stdin: nobody types a scene.
std::string load_stdin_text() {
  if (::isatty(STDIN_FILENO)) throw SceneError(std::string(kStdinScene) + ": is a terminal, not a scene (pipe one in)");
  const std::size_t limit = SceneLimits{}.max_file_bytes;
  std::string text;
  char buf[1 << 16];
  for (std::size_t n; text.size() <= limit && (n = std::fread(buf, 1, sizeof buf, stdin)) > 0;) text.append(buf, n);
  if (std::ferror(stdin)) throw SceneError(std::string(kStdinScene) + ": cannot read: " + std::strerror(errno));
  return text;
}
}  // namespace

SceneOverrides parameter_settings(const std::vector<std::string>& sets) {
  SceneOverrides o;
  o.parameters_source = "--set";
  for (const std::string& text : sets) {
    auto setting = tolerance::parse_named_value("--set", text);
    for (const auto& [name, value] : o.parameters)
      if (name == setting.first) throw Error("--set " + text + ": '" + name + "' is already set");
    o.parameters.push_back(std::move(setting));
  }
  return o;
}

void add_set_option(CLI::App* command, std::vector<std::string>* sets) {
  command->add_option("--set", *sets, "NAME=VALUE: the scene parameter NAME takes this value (repeat per parameter)")
      ->allow_extra_args(false);  // one NAME=VALUE an occurrence: the scene after it stays the scene
}

std::vector<SensitivityRequest> sensitivity_requests(const std::vector<std::string>& args) {
  std::vector<SensitivityRequest> out;
  for (const std::string& text : args) {
    if (text.find('=') == std::string::npos) {
      out.push_back({text, 0.0});
    } else {
      auto [name, step] = tolerance::parse_named_value("--sensitivity", text);
      if (step == 0.0)  // (0 is SensitivityRequest's "the default": NAME alone asks for it; negative: refused there)
        throw Error("--sensitivity " + text + ": the step must be positive (NAME alone: the default step)");
      out.push_back({std::move(name), step});
    }
  }
  return out;
}

void add_sensitivity_option(CLI::App* command, std::vector<std::string>* args) {
  command
      ->add_option("--sensitivity", *args,
                   "NAME or NAME=STEP: deliver the sensitivities to the scene parameter NAME (columns x.d_NAME, "
                   "x.v.d_NAME, x.a.d_NAME; STEP the difference step of its data's rates), instead of the "
                   "scene's output.sensitivities (repeat per parameter)")
      ->allow_extra_args(false);
}

// An error of the scene an import of `path` wrote ("PATH:LINE:COL: field: why", at a line of a text the user has not
// seen) as one the user can place; any other message unchanged.
static std::string converted_scene_error(const std::string& path, const std::string& what) {
  const std::string prefix = path + ":";
  if (what.rfind(prefix, 0) != 0 || what.size() == prefix.size() ||
      !std::isdigit(static_cast<unsigned char>(what[prefix.size()])))
    return what;
  return path + ": the scene it converts to (phiq convert) is refused at " + what.substr(prefix.size());
}

// (command_support.hpp)
std::optional<std::string> import_or_report(const std::string& path, const ImportOptions& options) {
  try {
    std::string yaml;
    std::vector<std::string> skipped;
    std::string gravity;  // a robot description's, stated with --forces (an .asmt scene's comment states its own)
    if (model_format(path) == ModelFormat::kAsmt) {
      AsmtImport imported = import_asmt_file(path, options);
      yaml = std::move(imported.yaml), skipped = std::move(imported.skipped);
    } else {
      ModelImport imported = import_model_file(path, options);
      yaml = std::move(imported.yaml), skipped = std::move(imported.skipped), gravity = std::move(imported.gravity);
    }
    // the scene phiq itself would refuse (an MJCF geom of negative size) is refused here, before the list of what
    // was left out, so that the refusal is the one line
    try {
      (void)phiq::parse_scene(yaml, path);
    } catch (const SceneError& e) {
      fail(converted_scene_error(path, e.what()), 2);
      return std::nullopt;
    }
    for (const std::string& why : skipped) std::fprintf(stderr, "phiq: not mapped: %s\n", printable(why).c_str());
    if (options.forces && !gravity.empty()) std::fprintf(stderr, "phiq: gravity %s\n", printable(gravity).c_str());
    return yaml;
  } catch (const SceneError& e) {
    fail(e.what(), 2);
  }
  return std::nullopt;
}

void add_import_options(CLI::App* command, std::vector<std::string>* drives, std::vector<double>* time,
                        std::string* gravity, ImportOptions* outputs) {
  command->add_option(
      "--drive", *drives,
      "JOINT=EXPR (URDF, MJCF, SDF; repeatable): drive the joint's angle (rad, 0 at the file's pose) or "
      "travel (m) by an expression of t");
  command
      ->add_option("--time", *time, "START END STEPS (URDF, MJCF, SDF): the time grid (default 0 0 0: the file's pose)")
      ->expected(3);
  command->add_flag("--rates", outputs->rates,
                    "(.asmt, URDF, MJCF, SDF) write velocities and accelerations, as a scene's `output` asks");
  command->add_flag("--forces", outputs->forces,
                    "(.asmt, URDF, MJCF, SDF) write every driver's effort and every joint's reaction");
  command->add_option("--gravity", *gravity,
                      "X,Y,Z (.asmt, URDF, MJCF, SDF): the gravity of the efforts and reactions instead of the "
                      "file's or the format's default (m/s²; an .asmt file's length unit per s²; 0,0,0: none)");
}

namespace {

// "X,Y,Z" as three finite numbers; nothing when it is not.
std::optional<std::array<double, 3>> gravity_components(const std::string& text) {
  std::array<double, 3> g{};
  std::size_t from = 0;
  for (std::size_t k = 0; k < 3; ++k) {
    const std::size_t comma = k < 2 ? text.find(',', from) : text.size();
    if (comma == std::string::npos) return std::nullopt;
    const std::string part = text.substr(from, comma - from);
    char* end = nullptr;
    g[k] = std::strtod(part.c_str(), &end);
    if (part.empty() || end != part.c_str() + part.size() || !std::isfinite(g[k])) return std::nullopt;
    from = comma + 1;
  }
  return g;
}

}  // namespace

std::optional<std::string> import_options(const std::string& command, const std::string& path,
                                          const std::vector<std::string>& drives, const std::vector<double>& time,
                                          const std::string& gravity, ImportOptions* options) {
  for (const std::string& d : drives) {
    const std::size_t eq = d.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == d.size())
      return command + ": --drive " + d + ": not JOINT=EXPR";
    options->drives.emplace_back(d.substr(0, eq), d.substr(eq + 1));
  }
  if (!time.empty()) {
    const double steps = time[2];
    if (!(steps >= 0) || steps != std::floor(steps) || steps > 1e9)
      return command + ": --time: STEPS must be a whole number from 0 to 1e9";
    options->t_start = time[0], options->t_end = time[1], options->steps = static_cast<int>(steps);
  }
  const ModelFormat format = path == "-" ? ModelFormat::kScene : model_format(path);
  if (!gravity.empty()) {
    if (format == ModelFormat::kScene)
      return command + ": --gravity is for .asmt, URDF, MJCF and SDF files: a scene's `loads.gravity` says it";
    options->gravity = gravity_components(gravity);
    if (!options->gravity)
      return command + ": --gravity " + gravity + ": not X,Y,Z (three finite numbers, m/s²; 0,0,0: none)";
  }
  if ((options->rates || options->forces) && format == ModelFormat::kScene)
    return command + ": " + (options->rates ? "--rates" : "--forces") +
           " is for .asmt, URDF, MJCF and SDF files: a scene's `output` says what it writes";
  if (drives.empty() && time.empty()) return std::nullopt;
  if (format == ModelFormat::kAsmt)
    return command + ": --drive and --time are for URDF, MJCF and SDF: an .asmt file has its motions";
  if (format == ModelFormat::kScene)
    return command + ": --drive and --time are for URDF, MJCF and SDF: a scene has its drivers and time";
  return std::nullopt;
}

std::optional<Scene> load_or_report(const std::string& path, const std::vector<std::string>& sets,
                                    const std::vector<std::string>& sensitivity_args,
                                    const ImportOptions& import_options_given) {
  try {
    SceneOverrides o = parameter_settings(sets);
    o.sensitivities = sensitivity_requests(sensitivity_args), o.sensitivities_source = "--sensitivity";
    if (path == "-") return phiq::parse_scene(load_stdin_text(), kStdinScene, SceneLimits{}, o);
    if (model_format(path) != ModelFormat::kScene) {  // converted here rather than in load_scene(), to list what
      const std::optional<std::string> imported = import_or_report(path, import_options_given);  // it leaves out
      if (!imported) return std::nullopt;
      return phiq::parse_scene(*imported, path, SceneLimits{}, o);
    }
    return phiq::load_scene(path, SceneLimits{}, o);
  } catch (const phiq::SceneError& e) {
    fail(e.what(), 2);
  } catch (const phiq::Error& e) {  // a --set that is not NAME=VALUE, a --sensitivity STEP that is not a number
    fail(e.what(), 2);
  }
  return std::nullopt;
}

AssemblyOptions assembly_options(const phiq::Scene& scene) { return phiq::assembly_options(scene.sweep.assembly); }

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

std::optional<std::string> make_square(const Scene& scene, SquareScene* square) {
  const phiq::SolveStatus st = phiq::prepare_scene(*scene.model, scene.sweep.t_begin, scene.sweep.assembly, square);
  if (st == phiq::SolveStatus::kSuccess) return std::nullopt;
  return "t = " + phiq::format_time(scene.sweep.t_begin) + ": " + square->assembly.message;
}

int with_stdout_checked(int status) {
  if (status == 0 || status == 1)
    if (const auto bad = stdout_error()) return fail(*bad, 3);
  return status;
}

}  // namespace phiq::tools
