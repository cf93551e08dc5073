/// @file
/// The lines that draw a mechanism, derived from its constraints (`phiq plot`): each kind's sketch() says what it
/// draws (kinds/registry.hpp), e.g. the bars between natural points (distance, polar, segment angle, the guide of a
/// point on a line, the segments of a constant angle) and, for every body, a line from its reference point to each
/// point where a revolute or prismatic pair attaches it. Endpoints
/// are OutputPoints, so a drawing at any q is evaluate_point() of each end; a spatial point kind will draw through
/// the same code (projected by the caller). Loops, drivers and equations draw nothing.
#pragma once

#include <vector>

#include "phiq/model.hpp"
#include "phiq/output_points.hpp"

namespace phiq {

/// One line of the drawing.
struct SketchSegment {
  OutputPoint from;  ///< first end
  OutputPoint to;    ///< second end
};

/// The lines of `model`, each once (a segment named by two constraints, e.g. a distance and the angle of the same
/// bar, is drawn once), in constraint order. Lines whose ends are both fixed (ground) are left out.
std::vector<SketchSegment> sketch_segments(const Model& model);

}  // namespace phiq
