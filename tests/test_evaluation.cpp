// Φ, Φq, Φt and γ evaluated into a workspace (evaluation.hpp), and Φq as an Eigen sparse view: the view against
// central differences of Φ on a planar and a spatial model, its storage against the model's pattern, and Φt, γ
// against differences of Φ along time and along the motion.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// Φq by central differences of Φ (every entry of the m × n matrix, zeros included).
Eigen::MatrixXd central_jacobian(const Model& m, Eigen::VectorXd q, double t, Workspace& ws) {
  Eigen::MatrixXd d(m.num_equations(), m.num_coordinates());
  for (Index j = 0; j < m.num_coordinates(); ++j) {
    const double qj = q(j), h = 1e-6 * std::max(1.0, std::fabs(qj));
    q(j) = qj + h;
    const Eigen::VectorXd plus = evaluate_residual(m, q, t, ws);
    q(j) = qj - h;
    const Eigen::VectorXd minus = evaluate_residual(m, q, t, ws);
    q(j) = qj;
    d.col(j) = (plus - minus) / (2.0 * h);
  }
  return d;
}

// The view equals central differences to 1e-7 relative (to the largest entry of its column) and is stored as the
// pattern is: the same arrays, no copy.
void expect_view_is_jacobian(const Model& m, const Eigen::VectorXd& q, double t) {
  Workspace ws(m);
  const Eigen::MatrixXd fd = central_jacobian(m, q, t, ws);
  const Index before = ws.counters.jacobian_evaluations;
  const JacobianView j = evaluate_jacobian(m, q, t, ws);
  EXPECT_EQ(ws.counters.jacobian_evaluations, before + 1);
  const CscPattern& p = m.jacobian_pattern();
  ASSERT_EQ(j.rows(), m.num_equations());
  ASSERT_EQ(j.cols(), m.num_coordinates());
  EXPECT_EQ(j.nonZeros(), p.nnz());
  EXPECT_EQ(j.outerIndexPtr(), p.col_ptr.data());
  EXPECT_EQ(j.innerIndexPtr(), p.row_idx.data());
  EXPECT_EQ(j.valuePtr(), ws.jacobian_values.data());
  const Eigen::MatrixXd dense = Eigen::MatrixXd(j);
  for (Index c = 0; c < dense.cols(); ++c) {
    const double scale = std::max(1.0, fd.col(c).cwiseAbs().maxCoeff());
    for (Index r = 0; r < dense.rows(); ++r)
      EXPECT_LE(std::fabs(dense(r, c) - fd(r, c)), 1e-7 * scale)
          << m.row_name(r) << " / " << m.coordinate_names()[static_cast<std::size_t>(c)];
  }
  // the view over the workspace's values without evaluating again
  const JacobianView again = jacobian_matrix(m, ws);
  EXPECT_EQ(again.valuePtr(), ws.jacobian_values.data());
  EXPECT_EQ(ws.counters.jacobian_evaluations, before + 1);
}

TEST(Evaluation, JacobianViewIsCentralDifferencesOfPhiPlanar) {
  const Model m = test::crank_slider_model(2.0, 0.0);
  Eigen::VectorXd q = m.initial_positions();  // any point, not only solutions
  expect_view_is_jacobian(m, q, 0.3);
  Workspace ws(m);
  ASSERT_EQ(solve_position(m, 0.3, {}, ws), SolveStatus::kSuccess);
  expect_view_is_jacobian(m, ws.q, 0.3);
}

TEST(Evaluation, JacobianViewIsCentralDifferencesOfPhiSpatial) {
  const Scene sc = load_scene(test::model_path("spatial/rssr.yaml"));
  const Model& m = *sc.model;
  expect_view_is_jacobian(m, m.initial_positions(), 0.2);
  Workspace ws(m);
  ASSERT_EQ(solve_position(m, 0.2, {}, ws), SolveStatus::kSuccess);
  expect_view_is_jacobian(m, ws.q, 0.2);
}

// At a solved state: Φq q̇ = −Φt and Φq q̈ = γ through the view; Φt is the time difference of Φ, and γ minus the
// second difference of Φ along (q̇, 1): d²/ds² Φ(q + s q̇, t + s) = Φqq q̇ q̇ + 2 Φqt q̇ + Φtt = −γ.
TEST(Evaluation, PhiTAndGammaAgainstDifferencesOfPhi) {
  const Scene sc = load_scene(test::model_path("spatial/rssr.yaml"));
  for (const Model* m : {sc.model.get()}) {
    Workspace ws(*m);
    const double t = 0.35;
    ASSERT_EQ(solve_position(*m, t, {}, ws), SolveStatus::kSuccess);
    ASSERT_EQ(solve_velocity(*m, t, ws), SolveStatus::kSuccess);
    ASSERT_EQ(solve_acceleration(*m, t, ws), SolveStatus::kSuccess);
    const Eigen::VectorXd q = ws.q, qd = ws.qd, qdd = ws.qdd;
    Workspace ev(*m);
    const Eigen::VectorXd phi_t = evaluate_phi_t(*m, q, t, ev);
    const Eigen::VectorXd gamma = evaluate_gamma(*m, q, qd, t, ev);
    const JacobianView j = evaluate_jacobian(*m, q, t, ev);
    const Eigen::VectorXd jqd = j * qd, jqdd = j * qdd;
    EXPECT_LE((jqd + phi_t).cwiseAbs().maxCoeff(), 1e-12 * std::max(1.0, phi_t.cwiseAbs().maxCoeff()));
    EXPECT_LE((jqdd - gamma).cwiseAbs().maxCoeff(), 1e-11 * std::max(1.0, gamma.cwiseAbs().maxCoeff()));
    const double h = 1e-6;
    const Eigen::VectorXd later = evaluate_residual(*m, q, t + h, ev);  // (a copy: the next call overwrites ev.phi)
    const Eigen::VectorXd earlier = evaluate_residual(*m, q, t - h, ev);
    const Eigen::VectorXd dt = (later - earlier) / (2 * h);
    EXPECT_LE((dt - phi_t).cwiseAbs().maxCoeff(), 1e-7 * std::max(1.0, phi_t.cwiseAbs().maxCoeff()));
    const double s = 1e-4;
    const Eigen::VectorXd p0 = evaluate_residual(*m, q, t, ev);
    const Eigen::VectorXd pp = evaluate_residual(*m, q + s * qd, t + s, ev);
    const Eigen::VectorXd pm = evaluate_residual(*m, q - s * qd, t - s, ev);
    const Eigen::VectorXd second = (pp - 2.0 * p0 + pm) / (s * s);
    EXPECT_LE((second + gamma).cwiseAbs().maxCoeff(), 1e-5 * std::max(1.0, gamma.cwiseAbs().maxCoeff()));
    EXPECT_GT(gamma.cwiseAbs().maxCoeff(), 1e-3);  // a real test: the motion accelerates
  }
}

TEST(Evaluation, WrongSizesAndForeignWorkspacesThrow) {
  const Model m = test::crank_slider_model();
  const Model other = test::crank_slider_model();
  Workspace ws(m), theirs(other);
  EXPECT_THROW((void)evaluate_residual(m, Eigen::VectorXd::Zero(3), 0.0, ws), Error);
  EXPECT_THROW((void)evaluate_gamma(m, m.initial_positions(), Eigen::VectorXd::Zero(5), 0.0, ws), Error);
  EXPECT_THROW((void)evaluate_jacobian(m, m.initial_positions(), 0.0, theirs), Error);
  EXPECT_THROW((void)jacobian_matrix(m, theirs), Error);
  try {
    (void)evaluate_phi_t(m, Eigen::VectorXd::Zero(2), 0.0, ws);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "q has 2 entries; the model has 4 coordinates");
  }
}

}  // namespace
}  // namespace phiq
