// The notes' four-bar (models/seed/fourbar_*.yaml) with three massive links, in each of its four formulations
// (relative, natural, reference_point, mixed): what the inverse dynamics and applied loads tests load.
#pragma once

#include <string>

#include "test_support.hpp"

namespace phiq::test {

// The `parts` entries of the four-bar in formulation `form`: mass properties of the three links (kg, kg·m² about
// the centre), the centre at each link's middle, each part named as its link (crank, coupler, rocker).
inline std::string fourbar_parts(const std::string& form) {
  const std::string crank = "mass: 1.0, inertia: 1.0*L2*L2/12";
  const std::string coupler = "mass: 2.0, inertia: 2.0*L3*L3/12";
  const std::string rocker = "mass: 1.5, inertia: 1.5*L4*L4/12";
  auto on_frame = [](const std::string& name, const std::string& frame, const std::string& half,
                     const std::string& mass) {
    return "  " + name + ": {frame: " + frame + ", center_of_mass: [" + half + ", 0], " + mass + "}\n";
  };
  auto on_body = [](const std::string& name, const std::string& mass) {
    return "  " + name + ": {center_of_mass: [0, 0], " + mass + "}\n";
  };
  if (form == "relative")
    return on_frame("crank", "{at: [0, 0], angle: psi2}", "L2/2", crank) +
           on_frame("coupler", "{at: [L2*cos(psi2), L2*sin(psi2)], angle: psi2 + psi3}", "L3/2", coupler) +
           on_frame("rocker",  // the loop's third link runs from B to C
                    "{at: [L2*cos(psi2) + L3*cos(psi2 + psi3), L2*sin(psi2) + L3*sin(psi2 + psi3)], "
                    "angle: psi2 + psi3 + psi4}",
                    "L4/2", rocker);
  if (form == "natural")
    return on_frame("crank", "{origin: O, x: A}", "L2/2", crank) +
           on_frame("coupler", "{origin: A, x: B}", "L3/2", coupler) +
           on_frame("rocker", "{origin: C, x: B}", "L4/2", rocker);
  if (form == "reference_point")
    return on_body("crank", crank) + on_body("coupler", coupler) + on_body("rocker", rocker);
  return on_frame("crank", "{origin: O, x: A}", "L2/2", crank) + on_body("coupler", coupler) +
         on_frame("rocker", "{origin: C, x: B}", "L4/2", rocker);  // mixed
}

}  // namespace phiq::test
