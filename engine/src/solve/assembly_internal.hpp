// Internal to the engine: what the sweep needs of assembly.cpp beyond the public functions.
#pragma once

#include "phiq/assembly.hpp"

namespace phiq::detail {

/// The freedoms the drivers leave at a solution assembled near q at t (from q moved off it by up to a tenth of each
/// coordinate's scale), or −1 when none was found: fewer than at q means q is a singular position of a model
/// regular elsewhere (assembly.cpp). Called on failure paths only (an assembly and a rank analysis). With `report`,
/// that solution's rank analysis is left there (the redundant constraints it names).
Index driven_dof_nearby(const Model& model, const Eigen::VectorXd& q, double t, const AssemblyOptions& options,
                        RankReport* report = nullptr);

}  // namespace phiq::detail
