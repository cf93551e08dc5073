// What `phiq animate SCENE RESULT -o OUT.html` plays: the points of the scene's sketch (mechanism_sketch.hpp: the
// ends of its lines and its joints, each once) at a subset of the result's rows, their velocities from the
// result's q̇ columns when it has them, and the paths of the traced output points, as the JSON that the viewer's
// scripts read (tools/animate/viewer/viewer.js documents its fields). Positions and velocities are stored as
// 16-bit integers over the drawing's extent (base64), and rows are dropped evenly until the frames fit a byte
// budget: a 10⁴-loop chain stays a file of a few MB and the page interpolates between the rows it keeps.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "phiq/csv_compare.hpp"
#include "phiq/mechanism_sketch.hpp"
#include "phiq/scene.hpp"
#include "plot_mechanism.hpp"

namespace phiq::tools {

struct ViewerMotion {
  nlohmann::json data;            // the viewer's input (viewer.js)
  std::vector<std::size_t> rows;  // the result's rows kept as frames, first and last included
  MechanismFrames frames;         // q at the kept rows and the traces: the planar drawing's box (plot_mechanism.hpp)
};

// Bytes of frame data (positions and velocities, base64) the page holds at most by default.
constexpr std::size_t kFrameBudget = std::size_t{8} << 20;

// The motion of `table`, the result of `scene` read from `result`, drawn with `sketch` (which must outlive the
// returned frames). Throws MissingCoordinate (motion_columns.hpp) for a coordinate the drawing reads without a
// column, phiq::Error with one line for a result without t, a value read that is not finite, t decreasing, or a
// scene with nothing to draw.
ViewerMotion viewer_motion(const Scene& scene, const MechanismSketch& sketch, const CsvTable& table,
                           const std::string& result, std::size_t budget = kFrameBudget);

}  // namespace phiq::tools
