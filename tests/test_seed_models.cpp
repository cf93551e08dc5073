// The notes' examples in models/seed/, loaded from their scene files, against closed forms and each other.
#include <gtest/gtest.h>

#include <cmath>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

using test::angle_diff;

Scene load(const std::string& name) { return load_scene(test::model_path("seed/" + name)); }

struct SeedAngles {
  double crank, coupler, rocker;  // absolute: crank O→A, coupler A→B, rocker C→B
};

// Crank, coupler and rocker angles from each formulation's coordinates.
SeedAngles angles_of(const std::string& formulation, const Model& m, const Eigen::VectorXd& q) {
  auto c = [&](const char* n) { return q(m.coordinate_index(n)); };
  const double L1 = 1.0;
  if (formulation == "relative") return {c("psi2"), c("psi2") + c("psi3"), c("psi2") + c("psi3") + c("psi4") + M_PI};
  if (formulation == "reference_point") return {c("psi2"), c("psi3"), c("psi4")};
  if (formulation == "natural")
    return {c("theta2"), std::atan2(c("yB") - c("yA"), c("xB") - c("xA")), std::atan2(c("yB"), c("xB") - L1)};
  return {c("theta2"), c("psi3"), std::atan2(c("yB"), c("xB") - L1)};  // mixed
}

TEST(SeedModels, FourFourBarFormulationsAgreeOverAFullTurn) {
  const char* forms[] = {"relative", "reference_point", "natural", "mixed"};
  std::vector<test::Trace> traces(4);
  std::vector<Scene> scenes;
  for (int f = 0; f < 4; ++f) {
    scenes.push_back(load(std::string("fourbar_") + forms[f] + ".yaml"));
    SweepSummary s;
    ASSERT_EQ(test::sweep(*scenes[f].model, scenes[f].sweep, &traces[f], &s), SolveStatus::kSuccess)
        << forms[f] << ": " << s.message;
    ASSERT_EQ(traces[f].t.size(), 361u);
    EXPECT_NEAR(traces[f].t.back(), 2 * M_PI, 1e-15);
  }
  double worst = 0.0;
  for (std::size_t k = 0; k < 361; ++k) {
    SeedAngles ref = angles_of(forms[0], *scenes[0].model, traces[0].q[k]);
    EXPECT_NEAR(angle_diff(ref.crank, traces[0].t[k]), 0.0, 1e-12);
    for (int f = 1; f < 4; ++f) {
      SeedAngles a = angles_of(forms[f], *scenes[f].model, traces[f].q[k]);
      worst = std::max({worst, std::fabs(angle_diff(a.crank, ref.crank)), std::fabs(angle_diff(a.coupler, ref.coupler)),
                        std::fabs(angle_diff(a.rocker, ref.rocker))});
    }
  }
  EXPECT_LT(worst, 1e-9);
}

// Freudenstein: K1 cos θ4 − K2 cos θ2 + K3 = cos(θ2 − θ4), K1 = d/a, K2 = d/c, K3 = (a² − b² + c² + d²)/(2ac),
// a crank, b coupler, c rocker, d ground; θ4 the rocker angle at its ground pivot. Solved as a quadratic in
// tan(θ4/2); the two roots are the open and the crossed assembly.
struct Freudenstein {
  double a = 0.4, b = 1.2, c = 1.0, d = 1.0;
  double theta4(double th2, double sign) const {
    const double K1 = d / a, K2 = d / c, K3 = (a * a - b * b + c * c + d * d) / (2 * a * c);
    const double A = std::cos(th2) - K1 - K2 * std::cos(th2) + K3, B = -2 * std::sin(th2),
                 C = K1 - (K2 + 1) * std::cos(th2) + K3;
    return 2 * std::atan2(-B + sign * std::sqrt(B * B - 4 * A * C), 2 * A);
  }
  // dθ4/dθ2 by implicit differentiation of the same equation.
  double ratio(double th2, double th4) const {
    const double K1 = d / a, K2 = d / c;
    return (K2 * std::sin(th2) + std::sin(th2 - th4)) / (K1 * std::sin(th4) + std::sin(th2 - th4));
  }
};

void check_branch(bool crossed) {
  Scene s = load("fourbar_natural.yaml");
  const Model& m = *s.model;
  Workspace ws(m);
  if (crossed) ws.q(m.coordinate_index("yB")) = -1.0;  // rough placement below the ground line
  test::Trace tr;
  SweepSummary sum;
  ASSERT_EQ(test::sweep(m, s.sweep, &tr, &sum, &ws), SolveStatus::kSuccess) << sum.message;
  Freudenstein fr;
  const double sign = crossed ? 1.0 : -1.0;
  double worst_pos = 0, worst_vel = 0;
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    const Eigen::VectorXd& q = tr.q[k];
    const double th2 = q(m.coordinate_index("theta2"));
    const double th4 = std::atan2(q(m.coordinate_index("yB")), q(m.coordinate_index("xB")) - fr.d);
    worst_pos = std::max(worst_pos, std::fabs(angle_diff(th4, fr.theta4(th2, sign))));
    // rocker angular velocity: θ̇4 = (dθ4/dθ2) θ̇2, with θ̇4 from the natural velocities of B
    const double xb = q(m.coordinate_index("xB")) - fr.d, yb = q(m.coordinate_index("yB"));
    const double vx = tr.qd[k](m.coordinate_index("xB")), vy = tr.qd[k](m.coordinate_index("yB"));
    const double w4 = (xb * vy - yb * vx) / (xb * xb + yb * yb);
    worst_vel = std::max(worst_vel, std::fabs(w4 - fr.ratio(th2, th4) * tr.qd[k](m.coordinate_index("theta2"))));
  }
  // to the Newton tolerance: 1e-10 × the length scale (1.2 m, the coupler) on positions, over a 1 m rocker
  EXPECT_LT(worst_pos, 1.2e-10 * 1.2) << (crossed ? "crossed" : "open");
  EXPECT_LT(worst_vel, 1e-9) << (crossed ? "crossed" : "open");
}

TEST(SeedModels, FourBarMatchesFreudensteinOpenBranch) { check_branch(false); }
TEST(SeedModels, FourBarMatchesFreudensteinCrossedBranch) { check_branch(true); }

TEST(SeedModels, CrankSliderSceneMatchesClosedForm) {
  const double L2 = 0.3, L3 = 1.0;
  for (const char* file : {"crank_slider_mixed.yaml", "crank_slider_equations.yaml"}) {
    Scene s = load(file);
    const Model& m = *s.model;
    ASSERT_EQ(m.coordinate_names(), (std::vector<std::string>{"theta2", "xA", "yA", "xB"}));
    EXPECT_EQ(s.sweep.steps, 180);
    EXPECT_DOUBLE_EQ(s.sweep.t_end, M_PI);
    test::Trace tr;
    SweepSummary sum;
    ASSERT_EQ(test::sweep(m, s.sweep, &tr, &sum), SolveStatus::kSuccess) << file << ": " << sum.message;
    ASSERT_EQ(tr.t.size(), 181u);
    double wx = 0, wv = 0, wa = 0;
    for (std::size_t k = 0; k < tr.t.size(); ++k) {
      const double th = 2 * tr.t[k], w = 2;
      const double sn = std::sin(th), cs = std::cos(th);
      const double S = std::sqrt(L3 * L3 - L2 * L2 * sn * sn);
      const double x = L2 * cs + S;
      // ẋ and ẍ differentiated by hand in t (θ = 2t)
      const double v = -L2 * w * sn - L2 * L2 * w * sn * cs / S;
      const double a = -L2 * w * w * cs - L2 * L2 * w * w * (cs * cs - sn * sn) / S -
                       std::pow(L2 * L2 * w * sn * cs, 2) / (S * S * S);
      wx = std::max(wx, std::fabs(tr.q[k](3) - x));
      wv = std::max(wv, std::fabs(tr.qd[k](3) - v));
      wa = std::max(wa, std::fabs(tr.qdd[k](3) - a));
    }
    EXPECT_LT(wx, 1e-8) << file;
    EXPECT_LT(wv, 1e-8) << file;
    EXPECT_LT(wa, 1e-8) << file;
  }
}

}  // namespace
}  // namespace phiq

namespace phiq {
namespace {

// The Grübler–Kutzbach count is defined for the formulation made of bodies and joints only: 3 · 3 − 4 · 2 = 1 for
// the reference-point four-bar; the natural, mixed (a body pinned to natural points) and relative ones are not
// made of joints, and the count is null.
TEST(SeedModels, GrublerOfTheFourBarFormulations) {
  const Scene rp = load_scene(test::model_path("seed/fourbar_reference_point.yaml"));
  ASSERT_TRUE(rp.model->grubler().has_value());
  EXPECT_EQ(*rp.model->grubler(), 1);
  EXPECT_EQ(rp.model->body_names(), (std::vector<std::string>{"crank", "coupler", "rocker"}));
  for (const char* f : {"fourbar_natural.yaml", "fourbar_mixed.yaml", "fourbar_relative.yaml",
                        "crank_slider_mixed.yaml", "crank_slider_equations.yaml"})
    EXPECT_FALSE(load_scene(test::model_path(std::string("seed/") + f)).model->grubler().has_value()) << f;
}

}  // namespace
}  // namespace phiq
