// libFuzzer target: any byte string as a scene. The loader must either build a model or throw SceneError with a
// one-line message that starts with the file name; nothing else may escape (another exception, a crash, a hang, a
// sanitizer report). Scenes that load and are small are then swept for a few steps, so that the solver sees
// whatever the fuzzer makes (NaN-free but wild numbers, degenerate geometry): it must end with a status and, on
// failure, a message.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "phiq/phiq.hpp"

namespace {
void check_line(const std::string& m, const char* what) {
  if (m.empty() || m.find('\n') != std::string::npos) {
    std::fprintf(stderr, "fuzz_scene: %s is not one line: [%s]\n", what, m.c_str());
    std::abort();
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  phiq::Scene scene;
  // Families let a few bytes ask for millions of entities (the scale issue's 10^6 models): legitimate, but not
  // what a fuzzer iteration should build. Above this the loader refuses with its one-line limit error.
  phiq::SceneLimits limits;
  limits.max_family_instances = 20000;
  try {
    scene = phiq::parse_scene(text, "fuzz.yaml", limits);
  } catch (const phiq::SceneError& e) {
    const std::string m = e.what();
    check_line(m, "scene error");
    if (m.rfind("fuzz.yaml", 0) != 0) {
      std::fprintf(stderr, "fuzz_scene: error does not name the file: [%s]\n", m.c_str());
      std::abort();
    }
    return 0;
  }
  const phiq::Model& m = *scene.model;
  if (m.num_coordinates() > 200) return 0;
  phiq::SweepOptions o = scene.sweep;
  o.steps = std::min<phiq::Index>(o.steps, 3);
  o.newton.max_iterations = std::min(o.newton.max_iterations, 8);
  o.assembly.max_iterations = std::min(o.assembly.max_iterations, 20);
  o.max_subdivisions = std::min(o.max_subdivisions, 2);
  phiq::Workspace ws(m);
  phiq::SweepSummary sum;
  (void)phiq::run_sweep(m, o, ws, nullptr, &sum);  // the status is read from the summary below
  if (sum.status != phiq::SolveStatus::kSuccess) check_line(sum.message, "sweep failure message");
  return 0;
}
