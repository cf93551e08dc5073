// Internal: minimum_norm_multipliers() (phiq/joint_reactions.hpp) with its buffers lent by the caller, one per
// thread (the sweep's Sweeper), so that a written row of a model with redundant rows allocates nothing.
#pragma once

#include <Eigen/Dense>

#include <vector>

#include "phiq/linear_solver.hpp"
#include "phiq/model.hpp"

namespace phiq::detail {

// The dense work of minimum_norm_multipliers(): their capacity kept from row to row.
struct MinimumNormScratch {
  Eigen::MatrixXd directions;                   // N, m × dropped rows: the directions λ may move along
  Eigen::VectorXd unit, gradient, alpha, step;  // e_r (rows), ∇Φ_r (coordinates), α (kept rows), N's coefficients
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr;  // of N
};

// minimum_norm_multipliers() with `scratch`'s buffers.
bool minimum_norm_multipliers(const Model& model, SparseLuNumeric& lu, const double* q, double t,
                              Eigen::VectorXd& lambda, std::vector<Index>* indeterminate, MinimumNormScratch& scratch);

}  // namespace phiq::detail
