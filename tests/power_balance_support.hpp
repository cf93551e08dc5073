// The rate of a part's rotational kinetic energy, for the tests that balance a driver's power against the energy's
// rate and the loads' power (test_applied_loads.cpp, test_power_balance.cpp).
#pragma once

#include "phiq/part_motion.hpp"
#include "phiq/parts.hpp"

namespace phiq::test {

// ω · (R I Rᵀ α): the rate of a part's rotational kinetic energy ½ ω · I_world ω (the rate of I_world does no work).
inline double rotational_energy_rate(const Part& p, const PartMotion& pm) {
  const RotationMatrix& r = pm.pose.rotation;
  const kin3::V3 a = pm.alpha;
  const double b[3] = {r[0] * a.x + r[3] * a.y + r[6] * a.z, r[1] * a.x + r[4] * a.y + r[7] * a.z,
                       r[2] * a.x + r[5] * a.y + r[8] * a.z};
  double c[3];
  for (int i = 0; i < 3; ++i)
    c[i] = p.mass.inertia[3 * i] * b[0] + p.mass.inertia[3 * i + 1] * b[1] + p.mass.inertia[3 * i + 2] * b[2];
  const kin3::V3 d{r[0] * c[0] + r[1] * c[1] + r[2] * c[2], r[3] * c[0] + r[4] * c[1] + r[5] * c[2],
                   r[6] * c[0] + r[7] * c[1] + r[8] * c[2]};
  return kin3::dot(pm.omega, d);
}

}  // namespace phiq::test
