// phiq — command line front end. See tools/README.md.
//
// Exit status: 0 success; 1 the mechanism could not be solved (the message names step, time and constraints);
// 2 bad input (scene or command line); 3 an output file could not be written; 130 interrupted.
#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "phiq/phiq.hpp"

namespace {

std::atomic<bool> g_interrupted{false};
extern "C" void on_sigint(int) { g_interrupted = true; }

int fail(const std::string& msg, int code) {
  std::cerr << "phiq: " << msg << "\n";
  return code;
}

std::string sci(double v) {
  std::ostringstream s;
  s.precision(3);
  s << std::scientific << v;
  return s.str();
}

int cmd_run(const std::string& scene_path, const std::string& out_path, bool quiet) {
  phiq::Scene scene;
  try {
    scene = phiq::load_scene(scene_path);
  } catch (const phiq::SceneError& e) {
    return fail(e.what(), 2);
  }
  const phiq::Model& model = *scene.model;
  phiq::Workspace ws(model);
  phiq::CsvFormat csv(model, scene.output_coordinates, scene.sweep.velocities, scene.sweep.accelerations);

  std::unique_ptr<phiq::AtomicOutputFile> file;
  std::string buffer = csv.header();
  try {
    if (!out_path.empty()) file = std::make_unique<phiq::AtomicOutputFile>(out_path);
  } catch (const phiq::Error& e) {
    return fail(e.what(), 3);
  }

  std::signal(SIGINT, on_sigint);
  phiq::SweepSummary summary;
  try {
    phiq::run_sweep(model, scene.sweep, ws, [&](const phiq::StepView& step) {
      csv.append_row(step, buffer);
      if (file && buffer.size() > (1u << 20)) file->write(buffer), buffer.clear();
      return !g_interrupted.load();
    }, &summary);
  } catch (const phiq::Error& e) {
    return fail(scene_path + ": " + e.what(), 3);
  }
  std::signal(SIGINT, SIG_DFL);

  if (summary.status == phiq::SolveStatus::kCancelled) return fail(scene_path + ": interrupted; no output written", 130);
  if (summary.status != phiq::SolveStatus::kSuccess)
    return fail(scene_path + ": " + summary.message + (out_path.empty() ? "" : "; no output written"), 1);
  try {
    if (file) {
      file->write(buffer);
      file->commit();
    } else {
      std::fwrite(buffer.data(), 1, buffer.size(), stdout);
      std::fflush(stdout);
    }
  } catch (const phiq::Error& e) {
    return fail(e.what(), 3);
  }
  if (!quiet) {
    for (const auto& w : summary.warnings)
      std::cerr << "phiq: " << scene_path << ": warning: t = " << w.t << ": " << w.kind << ": " << w.message << "\n";
    std::cerr << "phiq: " << scene_path << ": " << summary.BriefReport();
    if (summary.min_rcond > 0) std::cerr << ", min rcond " << sci(summary.min_rcond) << " at t = " << summary.min_rcond_time;
    if (file) std::cerr << "; wrote " << out_path;
    std::cerr << "\n";
  }
  return 0;
}

int cmd_check(const std::string& scene_path) {
  phiq::Scene scene;
  try {
    scene = phiq::load_scene(scene_path);
  } catch (const phiq::SceneError& e) {
    return fail(e.what(), 2);
  }
  const phiq::Model& model = *scene.model;
  int drivers = 0;
  for (const auto& c : model.constraints()) drivers += c.depends_on_time ? c.rows : 0;
  std::cout << "scene         " << scene_path << (scene.name.empty() ? "" : " (" + scene.name + ")") << "\n"
            << "coordinates   " << model.num_coordinates() << "\n"
            << "equations     " << model.num_equations() << " (" << model.num_equations() - drivers
            << " kinematic, " << drivers << " rheonomic)\n"
            << "constraints   " << model.constraints().size() << "\n"
            << "jacobian      " << model.num_equations() << " x " << model.num_coordinates() << ", "
            << model.jacobian_pattern().nnz() << " non-zeros\n"
            << "length scale  " << model.length_scale() << " m\n"
            << "linear solver " << phiq::to_string(model.linear_solver()) << "\n";
  phiq::Workspace ws(model);
  phiq::PositionSummary ps;
  const double t0 = scene.sweep.t_begin;
  if (t0 < model.time_domain_begin() || t0 > model.time_domain_end()) {
    std::cout << "assembly      not attempted: driver '" << model.time_domain_limiter() << "' is not defined at t = "
              << t0 << "\n";
    return 1;
  }
  phiq::solve_position(model, t0, scene.sweep.assembly, ws, &ps);
  std::cout << "assembly      " << phiq::to_string(ps.status) << " at t = " << t0 << " in " << ps.iterations
            << " iterations, scaled residual " << sci(ps.residual) << " (tolerance "
            << sci(scene.sweep.assembly.tolerance) << ")\n";
  if (ps.status != phiq::SolveStatus::kSuccess) {
    std::cout << "diagnosis     " << ps.message << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"phiq: sparse, large-scale multibody kinematics"};
  app.set_version_flag("--version", std::string("phiq ") + phiq::kVersion);
  app.require_subcommand(1);

  std::string scene_path, out_path;
  bool quiet = false;
  CLI::App* run = app.add_subcommand("run", "Solve position, velocity and acceleration over the scene's time sweep");
  run->add_option("scene", scene_path, "Scene file (YAML)")->required();
  run->add_option("-o,--output", out_path, "CSV file to write (default: standard output)");
  run->add_flag("-q,--quiet", quiet, "Do not print the run summary on standard error");

  std::string check_path;
  CLI::App* check = app.add_subcommand("check", "Count coordinates and equations and try the initial assembly");
  check->add_option("scene", check_path, "Scene file (YAML)")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return e.get_exit_code() == 0 ? app.exit(e) : (app.exit(e), 2);
  }
  try {
    if (*run) return cmd_run(scene_path, out_path, quiet);
    if (*check) return cmd_check(check_path);
  } catch (const std::exception& e) {
    return fail(std::string("internal error: ") + e.what(), 4);
  }
  return 2;
}
