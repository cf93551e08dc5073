// `phiq generate chain3d`: a row of N spatial loops in natural and reference-point coordinates. The scene is square
// with the stated counts (natural n = 3N + 4, 3N + 3 kinematic equations + 1 driver; reference-point n = 7N + 7,
// 7N + 6 kinematic equations + 1 driver), of one degree of freedom by the rank analysis at its rough placement and
// at the assembled position, starts off the solution (the first solve is an assembly), and its sweep follows the
// closed form (tools::ClosedForm "chain3d") in positions, velocities and accelerations at every step: the
// parallelogram row over the default quarter turn, the twisted row (--twist) over two full turns.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "chain3d_geometry.hpp"
#include "closed_forms.hpp"
#include "generate.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

using tools::GenerateOptions;

GenerateOptions chain3d(std::int64_t n, const std::string& coords, std::int64_t steps = 24, double twist = 0.0,
                        double from = M_PI / 4, double to = 3 * M_PI / 4) {
  GenerateOptions o = test::generate_options("chain3d", n, coords, from, to, steps);
  o.twist = twist;
  return o;
}

std::unique_ptr<tools::ClosedForm> exact(const GenerateOptions& o, const Model& m) {
  char spec[160];
  std::snprintf(spec, sizeof spec, "chain3d:from=%.17g,to=%.17g,twist=%.17g", o.from, o.to, o.twist);
  auto f = tools::make_closed_form(spec);
  f->bind(m.coordinate_names());
  return f;
}

// The rank analysis at q: one degree of freedom, driven, nothing redundant; the Grübler count where it is defined.
void expect_one_dof(const Model& m, const Eigen::VectorXd& q, bool bodies, const char* where) {
  const RankReport r = analyse_rank(m, q, 0.0);
  EXPECT_EQ(r.rank, m.num_coordinates() - 1) << where;
  EXPECT_EQ(r.dof, 1) << where;
  EXPECT_EQ(r.driven_dof, 0) << where;
  EXPECT_TRUE(r.redundant.empty()) << where;
  EXPECT_FALSE(r.uncertain) << where << ": " << r.message;
  if (bodies) {
    ASSERT_TRUE(r.grubler.has_value());
    EXPECT_EQ(*r.grubler, 1);  // 6 (N + 1) − 5 (N + 1) hinges − N couplers
  } else {
    EXPECT_FALSE(r.grubler.has_value());  // natural points: no joints between bodies
  }
}

// Generates, loads, checks the counts, the rough placement and the rank, sweeps and compares every row with the
// closed form.
void expect_closed_form_motion(const GenerateOptions& o) {
  SCOPED_TRACE("chain3d " + std::to_string(o.n) + " " + o.coords + " twist " + std::to_string(o.twist));
  const Scene scene = parse_scene(tools::generate_scene(o), "chain3d.yaml");
  const Model& m = *scene.model;
  const bool bodies = o.coords == "reference-point";
  const Index n = o.n;
  const Index coordinates = bodies ? 7 * n + 7 : 3 * n + 4, kinematic = bodies ? 7 * n + 6 : 3 * n + 3;
  EXPECT_EQ(m.num_coordinates(), coordinates);
  EXPECT_EQ(m.num_equations(), coordinates);  // square
  Index kin = 0, drivers = 0;
  for (const ConstraintInfo& c : m.constraints()) (c.depends_on_time ? drivers : kin) += c.rows;
  EXPECT_EQ(kin, kinematic);
  EXPECT_EQ(drivers, 1);
  EXPECT_EQ(scene.sweep.steps, o.steps);

  auto f = exact(o, m);
  ASSERT_EQ(f->size(), static_cast<std::size_t>(coordinates));  // the closed form covers every coordinate
  // The rough placement is off the solution at t = 0 by about a hundredth (the sweep starts with an assembly).
  const auto nq = static_cast<std::size_t>(coordinates);
  std::vector<double> q0(nq), v0(nq), a0(nq);
  f->evaluate(0.0, q0.data(), v0.data(), a0.data());
  double off = 0.0;
  for (std::size_t j = 0; j < nq; ++j)
    off = std::max(off, std::fabs(m.initial_positions()(static_cast<Index>(j)) - q0[j]));
  EXPECT_GT(off, 5e-3);
  EXPECT_LT(off, 0.05);
  expect_one_dof(m, m.initial_positions(), bodies, "rough placement");

  test::Trace trace;
  SweepSummary summary;
  ASSERT_EQ(test::sweep(m, scene.sweep, &trace, &summary), SolveStatus::kSuccess) << summary.message;
  EXPECT_TRUE(summary.warnings.empty());
  ASSERT_EQ(trace.t.size(), static_cast<std::size_t>(o.steps + 1));
  ASSERT_EQ(trace.qd.size(), trace.t.size());
  ASSERT_EQ(trace.qdd.size(), trace.t.size());
  expect_one_dof(m, trace.q[0], bodies, "assembled");
  tools::ClosedFormErrors err(*f);
  for (std::size_t k = 0; k < trace.t.size(); ++k)
    err.add(trace.t[k], trace.q[k].data(), trace.qd[k].data(), trace.qdd[k].data());
  // relative to the crank's rate ω (velocities ~ω, accelerations ~ω²; ω = 4π over two turns)
  const double w = std::max(1.0, std::fabs(o.to - o.from));
  EXPECT_LT(err.q_error, 1e-9);
  EXPECT_LT(err.v_error, 1e-9 * w);
  EXPECT_LT(err.a_error, 1e-9 * w * w);
}

TEST(GenerateChain3d, ParallelogramRowFollowsTheClosedForm) {
  for (const char* coords : {"natural", "reference-point"})
    for (std::int64_t n : {1, 3, 50}) expect_closed_form_motion(chain3d(n, coords));
}

TEST(GenerateChain3d, TwistedRowRunsThroughTwoFullTurns) {
  // crank 0 from 0 to 4π: the driver and the loops are smooth at every angle
  for (const char* coords : {"natural", "reference-point"})
    for (auto [n, twist] : {std::pair<std::int64_t, double>{1, 2.0}, {4, -2.5}, {20, M_PI / 2}})
      expect_closed_form_motion(chain3d(n, coords, 160, twist, 0.0, 4 * M_PI));
}

// The frame of chain3d_geometry.hpp: u ⟂ d, e2 = u × d, and the Euler parameters p(θ) = cos(θ/2) qa + sin(θ/2) qb
// turn the body axes x, z onto c(θ) = cos θ e1 + sin θ e2 and u (phiq's R(p), spatial_attachment.hpp).
TEST(GenerateChain3d, GeometryIsAnOrthonormalFrameWithItsEulerParameters) {
  const tools::chain3d::Geometry g = tools::chain3d::geometry();
  using tools::chain3d::dot;
  EXPECT_NEAR(dot(g.u, g.e1), 0.0, 1e-16);
  for (const auto& v : {g.u, g.e1, g.e2}) EXPECT_NEAR(dot(v, v), 1.0, 1e-15);
  for (int k = 0; k < 3; ++k) EXPECT_NE(std::fabs(g.u[static_cast<std::size_t>(k)]), 1.0);  // not a coordinate axis
  auto rotate = [](const tools::chain3d::Quat& p, const tools::chain3d::Vec& s) {           // R(p) s
    const tools::chain3d::Vec e{p[1], p[2], p[3]}, exs = tools::chain3d::cross(e, s);
    const double c = p[0] * p[0] - dot(e, e), es = dot(e, s);
    tools::chain3d::Vec r;
    for (std::size_t k = 0; k < 3; ++k) r[k] = c * s[k] + 2 * es * e[k] + 2 * p[0] * exs[k];
    return r;
  };
  for (double th : {0.0, 0.7, 2.0, -2.9, 5.5}) {
    tools::chain3d::Quat p;
    for (std::size_t k = 0; k < 4; ++k) p[k] = std::cos(th / 2) * g.qa[k] + std::sin(th / 2) * g.qb[k];
    const tools::chain3d::Vec x = rotate(p, {1, 0, 0}), z = rotate(p, {0, 0, 1});
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_NEAR(x[k], std::cos(th) * g.e1[k] + std::sin(th) * g.e2[k], 1e-15) << th;
      EXPECT_NEAR(z[k], g.u[k], 1e-15) << th;
    }
  }
}

TEST(GenerateChain3d, HeaderCountsAndASizeIndependentOfN) {
  EXPECT_NE(tools::generate_scene(chain3d(5, "natural"))
                .find("# Counts: 19 coordinates, 18 kinematic equations + 1 driver = 19 equations; 1 dof\n"),
            std::string::npos);
  EXPECT_NE(tools::generate_scene(chain3d(5, "reference-point"))
                .find("# Counts: 42 coordinates, 41 kinematic equations + 1 driver = 42 equations; 1 dof\n"),
            std::string::npos);
  for (const char* coords : {"natural", "reference-point"})
    for (double twist : {0.0, 1.0}) {
      auto size = [&](std::int64_t n) { return tools::generate_scene(chain3d(n, coords, 10, twist)).size(); };
      EXPECT_LT(size(1000000) - size(10), 100u) << coords;  // a few more digits in the counts and N
      EXPECT_LT(size(tools::max_n(chain3d(1, coords, 10, twist))), 4096u) << coords;
    }
}

TEST(GenerateChain3d, RefusesSingularRangesAndTwists) {
  const auto message = test::generate_error;
  // the parallelogram row is singular where the cranks lie along the row: a multiple of π in the driven range
  for (auto [from, to] : {std::pair{0.0, 1.0}, {1.0, M_PI}, {-0.1, 0.1}, {3.0, 3.5}, {2.0, 7.0}})
    EXPECT_NE(message(chain3d(3, "natural", 10, 0.0, from, to)).find("multiple of pi"), std::string::npos) << from;
  for (auto [from, to] : {std::pair{0.1, 3.0}, {3.2, 6.2}, {-0.1, -3.0}})
    EXPECT_EQ(message(chain3d(3, "reference-point", 10, 0.0, from, to)), "(no error)") << from;
  // the twisted row is singular when neighbouring cranks are parallel or opposite; any range is fine otherwise
  for (double twist : {1e-3, M_PI, -2 * M_PI, double(NAN)})
    EXPECT_NE(message(chain3d(3, "natural", 10, twist)).find("--twist"), std::string::npos) << twist;
  EXPECT_EQ(message(chain3d(3, "natural", 10, 1.0, -20.0, 20.0)), "(no error)");
  GenerateOptions o = chain3d(3, "natural", 10, 1.0);
  o.kind = "nfourbar";
  EXPECT_EQ(message(o), "--twist applies to chain3d only");
}

}  // namespace
}  // namespace phiq
