/// @file
/// The spatial (3D) constraint kinds: the normalisation of a body's Euler parameters and of a natural unit vector,
/// the rigid-body conditions of 3D natural coordinates (distance, constant dot product), the joints (spherical,
/// revolute, prismatic, cylindrical, universal, planar, rigid, point on line, point on plane) and the drivers on
/// joint angles and joint distances: one header each in kinds/ (the joints share kinds/spatial_joints.hpp), all
/// listed by kinds/registry.hpp. Same contract as the planar kinds (constraint_kinds.hpp).
#pragma once

#include "phiq/kinds/registry.hpp"
