// Internal: whether two readings of a scene's parts and loads give the same generalized forces Q(q, q̇, q̈, t)
// everywhere (phiq/inverse_dynamics.hpp), decided from their data: what a design parameter reaches of them. The
// efforts' sensitivities (phiq/effort_sensitivity.hpp) difference Q along a parameter only where it does.
#pragma once

#include <vector>

#include "phiq/parts.hpp"

namespace phiq::detail {

// Whether two frames follow q and t alike: the same kind, slots, attachments and expressions.
bool same_frame(const PartFrame& a, const PartFrame& b);

// Whether `a` and `b` hold the same parts in the same order with the same frames and mass properties (names and
// shapes are not compared: Q reads neither; a density moves the mass properties, which are). Conservative: a
// difference that changes no Q (a massless part's frame) still counts as one.
bool same_inertia(const std::vector<Part>& a, const std::vector<Part>& b);

// Whether `a` and `b` have the same gravity and the same applied loads (their frames, points, axes, compiled
// expressions, a parameter being a constant of their tapes, and the springs' constants), names aside.
bool same_loads(const Loads& a, const Loads& b);

}  // namespace phiq::detail
