// The helpers every phiq command shares (command_support.hpp).
#include "command_support.hpp"

#include <iostream>

#include "cli_support.hpp"

namespace phiq::tools {

int fail(const std::string& msg, int code) {
  std::cerr << "phiq: " << msg << "\n";
  return code;
}

std::optional<Scene> load_or_report(const std::string& path) {
  try {
    return phiq::load_scene(path);
  } catch (const phiq::SceneError& e) {
    fail(e.what(), 2);
    return std::nullopt;
  }
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
