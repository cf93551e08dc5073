// The assembly-mode count of `phiq check` and the run summary (mode_count.hpp).
#include "mode_count.hpp"

#include <cmath>

namespace phiq::tools {

namespace {

// The norm mode_distance() measures in, as the reports name it.
constexpr const char* kNorm =
    "max over coordinates of |dq| / scale: lengths over the length scale, angles in rad modulo 2 pi";

// The state and reason of a solve that did not count (find_assembly_modes()'s status and message).
void refused(const AssemblyModes& found, ModeCount& out) {
  const ModesSummary& s = found.summary;
  out.reason = s.message;
  switch (s.status) {
    case ModesStatus::kNotPolynomial:
      out.state = ModeCount::State::kNotPolynomial;
      break;
    case ModesStatus::kTooManyPaths: {
      out.state = ModeCount::State::kSkipped;
      // the paths the solve would take (degrees lowered, the start system with the fewest), not the total degree;
      // where the block solve gave up first (its paths past the bound, or a block not safe), why, and that these
      // are the whole system's paths: `phiq modes`, unbounded, may take the blocks' fewer
      const std::string paths = std::to_string(s.paths) + " paths, above " + std::to_string(kModeCountMaxPaths);
      const std::string prefix = "the block solve was not safe: ";
      std::string gave_up = s.method_note;
      if (gave_up.rfind(prefix, 0) == 0) gave_up = gave_up.substr(prefix.size());
      out.reason = gave_up.empty() ? "not counted here: " + paths + " (phiq modes counts them)"
                                   : "not counted here: the block solve gave up at " + gave_up +
                                         "; the whole system takes " + paths + " (phiq modes counts them)";
      break;
    }
    default:
      out.state = ModeCount::State::kNotAvailable;
  }
}

}  // namespace

ModeCount counted_modes(const Scene& scene, double t, AssemblyModes found, const Eigen::VectorXd* position) {
  ModeCount out;
  out.time = t;
  if (found.summary.status != ModesStatus::kSuccess) {
    refused(found, out);
    return out;
  }
  out.state = ModeCount::State::kCounted;
  out.found = std::move(found);
  if (position) {
    out.located = true;
    out.where = locate_mode(*scene.model, *position, out.found.modes);
  }
  return out;
}

ModeCount count_modes(const Scene& scene, double t, const Eigen::VectorXd* position, int threads) {
  ModeCount out;
  out.time = t;
  const Model& model = *scene.model;
  if (model.num_coordinates() > kModeCountMaxCoordinates) {
    out.reason = "not counted here: " + std::to_string(model.num_coordinates()) + " coordinates, above " +
                 std::to_string(kModeCountMaxCoordinates) + " (phiq modes counts them)";
    return out;
  }
  ModesOptions options;
  options.time = t;
  options.threads = threads;
  options.max_paths = kModeCountMaxPaths;
  try {
    return counted_modes(scene, t, find_assembly_modes(model, options), position);
  } catch (const Error& e) {
    out.state = ModeCount::State::kNotAvailable;
    out.reason = e.what();
    return out;
  }
}

std::string mode_count_text(const ModeCount& c, const std::string& subject) {
  switch (c.state) {
    case ModeCount::State::kCounted:
      break;
    case ModeCount::State::kNotPolynomial:
    case ModeCount::State::kNotAvailable:
      return "not available: " + c.reason;
    case ModeCount::State::kSkipped:
      return c.reason;
  }
  const AssemblyModes& f = c.found;
  int singular = 0;
  for (const AssemblyMode& m : f.modes) singular += m.singular ? 1 : 0;
  std::string s = std::to_string(f.modes.size()) + " real at t = " + format_time(c.time) + " (" +
                  std::to_string(f.summary.paths) + (f.summary.paths == 1 ? " path" : " paths") +
                  (f.summary.method == ModesMethod::kBlocks ? ", block by block" : "") +
                  (singular ? ", " + std::to_string(singular) + " of the modes singular" : std::string()) + ")";
  if (!c.located) return s + "; " + subject + " did not assemble";
  const ModeLocation& w = c.where;
  if (w.mode < 0) return s + "; " + subject + " is in none";
  s += "; " + subject + " is mode " + std::to_string(w.mode + 1) + " (phiq run --mode " + std::to_string(w.mode + 1) +
       "), " + significant(w.distance, 4) + " away";
  if (w.next >= 0)
    s += "; the next nearest, mode " + std::to_string(w.next + 1) + ", is " + significant(w.next_distance, 4) +
         " away (" + kNorm + ")";
  return s;
}

nlohmann::ordered_json mode_count_json(const ModeCount& c) {
  nlohmann::ordered_json j;
  const bool counted = c.state == ModeCount::State::kCounted;
  j["status"] = counted                                       ? "counted"
                : c.state == ModeCount::State::kNotPolynomial ? "not polynomial"
                : c.state == ModeCount::State::kSkipped       ? "skipped"
                                                              : "not available";
  j["message"] = c.reason;
  j["time"] = c.time;
  auto or_null = [&](bool known, auto v) { return known ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); };
  int singular = 0;
  for (const AssemblyMode& m : c.found.modes) singular += m.singular ? 1 : 0;
  j["real"] = or_null(counted, c.found.modes.size());
  j["singular"] = or_null(counted, singular);
  j["paths"] = or_null(counted, c.found.summary.paths);
  j["method"] = or_null(counted, modes_method_name(c.found.summary.method));
  const ModeLocation& w = c.where;
  const bool in_mode = counted && c.located && w.mode >= 0, has_next = in_mode && w.next >= 0;
  j["assembled"] = or_null(counted, c.located);
  j["mode"] = or_null(in_mode, w.mode + 1);
  j["distance"] = or_null(in_mode, w.distance);
  j["next_mode"] = or_null(has_next, w.next + 1);
  j["next_distance"] = or_null(has_next, w.next_distance);
  j["norm"] = kNorm;
  return j;
}

}  // namespace phiq::tools
