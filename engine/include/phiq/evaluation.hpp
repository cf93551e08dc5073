/// @file
/// Φ, Φq, Φt and γ at a point of the caller's choosing, evaluated into a Workspace, and Φq as an Eigen sparse
/// matrix: what an embedding program (or the Python bindings) reads besides the solves of kinematics.hpp. Each
/// evaluation is the one the solves make (Model::residual(), jacobian(), phi_t(), gamma()), counted in
/// ws.counters; the results live in the workspace's scratch, valid until the next solve or evaluation with it.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "phiq/workspace.hpp"

namespace phiq {

/// Φq as a read-only Eigen sparse matrix (m × n, compressed columns, phiq::Index indices) over the model's
/// jacobian_pattern() and values held elsewhere: no copy. Usable wherever Eigen takes a sparse expression
/// (products, `Eigen::SparseMatrix<double> copy = view;`, iteration with InnerIterator).
using JacobianView = Eigen::Map<const Eigen::SparseMatrix<double, Eigen::ColMajor, Index>>;

/// The view of ws.jacobian_values over model.jacobian_pattern(): Φq wherever the workspace's solves or
/// evaluate_jacobian() last evaluated it (not necessarily at ws.q: a solve that reused its factors evaluated none).
/// Valid while `model` and `ws` live and until the next evaluation of Φq into ws. Throws phiq::Error when ws was
/// made for another model or its Jacobian values were resized.
JacobianView jacobian_matrix(const Model& model, const Workspace& ws);

/// Evaluates Φq at (q, t) into ws.jacobian_values and returns their view (jacobian_matrix()). The workspace's
/// factorisation is left as it is (it is kept apart). Throws phiq::Error for a q of the wrong size or a workspace of
/// another model.
JacobianView evaluate_jacobian(const Model& model, const Eigen::VectorXd& q, double t, Workspace& ws);

/// Evaluates Φ(q, t) (m entries) into ws.phi and returns it. Throws as evaluate_jacobian().
const Eigen::VectorXd& evaluate_residual(const Model& model, const Eigen::VectorXd& q, double t, Workspace& ws);

/// Evaluates Φt(q, t) = ∂Φ/∂t (m entries; zero for rows that do not depend on t) into ws.rhs and returns it. The
/// velocity equation is Φq q̇ = −Φt. Throws as evaluate_jacobian().
const Eigen::VectorXd& evaluate_phi_t(const Model& model, const Eigen::VectorXd& q, double t, Workspace& ws);

/// Evaluates γ(q, q̇, t) = −(Φq q̇)q q̇ − 2 Φqt q̇ − Φtt (m entries) into ws.rhs and returns it: the right-hand side
/// of the acceleration equation Φq q̈ = γ. Throws as evaluate_jacobian(), also for a qd of the wrong size.
const Eigen::VectorXd& evaluate_gamma(const Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                                      Workspace& ws);

}  // namespace phiq
