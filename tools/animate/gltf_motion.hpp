// `phiq animate SCENE RESULT -o OUT.glb`: the motion of a scene's result as a glTF 2.0 binary. A node per part the
// drawing shows (phiq/drawn_parts.hpp: its shapes' triangles, keyframed by part_pose()); a scene without parts gets
// today's sketch instead: a node per moving body (planar bodies in the z = 0 plane rotated about z by ψ, spatial ones
// by their Euler parameters as the quaternion (e1, e2, e3, e0)), per link of the sketch (natural coordinates, a
// spatial distance: origin at its first point, x axis along it) and per joint (a ball at its point); a body without
// a part keeps its box. Keyframes at the result's rows; a spatial scene's nodes under a root turning z up.
#pragma once

#include <string>

#include "phiq/clearance.hpp"
#include "phiq/csv_compare.hpp"
#include "phiq/mechanism_sketch.hpp"
#include "phiq/scene.hpp"

namespace phiq::tools {

// The slots the .glb reads: the moving bodies' frames, the ends of the sketch's links, its joints.
std::vector<Slot> glb_reads(const Scene& scene, const MechanismSketch& sketch, const std::vector<Part>& parts);

// The .glb of `table`, the result of `scene` read from `result` (named in messages), with the witness points of
// `clearance` (the scene's output.clearance measured, or null). Throws MissingCoordinate (motion_columns.hpp) for a
// coordinate the drawing reads without a column, phiq::Error with one line for a result without t, a value that is
// not finite, times not increasing as 32-bit floats, or a scene with nothing to animate.
//
// Clearance as the HTML viewer shows it, in standard glTF (a part's colour cannot be animated without an
// extension): per pair two balls, each the material point of its part that is the witness at the pair's worst pose,
// carried by the part at every row and scaled ×2 at the rows where the pair comes within the threshold (the
// viewer's colouring: viewer_near_rows() at the report's row nearest in time); each ball's node `extras.clearance`
// holds the pair, its worst t and distance, the threshold, the near rows and the interference intervals.
std::string motion_glb(const Scene& scene, const CsvTable& table, const std::string& result,
                       const ClearanceReport* clearance = nullptr);

}  // namespace phiq::tools
