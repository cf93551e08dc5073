/// @file
/// The parts a drawing of a scene shows (`phiq animate`, `phiq plot`): the scene's own parts (its `parts` section)
/// and, for what has none, parts derived from the constraints (Part::derived): a moving body without a part gets
/// links from its reference point to the points its joints attach, a shaft along each joint axis, a cross for a
/// universal joint, a block for a slider, a fork for a revolute in space; a link of natural coordinates (a distance,
/// the bar of a polar or segment-angle constraint) gets a bar between its points; a kind's own geometry (a gear's
/// pitch circle, a cam's profile, a slot's curve, a belt's path, a screw's thread, a rack) is drawn on the body that
/// carries it. Sizes follow the model's length scale.
#pragma once

#include <vector>

#include "phiq/parts.hpp"
#include "phiq/scene.hpp"

namespace phiq {

/// The scene's parts followed by the derived ones (see the file comment), in scene order. Pre-condition: `scene`
/// was read by load_scene() or parse_scene() (its model and body frames set).
std::vector<Part> drawn_parts(const Scene& scene);

}  // namespace phiq
