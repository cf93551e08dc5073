// Inverse dynamics (phiq/inverse_dynamics.hpp): the notes' four-bar with three massive links under gravity, in
// relative, natural, reference-point and mixed coordinates. Its motor torque is one physical quantity, so the four
// formulations give it alike at every row, and it balances the mechanism's energy: τ θ̇ = d/dt (kinetic +
// potential), the joints doing no work.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "phiq/inverse_dynamics.hpp"
#include "phiq/part_motion.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

std::string seed_text(const std::string& name) {
  std::ifstream in(test::model_path("seed/" + name));
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Mass properties of the three links (kg, kg·m² about the centre), the centre at each link's middle.
const std::string kCrank = "mass: 1.0, inertia: 1.0*L2*L2/12";
const std::string kCoupler = "mass: 2.0, inertia: 2.0*L3*L3/12";
const std::string kRocker = "mass: 1.5, inertia: 1.5*L4*L4/12";

std::string parts_of(const std::string& form) {
  auto on_frame = [](const std::string& name, const std::string& frame, const std::string& half,
                     const std::string& mass) {
    return "  " + name + ": {frame: " + frame + ", center_of_mass: [" + half + ", 0], " + mass + "}\n";
  };
  auto on_body = [](const std::string& name, const std::string& mass) {
    return "  " + name + ": {center_of_mass: [0, 0], " + mass + "}\n";
  };
  if (form == "relative")
    return on_frame("crank", "{at: [0, 0], angle: psi2}", "L2/2", kCrank) +
           on_frame("coupler", "{at: [L2*cos(psi2), L2*sin(psi2)], angle: psi2 + psi3}", "L3/2", kCoupler) +
           on_frame("rocker",  // the loop's third link runs from B to C
                    "{at: [L2*cos(psi2) + L3*cos(psi2 + psi3), L2*sin(psi2) + L3*sin(psi2 + psi3)], "
                    "angle: psi2 + psi3 + psi4}",
                    "L4/2", kRocker);
  if (form == "natural")
    return on_frame("crank", "{origin: O, x: A}", "L2/2", kCrank) +
           on_frame("coupler", "{origin: A, x: B}", "L3/2", kCoupler) +
           on_frame("rocker", "{origin: C, x: B}", "L4/2", kRocker);
  if (form == "reference_point")
    return on_body("crank", kCrank) + on_body("coupler", kCoupler) + on_body("rocker", kRocker);
  return on_frame("crank", "{origin: O, x: A}", "L2/2", kCrank) + on_body("coupler", kCoupler) +
         on_frame("rocker", "{origin: C, x: B}", "L4/2", kRocker);  // mixed
}

TEST(InverseDynamics, TheMotorTorqueIsOneInEveryFormulationAndBalancesTheEnergy) {
  const Loads loads{{0.0, -9.81, 0.0}};
  const char* forms[] = {"relative", "natural", "reference_point", "mixed"};
  std::vector<std::vector<double>> torque(4);
  for (int f = 0; f < 4; ++f) {
    Scene s = parse_scene(seed_text(std::string("fourbar_") + forms[f] + ".yaml") + "\nparts:\n" + parts_of(forms[f]),
                          forms[f]);
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
