// `phiq plot`'s drawing of the mechanism: its parts (plot_parts.hpp) and its sketch
// (engine/include/phiq/mechanism_sketch.hpp) over them at a few rows, the
// ground hatched under fixed pivots and guides, revolute joints as circles, prismatic ones as blocks on their
// guides, link ends as dots, and the paths of the traced points. Planar scenes in x, y with ticks and units;
// spatial ones in an isometric view (x, y, z with z up) with the three axes drawn.
#pragma once

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

#include "phiq/mechanism_sketch.hpp"
#include "phiq/parts.hpp"
#include "phiq/scene.hpp"
#include "plot_draw.hpp"

namespace phiq::tools {

// The slots whose values place an output point.
std::vector<Slot> slots_of(const OutputPoint& p);

// The slots the drawing of `sketch` reads: the ends of its lines, its joints and the frames of its prismatic guides.
std::vector<Slot> sketch_reads(const MechanismSketch& sketch);

// sketch_reads() and the slots the frames of the scene's drawn parts read (part_reads()).
std::vector<Slot> drawing_reads(const MechanismSketch& sketch, const std::vector<Part>& parts);

struct MechanismFrames {
  const Model* model = nullptr;
  const MechanismSketch* sketch = nullptr;
  bool spatial = false;
  std::vector<Eigen::VectorXd> q;  // q at each drawn row (what the sketch reads is set)
  std::vector<double> t;           // t of each drawn row
  // traced output points: name and position at every row (z = 0 in the plane)
  std::vector<std::pair<std::string, std::vector<std::array<double, 3>>>> traces;
  std::vector<Part> parts;                         // the parts drawn (phiq/drawn_parts.hpp), under the sketch
  std::vector<std::array<double, 3>> part_bounds;  // points bounding the parts at every row (for the extent)
};

// The panel, in the square at (x0, y0) of side `side` pixels.
std::string mechanism_panel(const MechanismFrames& m, double x0, double y0, double side);

// What the panel's parts share (and `phiq animate`'s HTML viewer draws its moving mechanism on): screen axes of a
// point before scaling (x right, y up: the plane as it is, space in the isometric view from (1, 1, 1), z up, x towards
// the lower left and y towards the lower right, right-handed as space is).
std::pair<double, double> project(const std::array<double, 3>& p, bool spatial);

// The panel's pixel box around everything drawn at m's rows and its traces (equal scales, room for the ground
// symbols), and in space the length of the three axes drawn from the origin (0 in the plane).
struct MechanismView {
  svg::Box box;
  double axis_length = 0.0;
};
MechanismView mechanism_view(const MechanismFrames& m, double x0, double y0, double side);

// The still part of the panel: axes with ticks and units (plane) or the frame, the three axes and a scale bar
// (space), and the hatched ground under every fixed pivot, where it is at the first row: each drawn in full, or
// drawn once and used at each pivot, one per 2-pixel cell (the HTML viewer, where 10⁴ pivots in a row would
// otherwise weigh 7 MB and cost every frame's repaint).
enum class GroundPivots { kInline, kUses };
std::string mechanism_background(const MechanismFrames& m, const MechanismView& view,
                                 GroundPivots pivots = GroundPivots::kInline);

}  // namespace phiq::tools
