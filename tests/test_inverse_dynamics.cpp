// Inverse dynamics (phiq/inverse_dynamics.hpp): the notes' four-bar with three massive links under gravity, in
// relative, natural, reference-point and mixed coordinates. Its motor torque is one physical quantity, so the four
// formulations give it alike at every row, and it balances the mechanism's energy: τ θ̇ = d/dt (kinetic +
// potential), the joints doing no work.
#include <gtest/gtest.h>

#include <cmath>

#include "phiq/inverse_dynamics.hpp"
#include "phiq/part_motion.hpp"
#include "phiq/phiq.hpp"
#include "fourbar_parts.hpp"

namespace phiq {
namespace {

TEST(InverseDynamics, TheMotorTorqueIsOneInEveryFormulationAndBalancesTheEnergy) {
  const Loads loads{{0.0, -9.81, 0.0}, nullptr};
  const char* forms[] = {"relative", "natural", "reference_point", "mixed"};
  std::vector<std::vector<double>> torque(4);
  for (int f = 0; f < 4; ++f) {
    const std::string form = forms[f];
    Scene s = parse_scene(
        test::model_file_text("seed/fourbar_" + form + ".yaml") + "\nparts:\n" + test::fourbar_parts(form), form);
    const Model& m = *s.model;
    test::Trace tr;
    ASSERT_EQ(test::sweep(m, s.sweep, &tr), SolveStatus::kSuccess) << forms[f];
    Workspace ws(m);
    const Index motor = m.constraint("motor").first_row;
    double balance = 0.0, scale = 0.0;
    for (std::size_t k = 0; k < tr.t.size(); ++k) {
      const double t = tr.t[k];
      ws.q = tr.q[k], ws.qd = tr.qd[k], ws.qdd = tr.qdd[k];
      Eigen::VectorXd Q = Eigen::VectorXd::Zero(m.num_coordinates()), lambda;
      add_generalized_forces(s.parts, loads, ws.q.data(), ws.qd.data(), ws.qdd.data(), t, Q);
      std::string why;
      ASSERT_EQ(constraint_multipliers(m, t, ws, Q, lambda, &why), SolveStatus::kSuccess) << why;
      const double tau = -lambda(motor);
      torque[f].push_back(tau);
      // d/dt of the kinetic and potential energy, from each part's motion
      double power = 0.0;
      for (const Part& p : s.parts) {
        const PartMotion pm = part_motion(p.frame, ws.q.data(), ws.qd.data(), ws.qdd.data(), t);
        const auto [v, a] = pm.point(p.mass.center);
        power += p.mass.mass * kin3::dot(v, a) + p.mass.inertia[8] * pm.omega.z * pm.alpha.z -
                 p.mass.mass * kin3::dot(loads.gravity, v);
      }
      balance = std::max(balance, std::fabs(tau * 1.0 - power));  // θ̇ = 1 rad/s
      scale = std::max(scale, std::fabs(tau));
    }
    EXPECT_GT(scale, 1.0) << forms[f];  // gravity and inertia load the motor: a torque of newton-metres
    EXPECT_LT(balance, 1e-9 * scale) << forms[f];
  }
  double worst = 0.0;
  for (int f = 1; f < 4; ++f)
    for (std::size_t k = 0; k < torque[0].size(); ++k) worst = std::max(worst, std::fabs(torque[f][k] - torque[0][k]));
  EXPECT_LT(worst, 1e-7);  // four solutions of one motion, each to the solver's tolerance
}

}  // namespace
}  // namespace phiq
