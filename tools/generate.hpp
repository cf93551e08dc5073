// `phiq generate`: scalable scenes for tests and benchmarks (tools/README.md).
#pragma once

#include <cstdint>
#include <string>

namespace phiq::tools {

struct GenerateOptions {
  std::string kind;                  // nfourbar, scissor, grid, chain3d
  std::int64_t n = 10;               // size parameter (four-bars, stages, cells, spatial loops)
  std::int64_t steps = 1000;         // sweep intervals
  double from = 0.7853981633974483;  // driven range: π/4 ...
  double to = 2.356194490192345;     // ... to 3π/4 (radians)
  std::string coords = "natural";    // natural | reference-point
  double twist = 0.0;                // chain3d: phase between neighbouring cranks (rad); 0: the parallelogram row
  bool q = true, v = true, a = true; // outputs
};

// Writes the scene text for `o`. Throws std::invalid_argument naming the option for invalid values.
std::string generate_scene(const GenerateOptions& o);

}  // namespace phiq::tools
