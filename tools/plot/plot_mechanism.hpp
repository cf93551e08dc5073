// `phiq plot`'s drawing of the mechanism: its sketch (engine/include/phiq/mechanism_sketch.hpp) at a few rows, the
// ground hatched under fixed pivots and guides, revolute joints as circles, prismatic ones as blocks on their
// guides, link ends as dots, and the paths of the traced points. Planar scenes in x, y with ticks and units;
// spatial ones in an isometric view (x, y, z with z up) with the three axes drawn.
#pragma once

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

#include "phiq/mechanism_sketch.hpp"

namespace phiq::tools {

struct MechanismFrames {
  const Model* model = nullptr;
  const MechanismSketch* sketch = nullptr;
  bool spatial = false;
  std::vector<Eigen::VectorXd> q;  // q at each drawn row (what the sketch reads is set)
  std::vector<double> t;           // t of each drawn row
  // traced output points: name and position at every row (z = 0 in the plane)
  std::vector<std::pair<std::string, std::vector<std::array<double, 3>>>> traces;
};

// The panel, in the square at (x0, y0) of side `side` pixels.
std::string mechanism_panel(const MechanismFrames& m, double x0, double y0, double side);

}  // namespace phiq::tools
