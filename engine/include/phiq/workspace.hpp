// Per-thread data for the algorithms of kinematics.hpp: the state (q, q̇, q̈), the Jacobian values, the numeric LU
// factorisation and scratch vectors. A Workspace belongs to one thread at a time; the Model it was made for is
// shared and must outlive it (and must not be moved while it exists).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "phiq/model.hpp"

namespace phiq {

// Work done, counted where it happens (for summaries and for tests that the engine computes only what is asked).
struct WorkCounters {
  Index newton_iterations = 0;
  Index residual_evaluations = 0;
  Index jacobian_evaluations = 0;
  Index factorizations = 0;
  Index velocity_solves = 0;
  Index acceleration_solves = 0;
  Index phi_t_evaluations = 0;
  Index gamma_evaluations = 0;
};

class Workspace {
 public:
  explicit Workspace(const Model& model);
  const Model& model() const { return *model_; }

  // State. q starts at the model's initial positions; q̇ and q̈ at zero. Algorithms read and write them; so may
  // the caller (e.g. to give a better starting guess).
  Eigen::VectorXd q, qd, qdd;
  WorkCounters counters;

  // ---- used by the algorithms (kinematics.cpp); not needed by callers ----
  Eigen::VectorXd phi, rhs, step, trial, trial_phi;
  std::vector<double> jacobian_values;
  std::unique_ptr<SparseLuNumeric> lu;  // null for non-square models
  // The point (q, t) of the current factorisation, so that velocity and acceleration reuse it exactly when it is
  // still valid and refactorise otherwise.
  Eigen::VectorXd factorized_q;
  double factorized_t = 0.0;
  bool has_factorization = false;

 private:
  const Model* model_;
};

}  // namespace phiq
