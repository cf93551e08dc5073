// Outputs a scene lists (points, drivers, residuals, rcond) and the work the sweep does for them: exact counts of
// solves and evaluations, point motions against closed forms and finite differences.
// Where the output files go (AtomicOutputFile, same_file) is test_output_files.cpp.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstdint>
#include <cmath>
#include <limits>

#include <tbb/task_arena.h>

#include "atomic_file.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// The seed four-bar in mixed coordinates (coupler as a body), with every kind of output listed. Crank tip A is at
// 0.4 (cos t, sin t) exactly.
std::string fourbar_scene(const std::string& output, int steps = 36) {
  return R"(
phiq: 1
parameters: {L1: 1.0, L2: 0.4, L3: 1.2, L4: 1.0}
coordinates: {theta2: 0.0, xA: 0.4, yA: 0.0, x3: 0.7, y3: 0.5, psi3: 1.0, xB: 1.1, yB: 1.0}
points: {O: [0, 0], A: [xA, yA], B: [xB, yB], C: [L1, 0]}
bodies: {coupler: [x3, y3, psi3]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}
  - {name: A, type: revolute, between: [{body: coupler, at: [-L3/2, 0]}, {point: A}]}
  - {name: B, type: revolute, between: [{body: coupler, at: [L3/2, 0]}, {point: B}]}
  - {name: rocker, type: distance, points: [C, B], length: L4}
drivers:
  - {name: motor, coordinate: theta2, law: {type: harmonic, offset: 0.5, amplitude: 2, frequency: 1.5}}
time: {start: 0, end: 2, steps: )" +
         std::to_string(steps) + R"(}
output: )" +
         output + "\n";
}

struct Rows {
  std::vector<double> t;
  std::vector<Eigen::VectorXd> q;
  std::vector<std::vector<PointMotion>> points;
  std::vector<Eigen::VectorXd> phi;
  std::vector<double> rcond;
};

Rows sweep_scene(const Scene& scene, SweepSummary* sum, int threads = 1, Index chunk = 0) {
  Rows r;
  SweepOptions opt = scene.sweep;
  opt.threads = threads;
  opt.chunk_steps = chunk;
  Workspace ws(*scene.model);
  const SolveStatus st = run_sweep(
      *scene.model, opt, ws,
      [&](const StepView& s) {
        r.t.push_back(s.t);
        r.q.push_back(s.q);
        if (s.points) r.points.emplace_back(s.points, s.points + opt.points.size());
        if (s.phi) r.phi.push_back(*s.phi);
        r.rcond.push_back(s.rcond);
        return true;
      },
      sum);
  EXPECT_EQ(st, SolveStatus::kSuccess) << sum->message;
  return r;
}

TEST(OutputPoints, PlanarBodyPointMatchesTheClosedForm) {
  // body at (1, 2), ψ = 0.3, ψ̇ = 2, ψ̈ = −1, ṙ = (0.5, −0.25), r̈ = (0.1, 0.2); s = (0.4, −0.3)
  const double q[] = {1, 2, 0.3}, qd[] = {0.5, -0.25, 2}, qdd[] = {0.1, 0.2, -1};
  auto S = Slot::coordinate;
  OutputPoint p = planar_body_point("P", Frame2{S(0), S(1), S(2)}, 0.4, -0.3);
  PointMotion m = evaluate_point(p, q, qd, qdd);
  const double c = std::cos(0.3), s = std::sin(0.3);
  const double rx = c * 0.4 + s * 0.3, ry = s * 0.4 - c * 0.3;  // R(ψ) s
  EXPECT_DOUBLE_EQ(m.r[0], 1 + rx);
  EXPECT_DOUBLE_EQ(m.r[1], 2 + ry);
  EXPECT_DOUBLE_EQ(m.v[0], 0.5 - 2 * ry);
  EXPECT_DOUBLE_EQ(m.v[1], -0.25 + 2 * rx);
  EXPECT_DOUBLE_EQ(m.a[0], 0.1 + ry - 4 * rx);
  EXPECT_DOUBLE_EQ(m.a[1], 0.2 - rx - 4 * ry);
  EXPECT_EQ(m.r[2], 0.0);
  // without q̇ only the position is evaluated
  PointMotion only = evaluate_point(p, q, nullptr, nullptr);
  EXPECT_EQ(only.v[0], 0.0);
  EXPECT_EQ(only.a[1], 0.0);
  // a fixed point (constant slots) does not move
  PointMotion fixed = evaluate_point(planar_point("C", Point2{Slot::constant(1), Slot::constant(0)}), q, qd, qdd);
  EXPECT_EQ(fixed.r[0], 1.0);
  EXPECT_EQ(fixed.v[0], 0.0);
}

TEST(OutputPoints, SweepPointsAreExactAndTheirDerivativesMatchFiniteDifferences) {
  const int steps = 2000;  // h = 1e-3: central differences to ~h² = 1e-6
  Scene scene = parse_scene(fourbar_scene("{velocities: true, accelerations: true, points: [A, "
                                          "{name: P, body: coupler, at: [0.1, 0.3]}]}",
                                          steps),
                            "fourbar.yaml");
  ASSERT_EQ(scene.sweep.points.size(), 2u);
  SweepSummary sum;
  Rows r = sweep_scene(scene, &sum);
  ASSERT_EQ(r.points.size(), static_cast<std::size_t>(steps + 1));
  const double h = r.t[1] - r.t[0];
  double worst_v = 0, worst_a = 0;
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    // A is the crank tip: 0.4 (cos θ, sin θ), θ = 0.5 + 2 sin(1.5 t)
    const double t = r.t[k], th = 0.5 + 2 * std::sin(1.5 * t), w = 3 * std::cos(1.5 * t), al = -4.5 * std::sin(1.5 * t);
    const PointMotion& a = r.points[k][0];
    ASSERT_NEAR(a.r[0], 0.4 * std::cos(th), 1e-9);
    ASSERT_NEAR(a.r[1], 0.4 * std::sin(th), 1e-9);
    ASSERT_NEAR(a.v[0], -0.4 * w * std::sin(th), 1e-8);
    ASSERT_NEAR(a.a[1], 0.4 * (al * std::cos(th) - w * w * std::sin(th)), 1e-7);
    // P on the coupler: its position is r3 + R(ψ3) s from the row's coordinates
    const Eigen::VectorXd& q = r.q[k];
    const double c = std::cos(q(5)), s = std::sin(q(5));
    ASSERT_DOUBLE_EQ(r.points[k][1].r[0], q(3) + c * 0.1 - s * 0.3);
    ASSERT_DOUBLE_EQ(r.points[k][1].r[1], q(4) + s * 0.1 + c * 0.3);
    if (k == 0 || k + 1 == r.t.size()) continue;
    for (int d = 0; d < 2; ++d) {
      const PointMotion &prev = r.points[k - 1][1], &cur = r.points[k][1], &next = r.points[k + 1][1];
      worst_v = std::max(worst_v, std::fabs((next.r[d] - prev.r[d]) / (2 * h) - cur.v[d]));
      worst_a = std::max(worst_a, std::fabs((next.v[d] - prev.v[d]) / (2 * h) - cur.a[d]));
    }
  }
  EXPECT_LT(worst_v, 1e-4);
  EXPECT_LT(worst_a, 1e-3);
  EXPECT_GT(worst_v, 0.0);  // the differences are real numbers, not copies of the evaluated derivatives
  EXPECT_EQ(sum.counters.point_evaluations, 2 * (steps + 1));
  // a parallel sweep delivers the same motions, evaluated in the chunks, in time order
  SweepSummary par_sum;
  Rows par = sweep_scene(scene, &par_sum, 2, 64);
  EXPECT_GT(par_sum.parallel_chunks, 1);
  ASSERT_EQ(par.t, r.t);
  double worst = 0;
  for (std::size_t k = 0; k < r.t.size(); ++k)
    for (int i = 0; i < 2; ++i)
      for (int d = 0; d < 2; ++d)
        worst = std::max({worst, std::fabs(par.points[k][i].r[d] - r.points[k][i].r[d]),
                          std::fabs(par.points[k][i].v[d] - r.points[k][i].v[d]),
                          std::fabs(par.points[k][i].a[d] - r.points[k][i].a[d])});
  EXPECT_LT(worst, 1e-8);
  EXPECT_EQ(par_sum.counters.point_evaluations, 2 * (steps + 1));
}

TEST(OutputPoints, SpatialPointsMoveAsRigidBodyKinematicsSays) {
  // A disk on a hinge about u = (1, 2, 2)/3 through G = (0.3, −0.2, 0.5), turned by θ = −0.3 + 3t + 0.5t²; T is
  // the disk's point (1, 0, 0), P a natural point held fixed. Every point of the disk moves on a circle about the
  // axis: ṙ_T = θ̇ u × d and r̈_T = θ̈ u × d + θ̇² u × (u × d), d = r_T − G (the sense of θ about u, ±, from the
  // first row); r_T itself is r + R(e) (1, 0, 0) with R(e) the rotation matrix of the Euler parameters.
  Scene scene = parse_scene(R"Y(phiq: 1
dimension: 3
coordinates: {x: 0.068, y: -0.484, z: 0.843, e0: 1.317, e1: 0.017, e2: 0.068, e3: -0.239, px: 1, py: 2, pz: 3}
points: {P: [px, py, pz]}
bodies:
  disk: [x, y, z, e0, e1, e2, e3]
constraints:
  - {name: hinge, type: revolute, between: [{body: ground, at: [0.3, -0.2, 0.5], axis: [1, 2, 2]}, {body: disk, at: [0.1, 0.4, -0.3], axis: [0, 1, 1]}]}
  - {name: fixP, type: fixed_point, point: P, at: [1, 2, 3]}
drivers:
  - {name: motor, joint: hinge, measure: angle, law: {type: polynomial, coefficients: [-0.3, 3, 0.5]}}
time: {start: 0, end: 1, steps: 40}
output: {velocities: true, accelerations: true, points: [P, {name: T, body: disk, at: [1, 0, 0]}]}
)Y",
                            "disk.yaml");
  ASSERT_EQ(scene.sweep.points.size(), 2u);
  EXPECT_EQ(scene.sweep.points[1].dimension(), 3);
  SweepSummary sum;
  Rows r = sweep_scene(scene, &sum);
  ASSERT_EQ(r.points.size(), 41u);
  const Eigen::Vector3d u = Eigen::Vector3d(1, 2, 2) / 3.0, g(0.3, -0.2, 0.5);
  double sense = 0.0;
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    SCOPED_TRACE("t = " + std::to_string(r.t[k]));
    const PointMotion &p = r.points[k][0], &m = r.points[k][1];
    EXPECT_EQ(p.r[0], 1.0);
    EXPECT_EQ(p.r[2], 3.0);
    EXPECT_EQ(p.v[1], 0.0);
    EXPECT_EQ(p.a[2], 0.0);
    const Eigen::VectorXd& q = r.q[k];
    const Eigen::Quaterniond e(q(3), q(4), q(5), q(6));
    const Eigen::Vector3d rt(m.r[0], m.r[1], m.r[2]), vt(m.v[0], m.v[1], m.v[2]), at(m.a[0], m.a[1], m.a[2]);
    EXPECT_LT((rt - (q.head<3>() + e.toRotationMatrix() * Eigen::Vector3d(1, 0, 0))).norm(), 1e-9);  // |e| = 1 to tol
    const double t = r.t[k], w = 3 + t, al = 1;
    const Eigen::Vector3d d = rt - g;
    if (k == 0) sense = vt.dot(u.cross(d)) > 0 ? 1.0 : -1.0;
    EXPECT_LT((vt - sense * w * u.cross(d)).norm(), 1e-9);
    EXPECT_LT((at - (sense * al * u.cross(d) + w * w * u.cross(u.cross(d)))).norm(), 1e-8);
  }
}

// Exact counts of the work each output list causes, sequential and parallel. Full Newton and a fixed predictor
// make the position work independent of the outputs, so the counts below are exact.
struct Plan {
  const char* output;
  bool v, a;     // q̇ and q̈ solved
  Index points;  // output points
};

TEST(OutputPlan, TheSweepDoesOnlyTheWorkTheOutputListsAsksFor) {
  const int steps = 40;
  const Plan plans[] = {
      {"{coordinates: [theta2]}", false, false, 0},
      {"{velocities: true}", true, false, 0},
      {"{accelerations: true}", true, true, 0},  // q̈ needs q̇: solved, not delivered
      {"{velocities: true, accelerations: true, points: [B, {name: P, body: coupler}]}", true, true, 2},
      {"{points: [B], drivers: [motor], residuals: [rocker], max_residual: true, rcond: true}", false, false, 1},
  };
  for (const Plan& p : plans) {
    Scene scene = parse_scene(fourbar_scene(p.output, steps), "fourbar.yaml");
    scene.sweep.newton.jacobian_update = JacobianUpdate::kEveryIteration;
    scene.sweep.predictor = Predictor::kPrevious;
    for (int threads : {1, 2}) {
      SweepSummary sum;
      const Index chunk = 8;
      Rows r = sweep_scene(scene, &sum, threads, chunk);
      const Index rows = steps + 1;
      ASSERT_EQ(static_cast<Index>(r.t.size()), rows);
      // a parallel sweep solves one step more per chunk but the last, the seam its successor is checked against:
      // for its position only, so that the derivatives are solved exactly once per row, in order or not
      if (threads > 1) {
        EXPECT_EQ(sum.parallel_chunks, (steps + chunk - 1) / chunk) << p.output;
      }
      const Index solved = rows;
      const WorkCounters& c = sum.counters;
      EXPECT_EQ(c.velocity_solves, p.v ? solved : 0) << p.output << ", " << threads << " threads";
      EXPECT_EQ(c.phi_t_evaluations, p.v ? solved : 0) << p.output << ", " << threads << " threads";
      EXPECT_EQ(c.acceleration_solves, p.a ? solved : 0) << p.output << ", " << threads << " threads";
      EXPECT_EQ(c.gamma_evaluations, p.a ? solved : 0) << p.output << ", " << threads << " threads";
      // points only at delivered rows: not at seams, sub-steps or seeds
      EXPECT_EQ(c.point_evaluations, p.points * rows) << p.output << ", " << threads << " threads";
      EXPECT_EQ(sum.subdivisions, 0);
    }
  }
}

TEST(OutputPlan, ResidualsAndConditionAreDeliveredWithoutExtraEvaluations) {
  const int steps = 30;
  Scene plain = parse_scene(fourbar_scene("{velocities: true}", steps), "fourbar.yaml");
  Scene asked = parse_scene(fourbar_scene("{velocities: true, residuals: [rocker, A], max_residual: true, "
                                          "rcond: true}",
                                          steps),
                            "fourbar.yaml");
  EXPECT_TRUE(asked.sweep.residuals);
  EXPECT_TRUE(asked.sweep.condition);
  ASSERT_EQ(asked.sweep.residual_columns.size(), 2u);
  EXPECT_EQ(asked.model->constraints()[asked.sweep.residual_columns[0]].name, "rocker");
  for (int threads : {1, 2}) {
    SweepSummary s0, s1;
    Rows r0 = sweep_scene(plain, &s0, threads, 4), r1 = sweep_scene(asked, &s1, threads, 4);
    EXPECT_TRUE(r0.phi.empty());
    ASSERT_EQ(r1.phi.size(), r1.t.size());
    // Φ is the one Newton's convergence test evaluated: no residual or Jacobian evaluation more (in order: a
    // parallel sweep's chunks take pooled workspaces whose old factorisations modified Newton may reuse, so its
    // counts depend on the scheduling)
    if (threads == 1) {
      EXPECT_EQ(s1.counters.residual_evaluations, s0.counters.residual_evaluations);
      EXPECT_EQ(s1.counters.factorizations, s0.counters.factorizations);
    }
    Eigen::VectorXd phi(asked.model->num_equations());
    double min_rcond = INFINITY;
    for (std::size_t k = 0; k < r1.t.size(); ++k) {
      asked.model->residual(r1.q[k].data(), r1.t[k], phi.data());
      EXPECT_EQ(phi, r1.phi[k]) << "row " << k;  // Φ at the delivered q, bit for bit
      EXPECT_LE(scaled_residual(*asked.model, phi), 1e-10);
      EXPECT_TRUE(r1.rcond[k] > 0.0 && r1.rcond[k] <= 1.0);
      EXPECT_EQ(r0.rcond[k], 0.0);  // not asked: not delivered
      min_rcond = std::min(min_rcond, r1.rcond[k]);
    }
    // with velocities the factorisation is at the delivered q: the column's minimum is the summary's
    EXPECT_EQ(min_rcond, s1.min_rcond);
  }
}

TEST(OutputPlan, CsvColumnsFollowTheOutputList) {
  Scene scene = parse_scene(fourbar_scene("{velocities: true, coordinates: [theta2], points: [B, {name: P, body: "
                                          "coupler, at: [0, 0.3]}], drivers: [motor], residuals: [rocker], "
                                          "max_residual: true, rcond: true}",
                                          4),
                            "fourbar.yaml");
  CsvFormat csv(*scene.model, scene.sweep);
  EXPECT_EQ(csv.header(),
            "t,theta2,theta2.v,B.x,B.y,B.vx,B.vy,P.x,P.y,P.vx,P.vy,motor.f,motor.df,rocker.residual,residual,rcond\n");
  // the driver's columns are its law f(t) = 0.5 + 2 sin(1.5 t) and f'(t)
  std::string row;
  SweepSummary sum;
  Workspace ws(*scene.model);
  double rocker = -1;
  const SolveStatus st = run_sweep(
      *scene.model, scene.sweep, ws,
      [&](const StepView& s) {
        if (s.step == 1) {
          csv.append_row(s, row);
          // the rocker's one row (a length), scaled by the model's length scale
          const ConstraintInfo& c = scene.model->constraints()[scene.sweep.residual_columns[0]];
          rocker = std::fabs((*s.phi)(c.first_row)) / scene.model->length_scale();
        }
        return true;
      },
      &sum);
  ASSERT_EQ(st, SolveStatus::kSuccess) << sum.message;
  EXPECT_EQ(scene.model->length_scale(), 1.0);  // the largest length in the constraints' data: the rocker's
  std::vector<double> v;
  std::stringstream in(row);
  for (std::string cell; std::getline(in, cell, ',');) v.push_back(std::stod(cell));
  ASSERT_EQ(v.size(), 16u);
  EXPECT_DOUBLE_EQ(v[11], 0.5 + 2 * std::sin(1.5 * v[0]));
  EXPECT_DOUBLE_EQ(v[12], 3 * std::cos(1.5 * v[0]));
  EXPECT_NEAR(v[1], v[11], 1e-12);  // the driven coordinate is f(t), to the tolerance
  EXPECT_DOUBLE_EQ(v[13], rocker);
  EXPECT_GE(v[14], v[13]);  // the largest over all rows is at least the rocker's
  EXPECT_LE(v[14], 1e-10);
}

TEST(CsvFormat, ARowsValuesAreTheDoublesItsTextReads) {
  // every column kind (coordinates, q̇, points, a driver, residuals, rcond, efforts and reactions) and a step whose
  // q holds a −0
  Scene scene = parse_scene(fourbar_scene("{velocities: true, accelerations: true, points: [B, {name: P, body: "
                                          "coupler, at: [0, 0.3]}], drivers: [motor], residuals: [rocker], "
                                          "max_residual: true, rcond: true, efforts: all, power: true, reactions: all}",
                                          4) +
                                "parts: {coupler: {mass: 2.0, center_of_mass: [0.1, 0], inertia: 0.24}}\n"
                                "loads: {gravity: [0, -9.81]}\n",
                            "fourbar.yaml");
  const CsvFormat csv(*scene.model, scene.sweep);
  ASSERT_EQ(csv.num_values(), csv.column_names().size());
  Workspace ws(*scene.model);
  Index rows = 0;
  SweepSummary sum;
  const SolveStatus st = run_sweep(
      *scene.model, scene.sweep, ws,
      [&](const StepView& s) {
        Eigen::VectorXd q = s.q;
        q(0) = -0.0;
        const StepView step{s.step, s.t,     q,        s.qd,           s.qdd,           s.points,
                            s.phi,  s.rcond, s.joints, s.orientations, s.sensitivities, s.efforts};
        std::string text;
        csv.append_row(step, text);
        std::vector<double> values(csv.num_values() + 1, 7.0);  // one past the end: not written
        csv.append_values(step, values.data());
        EXPECT_EQ(values.back(), 7.0);
        std::size_t k = 0;
        for (const char* p = text.data(); *p != '\n'; ++k) {
          double read = 0.0;
          const auto [end, ec] = std::from_chars(p, text.data() + text.size(), read);
          EXPECT_EQ(ec, std::errc());
          EXPECT_EQ(std::bit_cast<std::uint64_t>(values[k]), std::bit_cast<std::uint64_t>(read))
              << "column " << csv.column_names()[k] << " at step " << s.step;
          p = *end == ',' ? end + 1 : end;
        }
        EXPECT_EQ(k, csv.num_values());
        EXPECT_FALSE(std::signbit(values[1]));  // −0 as the text writes it: 0
        // the values after the coordinates' straight into uneven slices (a writer's datasets), a run of efforts
        // split across two: the same bits
        const std::size_t n = csv.num_output_values(), first = csv.num_values() - n;
        EXPECT_GT(n, 4u);
        if (n <= 4) return false;
        std::vector<double> sliced(n + 1, 7.0);
        const std::size_t sizes[4] = {1, 0, n - 3, 2};
        double* const out[4] = {sliced.data(), sliced.data() + 1, sliced.data() + 1, sliced.data() + n - 2};
        csv.append_output_values(step, out, sizes, 4);
        EXPECT_EQ(sliced.back(), 7.0);
        for (std::size_t i = 0; i < n; ++i)
          EXPECT_EQ(std::bit_cast<std::uint64_t>(sliced[i]), std::bit_cast<std::uint64_t>(values[first + i]))
              << "column " << csv.column_names()[first + i] << " at step " << s.step;
        ++rows;
        return true;
      },
      &sum);
  ASSERT_EQ(st, SolveStatus::kSuccess) << sum.message;
  EXPECT_EQ(rows, 5);
}

// The text a row's values should have: shortest round-trip (std::to_chars), −0 written as 0, one value at a time.
std::string reference_row(double t, const std::vector<const Eigen::VectorXd*>& groups, const std::vector<Index>& cols) {
  auto text = [](double v) {
    char buf[64];
    if (v == 0.0) v = 0.0;
    return std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
  };
  std::string r = text(t);
  for (const Eigen::VectorXd* g : groups)
    for (Index j : cols) r.append(",").append(text((*g)(j)));
  return r + "\n";
}

TEST(CsvFormat, WideRowsFormattedInParallelReadAsTheSequentialText) {
  // 4 003 coordinates: q, q̇, q̈ make 12 009 values, twelve blocks of the parallel formatting (the last one short)
  const Model m = test::nfourbar_model(2000, M_PI / 4, 1.0);
  const Index n = m.num_coordinates();
  ASSERT_EQ(n, 4003);
  // values of every shape: −0, signed, tiny, huge, subnormal, integers, 17 significant digits
  Eigen::VectorXd q(n), qd(n), qdd(n);
  const double special[] = {-0.0,
                            0.0,
                            1.0,
                            -2.5,
                            1e-300,
                            -1.7976931348623157e308,
                            4.9406564584124654e-324,
                            0.1,
                            1.0 / 3.0,
                            -123456789.0,
                            2.2250738585072014e-308};
  for (Index j = 0; j < n; ++j) {
    q(j) = j < 11 ? special[j] : std::sin(0.37 * static_cast<double>(j)) * std::pow(10.0, j % 40 - 20);
    qd(j) = -std::cos(1.3 * static_cast<double>(j)) * (1 + j);
    qdd(j) = j % 7 == 0 ? -0.0 : 1.0 / (1.0 + static_cast<double>(j));
  }
  // every column, then a subset in scrambled order (the blocks' boundaries fall inside a group, at other columns)
  std::vector<Index> all(static_cast<std::size_t>(n)), some;
  for (Index j = 0; j < n; ++j) all[static_cast<std::size_t>(j)] = j;
  for (Index j = n - 1; j >= 0; j -= 3) some.push_back(j);
  for (Index j = 1; j < n; j += 5) some.push_back(j);
  const StepView step{3, 0.125, q, &qd, &qdd};
  for (const std::vector<Index>* cols : {&all, &some}) {
    for (const auto& [v, a] : {std::pair{true, true}, std::pair{false, true}, std::pair{false, false}}) {
      const CsvFormat csv(m, *cols, v, a);
      std::vector<const Eigen::VectorXd*> groups{&q};
      if (v) groups.push_back(&qd);
      if (a) groups.push_back(&qdd);
      const std::string expected = reference_row(0.125, groups, *cols);
      for (int threads : {1, 2, 4}) {
        // after earlier text, as the CLI's buffer holds the rows before it
        std::string out = "earlier row\n";
        tbb::task_arena(threads).execute([&] {
          csv.append_row(step, out);
          csv.append_row(step, out);
        });
        EXPECT_EQ(out, "earlier row\n" + expected + expected)
            << cols->size() << " columns, v " << v << ", a " << a << ", " << threads << " threads";
      }
    }
  }
  // a narrow row (one block) too, and the pre-conditions
  const CsvFormat narrow(m, {0, 1, 4002}, true, true);
  std::string out;
  narrow.append_row(step, out);
  EXPECT_EQ(out, reference_row(0.125, {&q, &qd, &qdd}, {0, 1, 4002}));
  out.clear();
  CsvFormat(m, {0, 2, 3, 4, 6, 8, 5}, false, false).append_row(step, out);
  EXPECT_EQ(out, "0.125,0,1,-2.5,1e-300,5e-324,0.3333333333333333,-1.7976931348623157e+308\n");
  const CsvFormat wide(m, all, true, true);
  EXPECT_THROW(wide.append_row(StepView{0, 0.0, q, nullptr, &qdd}, out), Error);
  const Eigen::VectorXd shorter = q.head(n - 1);
  EXPECT_THROW(wide.append_row(StepView{0, 0.0, shorter, &qd, &qdd}, out), Error);
}

TEST(OutputPlan, BadOutputListsAreOneLineErrorsNamingTheField) {
  auto error_of = [](const std::string& output) {
    try {
      parse_scene(fourbar_scene(output), "fourbar.yaml");
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("{points: [Q]}").find("output.points[0]: unknown point 'Q'"), std::string::npos)
      << error_of("{points: [Q]}");
  EXPECT_NE(error_of("{points: [{name: P, body: crank}]}").find("unknown body 'crank'"), std::string::npos);
  EXPECT_NE(error_of("{points: [A, A]}").find("listed twice"), std::string::npos);
  EXPECT_NE(error_of("{drivers: [crank]}").find("unknown driver 'crank'"), std::string::npos);
  EXPECT_NE(error_of("{residuals: [nothing]}").find("unknown constraint or driver 'nothing'"), std::string::npos);
  EXPECT_NE(error_of("{rcond: maybe}").find("output.rcond"), std::string::npos) << error_of("{rcond: maybe}");
  EXPECT_NE(error_of("{pionts: [A]}").find("pionts"), std::string::npos);
  // today's form keeps working: no points, no residuals, all coordinates
  Scene s = parse_scene(fourbar_scene("{velocities: true, accelerations: true}"), "fourbar.yaml");
  EXPECT_TRUE(s.sweep.points.empty());
  EXPECT_FALSE(s.sweep.residuals || s.sweep.condition);
  EXPECT_EQ(s.sweep.coordinate_columns.size(), 8u);
}

// The drawing's lines come from the constraints: each bar once, body arms to their pair attachments.
TEST(MechanismSketch, LinesFollowTheConstraintsEachOnce) {
  // natural four-bar: crank O–A is named twice (distance and segment angle), drawn once
  Scene natural = load_scene(test::model_path("seed/fourbar_natural.yaml"));
  const std::vector<SketchSegment> n = sketch_segments(*natural.model);
  ASSERT_EQ(n.size(), 3u);
  // at the assembled position the lines have the links' lengths: crank 0.4, coupler 1.2, rocker 1.0
  Workspace ws(*natural.model);
  ASSERT_EQ(solve_position(*natural.model, 0.0, natural.sweep.assembly, ws), SolveStatus::kSuccess);
  std::vector<double> lengths;
  for (const SketchSegment& s : n) {
    const PointMotion a = evaluate_point(s.from, ws.q.data(), nullptr, nullptr),
                      b = evaluate_point(s.to, ws.q.data(), nullptr, nullptr);
    lengths.push_back(std::hypot(b.r[0] - a.r[0], b.r[1] - a.r[1]));
  }
  std::sort(lengths.begin(), lengths.end());
  EXPECT_NEAR(lengths[0], 0.4, 1e-9);
  EXPECT_NEAR(lengths[1], 1.0, 1e-9);
  EXPECT_NEAR(lengths[2], 1.2, 1e-9);
  // mixed: the coupler body is drawn as two arms from its reference point to the revolutes (0.6 each)
  Scene mixed = load_scene(test::model_path("seed/fourbar_mixed.yaml"));
  const std::vector<SketchSegment> m = sketch_segments(*mixed.model);
  ASSERT_EQ(m.size(), 4u);
  int arms = 0;
  for (const SketchSegment& s : m)
    if (s.to.kind == OutputPointKind::kPlanarBodyPoint) {
      ++arms;
      EXPECT_DOUBLE_EQ(std::hypot(s.to.local_x, s.to.local_y), 0.6);
    }
  EXPECT_EQ(arms, 2);
}

// The joints: a pivot per revolute pair, on ground where a side is ground (still), each with its constraint; the
// spatial kinds draw their bars, arms and joints too.
TEST(MechanismSketch, JointsAndSpatialLinks) {
  Scene ref = load_scene(test::model_path("seed/fourbar_reference_point.yaml"));
  const MechanismSketch r = sketch_mechanism(*ref.model);
  ASSERT_EQ(r.joints.size(), 4u);
  std::vector<std::string> names;
  for (const SketchJoint& j : r.joints) {
    names.push_back(ref.model->constraints()[static_cast<std::size_t>(j.constraint)].name);
    EXPECT_EQ(j.mark, JointMark::kRevolute);
    EXPECT_EQ(j.fixed, names.back() == "O" || names.back() == "C") << names.back();
  }
  EXPECT_EQ(names, (std::vector<std::string>{"O", "A", "B", "C"}));
  // ground pivots at their places: O (0, 0), C (L1, 0)
  const PointMotion c = evaluate_point(r.joints[3].at, ref.model->initial_positions().data(), nullptr, nullptr);
  EXPECT_EQ(c.r[0], 1.0);
  EXPECT_EQ(c.r[1], 0.0);
  // rssr: the coupler's bar and the arms to its ends; two ground hinges; the bar's two ends
  Scene rssr = load_scene(test::model_path("spatial/rssr.yaml"));
  const MechanismSketch s = sketch_mechanism(*rssr.model);
  ASSERT_EQ(s.segments.size(), 3u);
  EXPECT_EQ(s.segments[0].line, SketchLine::kBar);
  EXPECT_EQ(rssr.model->constraints()[static_cast<std::size_t>(s.segments[0].constraint)].name, "coupler");
  Workspace ws(*rssr.model);
  ASSERT_EQ(solve_position(*rssr.model, 0.0, rssr.sweep.assembly, ws), SolveStatus::kSuccess);
  const PointMotion a = evaluate_point(s.segments[0].from, ws.q.data(), nullptr, nullptr),
                    b = evaluate_point(s.segments[0].to, ws.q.data(), nullptr, nullptr);
  EXPECT_NEAR(std::hypot(b.r[0] - a.r[0], b.r[1] - a.r[1], b.r[2] - a.r[2]), 0.92, 1e-9);
  ASSERT_EQ(s.joints.size(), 4u);
  int hinges = 0, ends = 0;
  for (const SketchJoint& j : s.joints) {
    if (j.mark == JointMark::kRevolute) {
      ++hinges;
      EXPECT_TRUE(j.fixed);
    }
    if (j.mark == JointMark::kPoint) {
      ++ends;
      EXPECT_FALSE(j.fixed);
    }
  }
  EXPECT_EQ(hinges, 2);
  EXPECT_EQ(ends, 2);
  // the scene keeps its moving bodies' frames, in the order of the model's body names
  ASSERT_EQ(rssr.spatial_bodies.size(), 2u);
  EXPECT_EQ(rssr.model->body_names(), (std::vector<std::string>{"crank", "rocker"}));
  EXPECT_EQ(rssr.spatial_bodies[1].e0.coord(), rssr.model->coordinate_index("rocker_e0"));
  EXPECT_EQ(ref.planar_bodies.size(), 3u);
  EXPECT_EQ(ref.planar_bodies[2].psi.coord(), ref.model->coordinate_index("psi4"));
  EXPECT_EQ(rssr.dimension, 3);
  EXPECT_EQ(ref.dimension, 2);
}

TEST(FormatTime, TenSignificantDigitsWhateverTheScale) {
  EXPECT_EQ(format_time(1e-7), "1e-07");
  EXPECT_EQ(format_time(0.6000000000000001), "0.6");
  EXPECT_EQ(format_time(0), "0");
  EXPECT_EQ(format_time(-1.0471975511965976), "-1.047197551");
  EXPECT_EQ(format_time(std::numeric_limits<double>::infinity()), "inf");
}

}  // namespace
}  // namespace phiq
