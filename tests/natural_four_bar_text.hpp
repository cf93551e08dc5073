// The natural four-bar's scene text shared by its reactions' tests (test_natural_reactions.cpp,
// test_natural_reaction_refusals.cpp): the seed scene with a time span of its own, and the links' parts.
#pragma once

#include <sstream>
#include <string>

#include "test_support.hpp"

namespace phiq {

inline std::string natural_reactions_scene(const std::string& rel) {
  return test::model_file_text(rel, "time:") + "time: {start: 0, end: 2*pi, steps: 40}\n";
}

// Mass properties of the three links (bars with their centres at mid-length): crank, coupler, rocker.
inline constexpr double kNaturalMass[3] = {1.0, 2.0, 1.5}, kNaturalLength[3] = {0.4, 1.2, 1.0};

inline std::string natural_reactions_part(const char* name, int k, double centre, const std::string& frame) {
  std::ostringstream s;
  s << "  " << name << ": {" << frame << "mass: " << kNaturalMass[k] << ", center_of_mass: [" << centre
    << ", 0], inertia: " << kNaturalMass[k] * kNaturalLength[k] * kNaturalLength[k] / 12 << "}\n";
  return s.str();
}

}  // namespace phiq
