// Internal: the sensitivities of one converged row with factors of Φq already at its position (sensitivity.hpp):
// what solve_sensitivities() does after it has factorised, and what the sweep does at each written row with the
// factors its velocity solve made there.
#pragma once

#include <array>
#include <vector>

#include "phiq/sensitivity.hpp"

namespace phiq::detail {

// The vectors one row's sensitivities are computed in, kept between rows (no allocation per row).
struct SensitivityScratch {
  std::array<Eigen::VectorXd, 4> f;  // the function at the four shifted points (one entry per row of Φ)
  Eigen::VectorXd d;                 // its difference quotient: the right-hand side, negated
  Eigen::VectorXd qk, vk;            // the shifted q and q̇
  // Φq of each model at its shifted q: made for the velocity, read again for the acceleration (the same point)
  std::array<std::vector<double>, 4> jacobian;
};

// Writes the sensitivities of (q, q̇, q̈) at t to every parameter into `out` (SensitivityLayout; derivatives above
// `order` are NaN), solving with `lu`, the factors of the swept model's Φq at q. `ws` lends the right-hand side
// of the kept rows (models with dropped rows) and counts the solves. Returns false when a solve fails (then the
// values are NaN).
bool sensitivities_with_factors(const Model& model, const std::vector<OutputSensitivity>& parameters, double t,
                                const double* q, const double* qd, const double* qdd, int order,
                                SparseLuNumeric& lu, Workspace& ws, SensitivityScratch& scratch, double* out);

}  // namespace phiq::detail
