// The closed forms of `phiq sweep-accuracy` (tools/accuracy/closed_forms.hpp): their positions satisfy the mechanism's
// geometry, their velocities and accelerations are the time derivatives of their positions (central differences),
// and phiq at tolerance 1e-12 agrees with them on every seed scene and on both nfourbar formulations.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>

#include "closed_forms.hpp"
#include "generate.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

using tools::make_closed_form;

struct State {
  std::vector<double> q, v, a;
};
State eval(const tools::ClosedForm& f, std::size_t n, double t) {
  State s{std::vector<double>(n), std::vector<double>(n), std::vector<double>(n)};
  f.evaluate(t, s.q.data(), s.v.data(), s.a.data());
  return s;
}

// Velocities and accelerations against central differences of the positions, for every bound coordinate.
void expect_derivatives_of_positions(const tools::ClosedForm& f, std::size_t n, double t0, double t1) {
  const double h = 1e-4;  // truncation ~h²·|q⁗|/12 ≈ 1e-9, rounding ~1e-16/h² = 1e-8 on the second difference
  double worst_v = 0, worst_a = 0;
  for (int k = 0; k <= 16; ++k) {
    const double t = t0 + (t1 - t0) * k / 16.0;
    const State m = eval(f, n, t - h), c = eval(f, n, t), p = eval(f, n, t + h);
    for (std::size_t j = 0; j < n; ++j) {
      worst_v = std::max(worst_v, std::fabs((p.q[j] - m.q[j]) / (2 * h) - c.v[j]));
      worst_a = std::max(worst_a, std::fabs((p.q[j] - 2 * c.q[j] + m.q[j]) / (h * h) - c.a[j]));
    }
  }
  EXPECT_LT(worst_v, 1e-7) << f.describe();
  EXPECT_LT(worst_a, 1e-5) << f.describe();
  EXPECT_GT(worst_v, 0.0);  // the comparison happened on moving coordinates (differences are never exact)
}

TEST(ClosedForms, FourBarPositionsCloseTheLoopOnBothBranches) {
  for (double branch : {1.0, -1.0}) {
    auto f = make_closed_form("fourbar:branch=" + std::to_string(static_cast<int>(branch)));
    f->bind({"xA", "yA", "xB", "yB", "theta2"});
    for (int k = 0; k < 24; ++k) {
      const State s = eval(*f, 5, 2 * M_PI * k / 24);
      EXPECT_NEAR(std::hypot(s.q[0], s.q[1]), 0.4, 1e-15);
      EXPECT_NEAR(std::hypot(s.q[2] - s.q[0], s.q[3] - s.q[1]), 1.2, 1e-14);
      EXPECT_NEAR(std::hypot(s.q[2] - 1.0, s.q[3]), 1.0, 1e-14);
      // B lies to the left of A→C on branch +1 (the seed's assembly: above the ground at θ2 = 0)
      const double side = (1.0 - s.q[0]) * (s.q[3] - s.q[1]) - (0.0 - s.q[1]) * (s.q[2] - s.q[0]);
      EXPECT_GT(side * branch, 0.0);
    }
  }
  auto f = make_closed_form("fourbar");
  f->bind({"xA", "yA", "xB", "yB", "theta2"});
  const State s0 = eval(*f, 5, 0.0);  // models/seed/README.md: B = (1.0667, 0.9978) at θ2 = 0
  EXPECT_NEAR(s0.q[2], 1.0 + 0.2 / 3.0, 1e-12);
  EXPECT_NEAR(s0.q[3], std::sqrt(1.44 - 4.0 / 9.0), 1e-12);
}

TEST(ClosedForms, CrankSliderMatchesTheSeedReadmeFormula) {
  auto f = make_closed_form("crank-slider");
  f->bind({"theta2", "xA", "yA", "xB"});
  for (double t : {0.0, 0.3, 1.1, 2.9}) {
    const State s = eval(*f, 4, t);
    const double th = 2 * t;
    EXPECT_DOUBLE_EQ(s.q[0], th);
    EXPECT_NEAR(s.q[3], 0.3 * std::cos(th) + std::sqrt(1.0 - 0.09 * std::sin(th) * std::sin(th)), 1e-15);
    EXPECT_EQ(s.v[0], 2.0);
    EXPECT_EQ(s.a[0], 0.0);
  }
}

TEST(ClosedForms, VelocitiesAndAccelerationsAreTheDerivativesOfThePositions) {
  {
    auto f = make_closed_form("crank-slider:L2=0.25,L3=0.9,theta0=0.4,omega=3");
    f->bind({"theta2", "xA", "yA", "xB"});
    expect_derivatives_of_positions(*f, 4, 0.0, 2.0);
  }
  for (const std::vector<std::string>& names :
       {std::vector<std::string>{"xA", "yA", "xB", "yB", "theta2"},
        std::vector<std::string>{"x2", "y2", "psi2", "x3", "y3", "psi3", "x4", "y4", "psi4"},
        std::vector<std::string>{"psi2", "psi3", "psi4"}}) {
    auto f = make_closed_form("fourbar:omega=1.7,theta0=0.2");
    f->bind(names);
    expect_derivatives_of_positions(*f, names.size(), 0.0, 3.5);
  }
  auto f = make_closed_form("nfourbar:from=0.3,to=2.5");
  f->bind({"x0", "y0", "x7", "y7", "theta", "xc3", "yc3", "psi3", "xk2", "yk2", "phi2"});
  expect_derivatives_of_positions(*f, 11, 0.0, 1.0);
  for (const char* spec : {"chain3d:from=0.3,to=2.5", "chain3d:from=-1,to=2,twist=2"}) {
    auto c = make_closed_form(spec);
    c->bind({"x0", "y3", "z12", "theta", "xc3", "yc0", "zc7", "e0c0", "e1c3", "e2c5", "e3c11"});
    expect_derivatives_of_positions(*c, 11, 0.0, 1.0);
  }
}

TEST(ClosedForms, BadSpecificationsAreRefused) {
  EXPECT_THROW(make_closed_form("pendulum"), std::invalid_argument);
  EXPECT_THROW(make_closed_form("fourbar:L5=1"), std::invalid_argument);
  EXPECT_THROW(make_closed_form("fourbar:L2"), std::invalid_argument);
  EXPECT_THROW(make_closed_form("fourbar:L2=abc"), std::invalid_argument);
  EXPECT_THROW(make_closed_form("fourbar:L2=nan"), std::invalid_argument);
  EXPECT_THROW(make_closed_form("fourbar:branch=0"), std::invalid_argument);
  EXPECT_THROW(make_closed_form("crank-slider:L2=2"), std::invalid_argument);  // the crank would not turn
  auto f = make_closed_form("nfourbar");
  EXPECT_THROW(f->bind({"x0", "zz1"}), std::invalid_argument);
  EXPECT_THROW(f->bind({"x01"}), std::invalid_argument);
  EXPECT_EQ(tools::closed_form_for_scene_name("fourbar_natural"), "fourbar");
  EXPECT_EQ(tools::closed_form_for_scene_name("nfourbar_1000_natural"), "nfourbar");
  EXPECT_EQ(tools::closed_form_for_scene_name("crank_slider_mixed"), "crank-slider");
  EXPECT_EQ(tools::closed_form_for_scene_name("scissor_10_natural"), "");
  EXPECT_EQ(tools::closed_form_for_scene_name("chain3d_10_reference_point"), "chain3d");
  auto c = make_closed_form("chain3d");
  EXPECT_EQ(c->describe(), "chain3d:from=0.7853981633974483,to=2.356194490192345,twist=0");
  for (const char* bad : {"x", "w1", "xk1", "e4c1", "e0c", "e0k1", "psi0"})
    EXPECT_THROW(c->bind({"x0", bad}), std::invalid_argument) << bad;
}

// phiq at tolerance 1e-12 (full Newton) against the closed form at every time point: positions (angles modulo 2π),
// velocities and accelerations, scaled by the model's length scale as sweep-accuracy scales them.
// `place` may change the rough placement first (another assembly branch).
void expect_phiq_matches(const Scene& scene, const std::string& spec,
                         const std::function<void(const Model&, Workspace&)>& place = {}) {
  const Model& m = *scene.model;
  auto f = make_closed_form(spec);
  f->bind(m.coordinate_names());
  SweepOptions o = scene.sweep;
  o.newton.tolerance = o.assembly.tolerance = 1e-12;
  o.newton.jacobian_update = JacobianUpdate::kEveryIteration;
  test::Trace tr;
  SweepSummary sum;
  Workspace ws(m);
  if (place) place(m, ws);
  ASSERT_EQ(test::sweep(m, o, &tr, &sum, &ws), SolveStatus::kSuccess) << scene.name << ": " << sum.message;
  ASSERT_EQ(tr.qd.size(), tr.t.size());
  ASSERT_EQ(tr.qdd.size(), tr.t.size());
  tools::ClosedFormErrors err(*f, m.tolerance_scales().coordinate_scale.data());
  for (std::size_t k = 0; k < tr.t.size(); ++k) err.add(tr.t[k], tr.q[k].data(), tr.qd[k].data(), tr.qdd[k].data());
  EXPECT_LT(err.q_error, 1e-11) << scene.name;
  EXPECT_LT(err.v_error, 1e-10) << scene.name;
  EXPECT_LT(err.a_error, 1e-10) << scene.name;
}

TEST(ClosedForms, PhiqAtTightToleranceMatchesThemOnEverySeedScene) {
  for (const char* file : {"crank_slider_mixed", "crank_slider_equations"})
    expect_phiq_matches(load_scene(test::model_path(std::string("seed/") + file + ".yaml")), "crank-slider");
  for (const char* file : {"fourbar_natural", "fourbar_mixed", "fourbar_reference_point", "fourbar_relative"})
    expect_phiq_matches(load_scene(test::model_path(std::string("seed/") + file + ".yaml")), "fourbar");
}

TEST(ClosedForms, TheFourBarsOtherBranchIsTheMirroredAssembly) {
  const Scene s = load_scene(test::model_path("seed/fourbar_natural.yaml"));
  expect_phiq_matches(s, "fourbar:branch=-1",
                      [](const Model& m, Workspace& ws) { ws.q(m.coordinate_index("yB")) = -1.0; });
  // and the default branch does not describe it: the scene's constraints hold, the coordinates do not
  auto f = make_closed_form("fourbar");
  f->bind(s.model->coordinate_names());
  std::vector<double> q(5), v(5), a(5);
  f->evaluate(0.0, q.data(), v.data(), a.data());
  EXPECT_GT(q[static_cast<std::size_t>(s.model->coordinate_index("yB"))], 0.9);
}

TEST(ClosedForms, PhiqAtTightToleranceMatchesTheNFourBarParallelogram) {
  for (const char* coords : {"natural", "reference-point"}) {
    tools::GenerateOptions g;
    g.kind = "nfourbar";
    g.n = 5;
    g.steps = 40;
    g.from = 0.2;
    g.to = 2.9;
    g.coords = coords;
    expect_phiq_matches(parse_scene(tools::generate_scene(g), "nfourbar_5"), "nfourbar:from=0.2,to=2.9");
  }
}

}  // namespace
}  // namespace phiq
