// solve_position / solve_velocity / solve_acceleration against closed forms, finite differences and each other.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <tuple>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

constexpr double kL2 = 0.3, kL3 = 1.0;

Model crank_slider(double omega, double theta0, LinearSolverKind lu = LinearSolverKind::kUmfpack) {
  return test::crank_slider_model(omega, theta0, lu);
}

// Closed form x_B(θ) = L2 cos θ + sqrt(L3² − L2² sin² θ) and its θ-derivatives.
struct SliderRef {
  double x, dx, ddx;
};
SliderRef slider(double th) {
  const double s = std::sin(th), c = std::cos(th);
  const double S = std::sqrt(kL3 * kL3 - kL2 * kL2 * s * s);
  const double dS = -kL2 * kL2 * s * c / S;
  const double ddS = -kL2 * kL2 * (c * c - s * s) / S - std::pow(kL2 * kL2 * s * c, 2) / (S * S * S);
  return {kL2 * c + S, -kL2 * s + dS, -kL2 * c + ddS};
}

TEST(Kinematics, CrankSliderMatchesClosedFormOverHalfTurnOfTime) {
  // Also a non-constant crank speed would need θ̈; here θ̇ = ω, θ̈ = 0: ẋ = x' ω, ẍ = x'' ω².
  const double omega = 2.0;
  Model m = crank_slider(omega, 0.0);
  SweepOptions opt;
  opt.t_begin = 0.0;
  opt.t_end = M_PI;
  opt.steps = 180;
  test::Trace tr;
  ASSERT_EQ(test::sweep(m, opt, &tr), SolveStatus::kSuccess);
  ASSERT_EQ(tr.t.size(), 181u);
  double worst_x = 0, worst_v = 0, worst_a = 0;
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    const double th = omega * tr.t[k];
    SliderRef r = slider(th);
    worst_x = std::max(worst_x, std::fabs(tr.q[k](3) - r.x));
    worst_v = std::max(worst_v, std::fabs(tr.qd[k](3) - r.dx * omega));
    worst_a = std::max(worst_a, std::fabs(tr.qdd[k](3) - r.ddx * omega * omega));
    EXPECT_NEAR(tr.q[k](1), kL2 * std::cos(th), 1e-12);
    EXPECT_NEAR(tr.qdd[k](0), 0.0, 1e-12);  // the notes' erratum: the driver row of γ is 0
  }
  // the tolerance (1e-10 × the 1 m rod) bounds the estimated error, not the error itself (measured 1.05e-10 with the
  // cubic predictor, whose steps mostly need no Newton step and carry their estimates from row to row)
  EXPECT_LT(worst_x, 2e-10);
  EXPECT_LT(worst_v, 1e-8);
  EXPECT_LT(worst_a, 1e-8);
}

TEST(Kinematics, NotesWorkedExampleJacobianAndGamma) {
  // Φq and γ at one state, entry by entry against the notes' matrices (with the distance row scaled by 1/(2 L3),
  // phiq's normalisation, and the polar rows written as the notes write them).
  Model m = crank_slider(2.0, 0.0);
  Eigen::VectorXd q(4), qd(4);
  const double th = 0.7, xa = kL2 * std::cos(th), ya = kL2 * std::sin(th), xb = 1.1;
  q << th, xa, ya, xb;
  qd << 2.0, 0.3, -0.4, 0.5;
  std::vector<double> vals(static_cast<std::size_t>(m.jacobian_pattern().nnz()));
  m.jacobian(q.data(), 0.1, vals.data());
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(4, 4);
  const CscPattern& p = m.jacobian_pattern();
  for (Index c = 0; c < p.cols; ++c)
    for (Index k = p.col_ptr[c]; k < p.col_ptr[c + 1]; ++k) J(p.row_idx[k], c) = vals[k];
  Eigen::MatrixXd notes(4, 4);
  notes << kL2 * std::sin(th), 1, 0, 0,  //
      -kL2 * std::cos(th), 0, 1, 0,      //
      0, 2 * xa - 2 * xb, 2 * ya, 2 * xb - 2 * xa, 1, 0, 0, 0;
  notes.row(2) /= 2 * kL3;
  // phiq orders rows as added: crank (2 rows), rod, motor — the same order as the notes.
  EXPECT_LT((J - notes).cwiseAbs().maxCoeff(), 1e-14);

  Eigen::VectorXd gamma(4);
  m.gamma(q.data(), qd.data(), 0.1, gamma.data());
  Eigen::VectorXd g_notes(4);
  g_notes << -qd(0) * qd(0) * kL2 * std::cos(th), -qd(0) * qd(0) * kL2 * std::sin(th),
      -(2 * qd(1) * (qd(1) - qd(3)) + 2 * qd(2) * qd(2) + 2 * qd(3) * (qd(3) - qd(1))) / (2 * kL3), 0.0;
  EXPECT_LT((gamma - g_notes).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(Kinematics, DenseAndSparsePathsAgree) {
  Model dense = crank_slider(1.3, 0.2, LinearSolverKind::kDense);
  SweepOptions opt;
  opt.t_end = 5.0;
  opt.steps = 97;
  test::Trace b;
  ASSERT_EQ(test::sweep(dense, opt, &b), SolveStatus::kSuccess);
  for (LinearSolverKind kind : {LinearSolverKind::kUmfpack, LinearSolverKind::kKlu}) {
    Model sparse = crank_slider(1.3, 0.2, kind);
    test::Trace a;
    ASSERT_EQ(test::sweep(sparse, opt, &a), SolveStatus::kSuccess) << to_string(kind);
    for (std::size_t k = 0; k < a.t.size(); ++k) {
      EXPECT_LT((a.q[k] - b.q[k]).cwiseAbs().maxCoeff(), 1e-12) << to_string(kind);
      EXPECT_LT((a.qd[k] - b.qd[k]).cwiseAbs().maxCoeff(), 1e-11) << to_string(kind);
      EXPECT_LT((a.qdd[k] - b.qdd[k]).cwiseAbs().maxCoeff(), 1e-10) << to_string(kind);
    }
  }
}

// The Newton loop evaluates Φ and Φq in one pass (Model::residual_and_jacobian); it must give exactly what the two
// separate passes give, for every kind of constraint (these scenes cover the 2D and 3D kinds and equations), both
// where each Jacobian entry has a slot of its own (stored) and where entries share one (added up: a pin whose
// two points share a coordinate).
TEST(Kinematics, FusedResidualAndJacobianEqualTheSeparatePasses) {
  auto same = [](const Model& m, const Eigen::VectorXd& q, double t, const std::string& what) {
    Eigen::VectorXd phi(m.num_equations()), phi2(m.num_equations());
    // different garbage in the two buffers: a slot neither pass writes cannot compare equal
    std::vector<double> jac(static_cast<std::size_t>(m.jacobian_pattern().nnz()), -7.0);
    std::vector<double> jac2(jac.size(), 5.0);
    m.residual(q.data(), t, phi.data());
    m.jacobian(q.data(), t, jac.data());
    m.residual_and_jacobian(q.data(), t, phi2.data(), jac2.data());
    EXPECT_EQ(phi, phi2) << what;
    EXPECT_EQ(jac, jac2) << what;
  };
  for (const char* rel : {"seed/fourbar_mixed.yaml", "seed/crank_slider_equations.yaml", "seed/fourbar_relative.yaml",
                          "seed/fourbar_reference_point.yaml", "spatial/rssr.yaml", "spatial/rssr_natural.yaml",
                          "benchmarks/bricard.yaml", "redundant/door_three_hinges.yaml"}) {
    Scene s = load_scene(test::model_path(rel));
    Eigen::VectorXd q = s.model->initial_positions();
    for (Index j = 0; j < q.size(); ++j) q(j) += 0.01 * std::sin(1.3 * static_cast<double>(j) + 0.4);
    same(*s.model, q, 0.37, rel);
  }
  // Shared slots: B = (x, x) makes the distance row's two entries on x fall on one slot.
  ModelBuilder b;
  const Index x = b.add_coordinate("x", 0.6), y = b.add_coordinate("y", 0.2);
  b.add("d", DistanceSpec{{Slot::constant(0.0), Slot::constant(0.0)}, {Slot::coordinate(x), Slot::coordinate(x)}, 1.0});
  b.add("e", DistanceSpec{{Slot::coordinate(y), Slot::constant(0.0)}, {Slot::coordinate(x), Slot::coordinate(y)}, 1.0});
  Model m = std::move(b).build();
  ASSERT_LT(m.jacobian_pattern().nnz(), 5);  // 5 entries on fewer slots
  Eigen::VectorXd q(2);
  q << 0.7, -0.3;
  same(m, q, 0.0, "shared slots");
  std::vector<double> jac(static_cast<std::size_t>(m.jacobian_pattern().nnz()));
  m.jacobian(q.data(), 0.0, jac.data());
  // d: (2x² − 1)/2 → ∂/∂x = 2x; e: ((x − y)² + y² − 1)/2 → ∂/∂x = x − y, ∂/∂y = 2y − x
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(2, 2);
  const CscPattern& p = m.jacobian_pattern();
  for (Index c = 0; c < 2; ++c)
    for (Index k = p.col_ptr[c]; k < p.col_ptr[c + 1]; ++k) dense(p.row_idx[k], c) = jac[static_cast<std::size_t>(k)];
  EXPECT_DOUBLE_EQ(dense(0, 0), 2 * 0.7);
  EXPECT_DOUBLE_EQ(dense(1, 0), 0.7 + 0.3);
  EXPECT_DOUBLE_EQ(dense(1, 1), 2 * -0.3 - 0.7);
}

TEST(Kinematics, AssemblyFromRoughPlacementIsTheNearbySolution) {
  Model m = crank_slider(2.0, 0.4);
  Workspace ws(m);
  ws.q << 0.1, 0.5, -0.2, 0.7;  // far from the solution, θ2 off by 0.3 rad
  PositionSummary s;
  ASSERT_EQ(solve_position(m, 0.0, NewtonOptions{}, ws, &s), SolveStatus::kSuccess) << s.message;
  EXPECT_NEAR(ws.q(0), 0.4, 1e-12);
  EXPECT_NEAR(ws.q(3), slider(0.4).x, 1e-10);
  EXPECT_LE(s.residual, 1e-10);
  EXPECT_GT(s.iterations, 2);
}

TEST(Kinematics, VelocityAndAccelerationAreTimeDerivativesOfPosition) {
  // Independent of any closed form: central differences of the converged positions in time.
  Model m = crank_slider(1.7, 0.3);
  Workspace ws(m);
  auto position_at = [&](double t) {
    ws.q(0) = 0.3 + 1.7 * t;  // good guess
    EXPECT_EQ(solve_position(m, t, NewtonOptions{1e-14, 30}, ws), SolveStatus::kSuccess);
    return Eigen::VectorXd(ws.q);
  };
  const double t = 0.9, h = 1e-4;
  Eigen::VectorXd qm = position_at(t - h), qp = position_at(t + h), q0 = position_at(t);
  ASSERT_EQ(solve_velocity(m, t, ws), SolveStatus::kSuccess);
  ASSERT_EQ(solve_acceleration(m, t, ws), SolveStatus::kSuccess);
  EXPECT_LT(((qp - qm) / (2 * h) - ws.qd).cwiseAbs().maxCoeff(), 1e-7);
  EXPECT_LT(((qp - 2 * q0 + qm) / (h * h) - ws.qdd).cwiseAbs().maxCoeff(), 1e-5);
}

TEST(Kinematics, VelocityReusesTheFactorisationAtTheConvergedPoint) {
  Model m = crank_slider(2.0, 0.0);
  Workspace ws(m);
  ASSERT_EQ(solve_position(m, 0.2, NewtonOptions{}, ws), SolveStatus::kSuccess);
  const Index f0 = ws.counters.factorizations;
  ASSERT_EQ(solve_velocity(m, 0.2, ws), SolveStatus::kSuccess);
  ASSERT_EQ(solve_acceleration(m, 0.2, ws), SolveStatus::kSuccess);
  // Newton's last step was below the tolerance, so its factorisation is Φq at the solution to the accuracy of q:
  // velocity and acceleration share it, no new factorisation
  EXPECT_EQ(ws.counters.factorizations, f0);
  EXPECT_EQ(ws.counters.velocity_solves, 1);
  EXPECT_EQ(ws.counters.acceleration_solves, 1);
  // ... and they agree with a factorisation made exactly at q
  Workspace fresh(m);
  fresh.q = ws.q;
  ASSERT_EQ(solve_velocity(m, 0.2, fresh), SolveStatus::kSuccess);
  ASSERT_EQ(solve_acceleration(m, 0.2, fresh), SolveStatus::kSuccess);
  EXPECT_EQ(fresh.counters.factorizations, 1);
  // (to the position tolerance 1e-10 they inherit: q̇ ~ 0.6 m/s, q̈ ~ 1.6 m/s² here)
  EXPECT_LT((fresh.qd - ws.qd).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT((fresh.qdd - ws.qdd).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(Kinematics, ModifiedNewtonReusesTheFactorisationAcrossSolvesAndRefreshesWhenSlow) {
  Model m = crank_slider(2.0, 0.0);
  Workspace ws(m);
  NewtonOptions full;
  NewtonOptions modified;
  modified.jacobian_update = JacobianUpdate::kWhenSlow;
  ASSERT_EQ(solve_position(m, 0.0, full, ws), SolveStatus::kSuccess);
  ASSERT_EQ(solve_velocity(m, 0.0, ws), SolveStatus::kSuccess);
  // a small step: the factorisation from t = 0 contracts well, no factorisation at all
  const Index f0 = ws.counters.factorizations;
  ws.q += 0.01 * ws.qd;
  PositionSummary s;
  ASSERT_EQ(solve_position(m, 0.01, modified, ws, &s), SolveStatus::kSuccess) << s.BriefReport();
  EXPECT_EQ(ws.counters.factorizations, f0);
  EXPECT_EQ(s.factorizations, 0);
  EXPECT_GE(s.iterations, 2);  // no contraction known yet: the error estimate needs a second step
  EXPECT_GE(ws.newton_contraction, 0.0);
  EXPECT_LT(ws.newton_contraction, 0.25);
  // same solution as full Newton from the same start, to the tolerance
  Workspace ref(m);
  ref.q = ws.q;
  ref.q(0) += 1e-3;
  ASSERT_EQ(solve_position(m, 0.01, full, ref), SolveStatus::kSuccess);
  EXPECT_LT((ref.q - ws.q).cwiseAbs().maxCoeff(), 1e-9);
  // a large jump (most of a turn): the old matrix contracts badly or slowly, so it is refreshed and the solve
  // still converges
  ws.q(0) += 2.5;
  ASSERT_EQ(solve_position(m, 1.26, modified, ws, &s), SolveStatus::kSuccess) << s.BriefReport();
  EXPECT_GE(s.factorizations, 1) << s.iterations << " iterations, theta " << ws.newton_contraction;
  Workspace ref2(m);
  ref2.q = ws.q;
  ASSERT_EQ(solve_position(m, 1.26, full, ref2), SolveStatus::kSuccess);
  EXPECT_LT((ref2.q - ws.q).cwiseAbs().maxCoeff(), 1e-9);
}

// NewtonOptions::start_error: a start whose residual holds is accepted without a Newton step only when its estimated
// error is within the tolerance too (or not given); otherwise one step at least, whose own estimate then reports.
TEST(Kinematics, AStartIsAcceptedWithoutAStepOnlyWhenItsErrorEstimateHolds) {
  Model m = crank_slider(2.0, 0.0, LinearSolverKind::kKlu);
  const double t = 0.3, th = 2.0 * t;
  Workspace ws(m);
  ASSERT_EQ(solve_position(m, t, NewtonOptions{}, ws), SolveStatus::kSuccess);
  const Eigen::VectorXd exact = ws.q;
  // 3e-11 m off along x_B: the residual (the rod's row, ~3e-11 m) is within the tolerance of 1e-10 m
  Eigen::VectorXd start = exact;
  start(3) += 3e-11;
  struct Case {
    double start_error;
    int iterations;
  };
  for (const Case c : {Case{-1.0, 0}, Case{0.5, 0}, Case{1.0, 0}, Case{1.5, 1}, Case{INFINITY, 1}}) {
    NewtonOptions o;
    o.start_error = c.start_error;
    ws.q = start;
    PositionSummary sum;
    ASSERT_EQ(solve_position(m, t, o, ws, &sum), SolveStatus::kSuccess) << c.start_error;
    EXPECT_EQ(sum.iterations, c.iterations) << c.start_error;
    if (c.iterations == 0) {
      EXPECT_EQ(ws.q, start);
      EXPECT_EQ(sum.error_estimate, c.start_error);
    } else {
      EXPECT_NEAR(ws.q(3), slider(th).x, 1e-15);  // the step lands on the solution (to rounding)
      EXPECT_GE(sum.error_estimate, 0.0);
      EXPECT_LE(sum.error_estimate, 1.0);
    }
  }
}

// NewtonOptions::known_to (a sweep's rows at their rounding level): a full step whose estimated error is within it
// ends the solve, reported as the rounding level with its warning; a step beyond it, or none given, goes on to the
// tolerance; and not where Φq is ill-conditioned (rcond < 1e-4), where linear convergence marks a singular position.
TEST(Kinematics, AStepWithinTheLevelQIsKnownToEndsTheSolve) {
  Model m = crank_slider(2.0, 0.0, LinearSolverKind::kKlu);
  const double t = 0.3;
  Workspace ws(m);
  ASSERT_EQ(solve_position(m, t, NewtonOptions{}, ws), SolveStatus::kSuccess);
  const Eigen::VectorXd exact = ws.q;
  Eigen::VectorXd start = exact;
  start(3) += 1e-7;  // 1000 tolerances off along x_B: its residual (the rod's row) is not within the tolerance
  auto solve = [&](double known_to) {
    NewtonOptions o;
    o.known_to = known_to;
    ws.q = start;
    PositionSummary sum;
    EXPECT_EQ(solve_position(m, t, o, ws, &sum), SolveStatus::kSuccess) << known_to;
    return sum;
  };
  const PositionSummary plain = solve(0.0);
  EXPECT_GE(plain.iterations, 2);
  EXPECT_EQ(plain.rounding_level, 0.0);
  EXPECT_FALSE(plain.slow_convergence);
  EXPECT_FALSE(plain.linear_convergence);
  EXPECT_EQ(solve(100.0).iterations, plain.iterations) << "a first step of about 1000 tolerances is beyond 100";
  const PositionSummary known = solve(1e4);
  EXPECT_EQ(known.iterations, 1);
  EXPECT_GT(known.rounding_level, 500.0);  // the step's size: about 1e-7 m over the tolerance test's 1e-10 m
  EXPECT_LT(known.rounding_level, 2000.0);
  EXPECT_EQ(known.error_estimate, known.rounding_level);
  EXPECT_FALSE(known.rounding_measured) << "an end within the level measures nothing a sweep should carry";
  EXPECT_TRUE(known.slow_convergence);
  EXPECT_FALSE(known.linear_convergence) << "a stop at the level q is known to, not a singular position";
  EXPECT_NE(known.message.find("within the level q can be known to here"), std::string::npos) << known.message;
  EXPECT_NEAR(ws.q(3), exact(3), 1e-12);  // Newton's step itself is as good as ever

  // The slider driven next to its dead centre (θ = 2e-5 rad): Φq's pivot ratio is about 1e-5
  ModelBuilder b;
  const double th0 = 2e-5, xb0 = kL2 * std::cos(th0) + std::sqrt(kL3 * kL3 - std::pow(kL2 * std::sin(th0), 2));
  Index th = b.add_coordinate("theta2", th0), xa = b.add_coordinate("xA", kL2 * std::cos(th0)),
        ya = b.add_coordinate("yA", kL2 * std::sin(th0)), xb = b.add_coordinate("xB", xb0);
  auto S = Slot::coordinate;
  auto C = Slot::constant;
  b.add("crank", PolarSpec{{S(xa), S(ya)}, {C(0), C(0)}, kL2, S(th)});
  b.add("rod", DistanceSpec{{S(xa), S(ya)}, {S(xb), C(0)}, kL3});
  b.add_driver("slide", xb, MotionLaw::linear(xb0, 0.0));
  Model dead = std::move(b).build();
  Workspace wd(dead);
  wd.q(th) += 1e-7;
  NewtonOptions o;
  o.known_to = 1e4;
  PositionSummary near;
  ASSERT_EQ(solve_position(dead, 0.0, o, wd, &near), SolveStatus::kSuccess) << near.message;
  EXPECT_LT(near.rcond, 1e-4);
  EXPECT_EQ(near.rounding_level, 0.0) << near.message;
  EXPECT_GE(near.iterations, 2);

  // On the dead centre itself (the slider at L2 + L3, θ = 0), from θ = 1e-3: Φ is quadratic in θ there, so the
  // steps only halve (linear convergence) and Newton stops with the residual within tolerance, θ about √tol from
  // the dead centre (measured: 7 halving steps, θ = 7.8e-6): a slow convergence that is linear_convergence, not a
  // rounding level.
  {
    ModelBuilder bd;
    Index t2 = bd.add_coordinate("theta2", 1e-3), xa2 = bd.add_coordinate("xA", kL2),
          ya2 = bd.add_coordinate("yA", 0.0), xb2 = bd.add_coordinate("xB", kL2 + kL3);
    bd.add("crank", PolarSpec{{S(xa2), S(ya2)}, {C(0), C(0)}, kL2, S(t2)});
    bd.add("rod", DistanceSpec{{S(xa2), S(ya2)}, {S(xb2), C(0)}, kL3});
    bd.add_driver("slide", xb2, MotionLaw::linear(kL2 + kL3, 0.0));
    Model on = std::move(bd).build();
    Workspace wo(on);
    PositionSummary at;
    ASSERT_EQ(solve_position(on, 0.0, NewtonOptions{}, wo, &at), SolveStatus::kSuccess) << at.message;
    EXPECT_TRUE(at.slow_convergence) << at.BriefReport();
    EXPECT_TRUE(at.linear_convergence) << at.BriefReport();
    EXPECT_EQ(at.rounding_level, 0.0);
    EXPECT_NE(at.message.find("stopped converging quadratically"), std::string::npos) << at.message;
    EXPECT_LT(std::fabs(wo.q(t2)), 2e-5);  // 2 √tol
    EXPECT_GE(at.iterations, 5);
  }
}

TEST(Kinematics, SingularJacobianIsAStatusNotACrash) {
  // Drive the slider coordinate xB instead of the crank: at the dead centre θ = 0 the crank angle is not
  // determined to first order by xB and Φq is singular.
  ModelBuilder b;
  Index th = b.add_coordinate("theta2", 0.0), xa = b.add_coordinate("xA", kL2), ya = b.add_coordinate("yA", 0.0),
        xb = b.add_coordinate("xB", kL2 + kL3);
  auto S = Slot::coordinate;
  auto C = Slot::constant;
  b.add("crank", PolarSpec{{S(xa), S(ya)}, {C(0), C(0)}, kL2, S(th)});
  b.add("rod", DistanceSpec{{S(xa), S(ya)}, {S(xb), C(0)}, kL3});
  b.add_driver("slide", xb, MotionLaw::linear(kL2 + kL3, 0.0));
  Model m = std::move(b).build();
  Workspace ws(m);
  ASSERT_EQ(solve_position(m, 0.0, NewtonOptions{}, ws), SolveStatus::kSuccess);  // already at the solution
  LinearSummary ls;
  EXPECT_EQ(solve_velocity(m, 0.0, ws, &ls), SolveStatus::kSingularJacobian);
  EXPECT_NE(ls.message.find("not unique"), std::string::npos) << ls.message;
}

// Settings no solve can honour are refused at the call, naming the field: an infinite tolerance used to accept the
// start as the solution, a NaN start_error to accept it unchecked with a NaN error estimate, a negative
// max_iterations to be refused as a bad tolerance; an unknown jacobian_update and negative max_backtracks passed.
TEST(Kinematics, NewtonOptionsNoSolveCanHonourAreRefusedNamingTheField) {
  Model m = crank_slider(2.0, 0.0);
  auto refusal = [&](auto&& edit) -> std::string {
    NewtonOptions o;
    edit(o);
    Workspace ws(m);
    try {
      (void)solve_position(m, 0.5, o, ws);  // throws: the test
    } catch (const Error& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_EQ(refusal([](NewtonOptions& o) { o.tolerance = INFINITY; }),
            "NewtonOptions: tolerance must be > 0 and finite");
  EXPECT_EQ(refusal([](NewtonOptions& o) { o.tolerance = 0.0; }), "NewtonOptions: tolerance must be > 0 and finite");
  EXPECT_EQ(refusal([](NewtonOptions& o) { o.tolerance = NAN; }), "NewtonOptions: tolerance must be > 0 and finite");
  EXPECT_EQ(refusal([](NewtonOptions& o) { o.max_iterations = -1; }), "NewtonOptions: max_iterations must be >= 0");
  EXPECT_EQ(refusal([](NewtonOptions& o) { o.max_backtracks = -1; }), "NewtonOptions: max_backtracks must be >= 0");
  EXPECT_EQ(refusal([](NewtonOptions& o) { o.max_contraction = 1.0; }),
            "NewtonOptions: max_contraction must be in (0, 1)");
  EXPECT_EQ(refusal([](NewtonOptions& o) { o.start_error = NAN; }),
            "NewtonOptions: start_error must not be NaN (negative: unknown)");
  for (double bad : {-1.0, double{NAN}, double{INFINITY}})
    EXPECT_EQ(refusal([&](NewtonOptions& o) { o.known_to = bad; }), "NewtonOptions: known_to must be >= 0 and finite");
  EXPECT_EQ(refusal([](NewtonOptions& o) { o.jacobian_update = static_cast<JacobianUpdate>(7); }),
            "NewtonOptions: jacobian_update is not a JacobianUpdate");
  // the limits themselves are settings: no step at all, no backtrack, an infinite start error (always a step)
  EXPECT_EQ(refusal([](NewtonOptions& o) { o.max_iterations = 0; }), "accepted");
  EXPECT_EQ(refusal([](NewtonOptions& o) { o.max_backtracks = 0; }), "accepted");
  EXPECT_EQ(refusal([](NewtonOptions& o) { o.start_error = INFINITY; }), "accepted");
}

// The workspace's scratch vectors are public; one a caller had resized made the solves write past its end (an
// abort in free()). It is refused at the call, like a wrong-sized state.
TEST(Kinematics, AWorkspaceWhoseScratchWasResizedIsRefused) {
  Model m = crank_slider(2.0, 0.0);
  auto refusal = [&](auto&& edit) -> std::string {
    Workspace ws(m);
    edit(ws);
    try {
      (void)solve_position(m, 0.5, NewtonOptions{}, ws);  // each throws: the test
      (void)solve_velocity(m, 0.5, ws);
      (void)solve_acceleration(m, 0.5, ws);
    } catch (const Error& e) {
      return e.what();
    }
    return "accepted";
  };
  const std::string refused =
      "workspace scratch has the wrong size (phi, rhs, step, trial, trial_phi, jacobian_values, solve_values, "
      "solve_rhs keep the sizes the Workspace was made with)";
  EXPECT_EQ(refusal([](Workspace& ws) { ws.phi.resize(1); }), refused);
  EXPECT_EQ(refusal([](Workspace& ws) { ws.rhs.resize(0); }), refused);
  EXPECT_EQ(refusal([](Workspace& ws) { ws.step.resize(2); }), refused);
  EXPECT_EQ(refusal([](Workspace& ws) { ws.trial.resize(1); }), refused);
  EXPECT_EQ(refusal([](Workspace& ws) { ws.trial_phi.resize(1); }), refused);
  EXPECT_EQ(refusal([](Workspace& ws) { ws.jacobian_values.resize(1); }), refused);
  EXPECT_EQ(refusal([](Workspace& ws) { ws.solve_rhs.resize(3); }), refused);
  EXPECT_EQ(refusal([](Workspace&) {}), "accepted");
}

TEST(Kinematics, NonSquareModelIsReportedWithCounts) {
  ModelBuilder b;
  Index x = b.add_coordinate("x", 0.0);
  b.add_coordinate("y", 0.0);
  b.add_driver("d", x, MotionLaw::linear(0, 1));
  Model m = std::move(b).build();
  Workspace ws(m);
  PositionSummary s;
  EXPECT_EQ(solve_position(m, 0.0, NewtonOptions{}, ws, &s), SolveStatus::kNotSquare);
  EXPECT_NE(s.message.find("1 equations for 2 coordinates"), std::string::npos) << s.message;
}

TEST(Kinematics, ConvergenceDoesNotDependOnTheOrigin) {
  // The same crank-slider translated by 10^6 m along x (ground pivot and slider line moved): converges, and
  // the positions relative to the pivot agree with the untranslated run to the relative tolerance.
  for (double shift : {0.0, 1e6}) {
    ModelBuilder b;
    Index th = b.add_coordinate("theta2", 0.0), xa = b.add_coordinate("xA", shift + 0.25),
          ya = b.add_coordinate("yA", 0.05), xb = b.add_coordinate("xB", shift + 1.2);
    auto S = Slot::coordinate;
    auto C = Slot::constant;
    b.add("crank", PolarSpec{{S(xa), S(ya)}, {C(shift), C(0)}, kL2, S(th)});
    b.add("rod", DistanceSpec{{S(xa), S(ya)}, {S(xb), C(0)}, kL3});
    b.add_driver("motor", th, MotionLaw::linear(0.0, 2.0));
    Model m = std::move(b).build();
    SweepOptions opt;
    opt.t_end = 1.0;
    opt.steps = 20;
    test::Trace tr;
    ASSERT_EQ(test::sweep(m, opt, &tr), SolveStatus::kSuccess) << "shift " << shift;
    for (std::size_t k = 0; k < tr.t.size(); ++k)
      EXPECT_NEAR(tr.q[k](3) - shift, slider(2.0 * tr.t[k]).x, 1e-8) << "shift " << shift;
  }
}

TEST(Kinematics, RoundingFloorIsTheRowsSensitivityToItsCoordinates) {
  // A bar 10^6 m from the origin: Φ = (|B − A|² − L²) / 2L, ∂Φ/∂x_B = −∂Φ/∂x_A = d_x / L (and y alike), so the floor
  // is 64 ε (|d_x| (|x_A| + |x_B|) + |d_y| (|y_A| + |y_B|)) / L: the few ulps a residual computed there carries.
  const double xa = 1e6 + 0.3, ya = -2e5 + 0.4, xb = 1e6 + 1.1, yb = -2e5 - 0.2, len = 1.25;
  ModelBuilder b;
  auto S = Slot::coordinate;
  const Index ia = b.add_coordinate("xa", xa), ja = b.add_coordinate("ya", ya), ib = b.add_coordinate("xb", xb),
              jb = b.add_coordinate("yb", yb);
  b.add("bar", DistanceSpec{{S(ia), S(ja)}, {S(ib), S(jb)}, len});
  Model m = std::move(b).build();
  const Eigen::VectorXd q = m.initial_positions();
  const double dx = xb - xa, dy = yb - ya;
  const double expected =
      ToleranceScales::kUlpFloor *
      (std::fabs(dx) * (std::fabs(xa) + std::fabs(xb)) + std::fabs(dy) * (std::fabs(ya) + std::fabs(yb))) / len;
  EXPECT_NEAR(m.row_rounding_floor(0, q.data(), 0.0), expected, 1e-14 * expected);

  // A driver atan(x) = t at x = 10^26: the row hardly moves with x (∂/∂x = 1/(1 + x²)), so the floor is
  // 64 ε · |x| / (1 + x²) ≈ 1e-38 and not 64 ε · |x| ≈ 4e14, which passed any residual for a drive beyond π/2.
  const Scene sc = parse_scene(R"Y(
coordinates: {x: 1e26}
drivers:
  - {name: d, expr: "atan(x)", unit: angle, law: {type: linear, initial: 0, rate: 1}}
time: {start: 0, end: 2, steps: 4}
)Y",
                               "atan.yaml");
  const Eigen::VectorXd qx = sc.model->initial_positions();
  EXPECT_NEAR(sc.model->row_rounding_floor(0, qx.data(), 2.0), ToleranceScales::kUlpFloor * 1e26 / (1.0 + 1e52), 1e-52);
  EXPECT_THROW(sc.model->row_rounding_floor(1, qx.data(), 2.0), Error);
}

TEST(Kinematics, ADriveBeyondAnAsymptoteFailsWhereThePositionsStopExisting) {
  // atan(x) = t has no solution from t = π/2 on (x runs off to infinity), nor 1/x = 1 − t from t = 1 for x > 0.
  // A residual of 0.43 at x = 2e26 was accepted before as "within its rounding floor" (64 ulps of |x|): the sweep
  // reported success with rows far off. Now it stops at the asymptote, and no row after it is delivered.
  for (const auto& [expr, rate, t_star] : {std::tuple{"atan(x)", 1.0, M_PI / 2}, std::tuple{"1/x", -1.0, 1.0}}) {
    const std::string start = rate > 0 ? "0" : "1";
    const std::string text = "coordinates: {x: " + start + "}\ndrivers:\n  - {name: d, expr: \"" + expr +
                             "\", unit: angle, law: {type: linear, initial: " + start +
                             ", rate: " + std::to_string(rate) + "}}\ntime: {start: 0, end: 2, steps: 4}\n";
    const Scene sc = parse_scene(text, "asymptote.yaml");
    Workspace ws(*sc.model);
    SweepSummary sum;
    double last_t = -1.0;
    const SolveStatus st = run_sweep(
        *sc.model, sc.sweep, ws,
        [&](const StepView& v) {
          last_t = v.t;
          return true;
        },
        &sum);
    EXPECT_NE(st, SolveStatus::kSuccess) << expr;
    EXPECT_LT(last_t, t_star) << expr;
    EXPECT_GT(sum.failed_time, t_star - 0.5) << expr << ": " << sum.message;
    EXPECT_LE(sum.failed_time, t_star + 0.5) << expr << ": " << sum.message;
  }
}

// A derivative that does not exist where the value does (√x at x = 0: ∂ = −∞; x^1.5 there: γ infinite; the law
// √t at t = 0: ḟ infinite) is a kNonFinite naming the constraint and the coordinate. It was a "singular position"
// (the LU found the matrix with −∞ singular) or a bare "velocity is not finite".
TEST(Kinematics, DerivativesThatDoNotExistAreNamedNotSingular) {
  auto scene = [](const std::string& expr, const std::string& law) {
    return parse_scene("phiq: 1\ncoordinates: {x: 0, y: 0}\nconstraints:\n  - {name: c, type: equation, expr: \"" +
                           expr + "\", unit: length}\ndrivers:\n  - {name: m, coordinate: x, law: " + law +
                           "}\ntime: {start: 0, end: 1, steps: 4}\noutput: {velocities: true, accelerations: true}\n",
                       "nf.yaml");
  };
  const std::string linear = "{type: linear, initial: 0, rate: 1}";
  {  // y = √x, x = t: ∂c/∂x = −1/(2√x) = −∞ at t = 0
    Scene s = scene("y - sqrt(x)", linear);
    Workspace ws(*s.model);
    ASSERT_EQ(solve_position(*s.model, 0.0, NewtonOptions{}, ws), SolveStatus::kSuccess);  // x = y = 0 holds
    LinearSummary ls;
    EXPECT_EQ(solve_velocity(*s.model, 0.0, ws, &ls), SolveStatus::kNonFinite);
    EXPECT_HAS(ls.message, "Φq is not finite: ∂'c'/∂'x' = -inf, a derivative that does not exist at this position");
    SweepSummary sum;
    test::Trace tr;
    EXPECT_EQ(test::sweep(*s.model, s.sweep, &tr, &sum), SolveStatus::kNonFinite);
    EXPECT_EQ(sum.failed_step, 0);
    EXPECT_HAS(sum.message, "∂'c'/∂'x' = -inf");
    EXPECT_EQ(sum.message.find("singular"), std::string::npos) << sum.message;
    // positions only: Newton's matrix at x = 0 has the −∞; the sub-steps cannot avoid it
    s.sweep.velocities = s.sweep.accelerations = false;
    EXPECT_EQ(test::sweep(*s.model, s.sweep, &tr, &sum), SolveStatus::kNonFinite);
    EXPECT_HAS(sum.message, "∂'c'/∂'x' = -inf");
    EXPECT_EQ(sum.message.find("singular"), std::string::npos) << sum.message;
  }
  {  // y = x^1.5: ∂ = 1.5 √x is 0 at x = 0, but γ = −0.75 ẋ²/√x is infinite
    Scene s = scene("y - x^1.5", linear);
    Workspace ws(*s.model);
    ASSERT_EQ(solve_position(*s.model, 0.0, NewtonOptions{}, ws), SolveStatus::kSuccess);
    LinearSummary ls;
    ASSERT_EQ(solve_velocity(*s.model, 0.0, ws, &ls), SolveStatus::kSuccess) << ls.message;
    EXPECT_EQ(ws.qd(1), 0.0);
    EXPECT_EQ(solve_acceleration(*s.model, 0.0, ws, &ls), SolveStatus::kNonFinite);
    EXPECT_HAS(ls.message, "acceleration is not finite: γ of 'c' is not finite, second derivatives that do not exist");
  }
  {  // x = √t: ḟ = 1/(2√t) is infinite at t = 0
    Scene s = scene("y - x", "{type: expression, f: \"sqrt(t)\"}");
    Workspace ws(*s.model);
    ASSERT_EQ(solve_position(*s.model, 0.0, NewtonOptions{}, ws), SolveStatus::kSuccess);
    LinearSummary ls;
    EXPECT_EQ(solve_velocity(*s.model, 0.0, ws, &ls), SolveStatus::kNonFinite);
    EXPECT_HAS(ls.message, "velocity is not finite: Φt of 'm' is not finite, a derivative that does not exist");
  }
}

}  // namespace
}  // namespace phiq
