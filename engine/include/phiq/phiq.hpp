/// @file
/// phiq: sparse, large-scale multibody kinematics. One include for the whole public API.
#pragma once

#include "phiq/assembly.hpp"
#include "phiq/batch.hpp"
#include "phiq/constraint_kinds.hpp"
#include "phiq/constraint_kinds_3d.hpp"
#include "phiq/csv_writer.hpp"
#include "phiq/expression.hpp"
#include "phiq/kinematics.hpp"
#include "phiq/linear_solver.hpp"
#include "phiq/mechanism_sketch.hpp"
#include "phiq/model.hpp"
#include "phiq/min_norm_solver.hpp"
#include "phiq/motion_law.hpp"
#include "phiq/output_plan.hpp"
#include "phiq/output_points.hpp"
#include "phiq/rank_analysis.hpp"
#include "phiq/scene.hpp"
#include "phiq/sweep.hpp"
#include "phiq/text.hpp"
#include "phiq/version.hpp"
#include "phiq/workspace.hpp"
