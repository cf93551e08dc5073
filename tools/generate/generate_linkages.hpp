// `phiq generate scissor` and `phiq generate grid` (generate_linkages.cpp) and `phiq generate chain3d`
// (generate_chain3d.cpp); formats in tools/README.md.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "generate.hpp"

namespace phiq::tools {

// A scissor lift of o.n stages, 1 dof, driven by the bars' angle to the horizontal. Throws std::invalid_argument
// for a bad --coords or a driven range that reaches a singular position (0 flat, π/2 vertical).
std::string scissor_scene(const GenerateOptions& o);

// A lattice of exactly o.n parallelogram cells in rows, one dof (and one driver) per row. Throws
// std::invalid_argument for a bad --coords or a driven range that reaches a singular position (0 or π: flat).
std::string grid_scene(const GenerateOptions& o);

// A row of o.n spatial loops (unit cranks on hinges of one axis, couplers with ball joints), 1 dof, driven by crank
// 0's angle; with o.twist ≠ 0 neighbouring cranks differ by that phase about one common hinge line. Throws
// std::invalid_argument for a bad --coords, a parallelogram row driven through a singular position (a multiple of
// π) or a twist with |sin twist| < 0.01.
std::string chain3d_scene(const GenerateOptions& o);

// The entries the families of these scenes make, as the loader counts them (family_entries(), generate.hpp).
std::uint64_t scissor_family_entries(const GenerateOptions& o);
std::uint64_t grid_family_entries(const GenerateOptions& o);
std::uint64_t chain3d_family_entries(const GenerateOptions& o);

// The driven range used when --from / --to are not given, for the kinds whose default differs from
// GenerateOptions' (π/4 → 3π/4): scissor 0.3 → 1.2 rad. Empty for the other kinds.
struct DrivenRange {
  double from, to;
};
std::optional<DrivenRange> kind_default_range(const std::string& kind);

}  // namespace phiq::tools
