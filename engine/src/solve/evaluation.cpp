// Φ, Φq, Φt and γ at the caller's point into a workspace, and Φq as an Eigen sparse view (evaluation.hpp): the
// model's own evaluations, with the checks of the public solves and the workspace's counters.
#include "phiq/evaluation.hpp"

#include "solve/factorisation.hpp"

#include <string>

namespace phiq {

namespace {

// The solves' check of the workspace, and of a vector the caller passes as q or q̇.
void check_point(const Model& model, const Workspace& ws, const Eigen::VectorXd& v, const char* what) {
  detail::check_workspace(model, ws);
  if (v.size() != model.num_coordinates())
    throw Error(std::string(what) + " has " + std::to_string(v.size()) + " entries; the model has " +
                std::to_string(model.num_coordinates()) + " coordinates");
}

}  // namespace

JacobianView jacobian_matrix(const Model& model, const Workspace& ws) {
  detail::check_workspace(model, ws);  // the values match the pattern's size
  const CscPattern& p = model.jacobian_pattern();
  return JacobianView(p.rows, p.cols, p.nnz(), p.col_ptr.data(), p.row_idx.data(), ws.jacobian_values.data());
}

JacobianView evaluate_jacobian(const Model& model, const Eigen::VectorXd& q, double t, Workspace& ws) {
  check_point(model, ws, q, "q");
  model.jacobian(q.data(), t, ws.jacobian_values.data());
  ++ws.counters.jacobian_evaluations;
  ws.has_jacobian = false;  // the values are no longer those a solve_position left at its solution
  return jacobian_matrix(model, ws);
}

const Eigen::VectorXd& evaluate_residual(const Model& model, const Eigen::VectorXd& q, double t, Workspace& ws) {
  check_point(model, ws, q, "q");
  model.residual(q.data(), t, ws.phi.data());
  ++ws.counters.residual_evaluations;
  return ws.phi;
}

const Eigen::VectorXd& evaluate_phi_t(const Model& model, const Eigen::VectorXd& q, double t, Workspace& ws) {
  check_point(model, ws, q, "q");
  model.phi_t(q.data(), t, ws.rhs.data());
  ++ws.counters.phi_t_evaluations;
  return ws.rhs;
}

const Eigen::VectorXd& evaluate_gamma(const Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                                      Workspace& ws) {
  check_point(model, ws, q, "q");
  check_point(model, ws, qd, "qd");
  model.gamma(q.data(), qd.data(), t, ws.rhs.data());
  ++ws.counters.gamma_evaluations;
  return ws.rhs;
}

}  // namespace phiq
