// How many real assembly modes a scene has at one time and which one a position is in, as `phiq check` and the run
// summary state it (tools/README.md, "Assembly modes in check and the run summary"). The count is a homotopy solve
// (phiq/modes.hpp) whose cost grows with the scene; these reports run it only within a bound (kModeCountMaxCoordinates,
// kModeCountMaxPaths) and say so when they skip it. `phiq modes` itself has no such bound.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "phiq/phiq.hpp"

namespace phiq::tools {

// Scenes with more coordinates than this are not counted: recovering their rows as polynomials evaluates the whole
// model for every sample of every row, quadratic in the scene's size.
constexpr Index kModeCountMaxCoordinates = 40;
// Nor are scenes whose homotopy has more paths than this: those of the start system the solve takes (degrees lowered,
// the fewest paths; the fit is done, nothing is tracked).
constexpr std::int64_t kModeCountMaxPaths = 64;

struct ModeCount {
  enum class State {
    kCounted,        // `found` holds the modes
    kNotPolynomial,  // a constraint is not polynomial: `reason` names it
    kSkipped,        // above the bound: `reason` says which
    kNotAvailable,   // the drivers leave a freedom, or the solve failed: `reason` says why
  };
  State state = State::kSkipped;
  std::string reason;    // one line, when not counted
  double time = 0.0;     // where the drivers were evaluated
  AssemblyModes found;   // the modes, when counted
  bool located = false;  // a position was given and located among the modes
  ModeLocation where;    // its mode, when located
};

// The modes of `scene` at time t, within the bound; `position` (may be null: the position did not assemble) located
// among them. Never throws for the scene's sake: a failure is a state.
ModeCount count_modes(const Scene& scene, double t, const Eigen::VectorXd* position, int threads);

// The same report for modes already found (`phiq run --mode K` found them for its start).
ModeCount counted_modes(const Scene& scene, double t, AssemblyModes found, const Eigen::VectorXd* position);

// One line, without a label: "2 real at t = 0 (4 paths); the placement assembled into mode 1 (`phiq run --mode
// 1`), 3e-16 away; the next nearest, mode 2, is 1.43 away (…)", or "not available: constraint 'cam' is not …".
// `subject`: what the position is ("the placement", "the run's first row").
std::string mode_count_text(const ModeCount& count, const std::string& subject);

// The JSON object of check --json and the run summary (tools/README.md).
nlohmann::ordered_json mode_count_json(const ModeCount& count);

}  // namespace phiq::tools
