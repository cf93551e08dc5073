/// @file
/// The lines and joints that draw a mechanism, derived from its constraints (`phiq plot`, `phiq animate`): each
/// kind's sketch() says what it draws (kinds/registry.hpp), e.g. the bars between natural points (distance, polar,
/// segment angle, the guide of a point on a line, the segments of a constant angle, a spatial distance), for every
/// body a line from its reference point to each point where a pair attaches it, and a mark at each joint (revolute,
/// prismatic, spherical, …). Endpoints are OutputPoints, so a drawing at any q is evaluate_point() of each end;
/// spatial points come through the same code (projected by the caller). Loops, drivers and equations draw nothing.
#pragma once

#include <vector>

#include "phiq/model.hpp"
#include "phiq/output_points.hpp"

namespace phiq {

/// What a line of the drawing is.
enum class SketchLine {
  kBar,  ///< a link between two points (natural coordinates, or a spatial distance between attachments)
  kArm,  ///< a body's arm: its reference point (`from`) to a point where a pair attaches it (`to`)
};

/// One line of the drawing.
struct SketchSegment {
  OutputPoint from;                    ///< first end
  OutputPoint to;                      ///< second end
  SketchLine line = SketchLine::kBar;  ///< a link or a body's arm
  Index constraint = -1;               ///< index into Model::constraints() of the constraint that drew it first
};

/// One joint of the drawing.
struct SketchJoint {
  OutputPoint at;                         ///< where it is
  JointMark mark = JointMark::kRevolute;  ///< how it is drawn
  /// kPrismatic: the guide's direction in the frame of `guide` (a planar direction in x, y); otherwise unused.
  kin::V2 axis{1, 0};
  Frame2 guide;           ///< kPrismatic: the body (or ground) carrying the guide
  bool fixed = false;     ///< it does not move (a ground pivot: drawn hatched)
  int end = -1;           ///< kPoint: which end (0, 1) of its constraint's link; −1 for a joint
  Index constraint = -1;  ///< index into Model::constraints() of the constraint that drew it first
};

/// The drawing of a model: its lines and joints, each once (a segment named by two constraints, e.g. a distance and
/// the angle of the same bar, is drawn once; a joint at a point already marked is not marked again), in constraint
/// order. Lines whose ends are both fixed (ground) are left out; fixed joints are kept (ground pivots).
struct MechanismSketch {
  std::vector<SketchSegment> segments;  ///< the lines
  std::vector<SketchJoint> joints;      ///< the joints
};

/// The drawing of `model` (see MechanismSketch).
MechanismSketch sketch_mechanism(const Model& model);

/// The lines of `model`: sketch_mechanism(model).segments.
std::vector<SketchSegment> sketch_segments(const Model& model);

}  // namespace phiq
