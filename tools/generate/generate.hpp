// `phiq generate`: scalable scenes for tests and benchmarks (tools/README.md).
#pragma once

#include <cstdint>
#include <string>

namespace phiq::tools {

struct GenerateOptions {
  std::string kind;                   // nfourbar, scissor, grid, chain3d
  std::int64_t n = 10;                // size parameter (four-bars, stages, cells, spatial loops)
  std::int64_t steps = 1000;          // sweep intervals
  double from = 0.7853981633974483;   // driven range: π/4 ...
  double to = 2.356194490192345;      // ... to 3π/4 (radians)
  std::string coords = "natural";     // natural | reference-point
  double twist = 0.0;                 // chain3d: phase between neighbouring cranks (rad); 0: the parallelogram row
  bool q = true, v = true, a = true;  // outputs
};

// Writes the scene text for `o`. Throws std::invalid_argument naming the option for invalid values, and for an N
// or a step count whose scene the loader would refuse (max_n(), kMaxSteps).
std::string generate_scene(const GenerateOptions& o);

// The entries (coordinates, points, bodies, constraints, drivers, and nested families) that the indexed families of
// the scene of o.kind, o.coords and o.n make, counted as the loader counts them against
// SceneLimits::max_family_instances; o.n from 1 to gen::kMaxN (generate_common.hpp).
std::uint64_t family_entries(const GenerateOptions& o);

// The largest N whose scene of o.kind in o.coords the loader accepts: its families within
// SceneLimits::max_family_instances (nfourbar natural 9 999 999, scissor natural 3 333 333, ...). o.n is ignored.
std::int64_t max_n(const GenerateOptions& o);

// The largest --steps a scene may have (the loader's limit of time.steps).
constexpr std::int64_t kMaxSteps = 1'000'000'000;

}  // namespace phiq::tools
