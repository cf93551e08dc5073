// Every scene under models/ with masses or loads (test_applied_loads.cpp's balances, on the scenes as written): at
// every written row its drivers' power is the rate of the parts' energy less the loads' power plus what the bearings
// and the gears lose, in whatever coordinates the scene is written.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "phiq/applied_loads.hpp"
#include "phiq/inverse_dynamics.hpp"
#include "phiq/joint_reactions.hpp"
#include "phiq/kinds/reaction_site.hpp"
#include "phiq/part_motion.hpp"
#include "phiq/phiq.hpp"
#include "power_balance_support.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

using test::rotational_energy_rate;

// Every scene under models/ with masses or loads, at every written row: its drivers' power as the sweep writes it
// (λ Φt, the `NAME.power` columns) is d(kinetic energy)/dt + d(gravity's potential)/dt − the applied loads' power
// (springs' and dampers' too) + what bearings and gears lose, to 1e-9 of the largest power; in whatever coordinates
// the scene is written.
TEST(PowerBalance, EveryModelWithMassesBalancesItsDriversPowerAtEveryRow) {
  std::vector<std::filesystem::path> scenes;
  for (const auto& e : std::filesystem::recursive_directory_iterator(PHIQ_MODELS_DIR))
    if (e.path().extension() == ".yaml") scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());
  std::vector<std::string> checked;
  for (const std::filesystem::path& path : scenes) {
    const Scene s = load_scene(path.string());
    bool massive = s.loads.applied != nullptr;
    for (const Part& p : s.parts) massive = massive || (p.mass_source != MassSource::kNone && p.mass.mass > 0.0);
    if (!massive) continue;
    SCOPED_TRACE(path.string());
    SquareScene square;
    ASSERT_EQ(prepare_scene(*s.model, s.sweep.t_begin, s.sweep.assembly, &square), SolveStatus::kSuccess);
    const Model& m = square.model(*s.model);
    SweepOptions o = s.sweep;  // the drivers' efforts and powers, whatever the scene writes
    o.efforts = OutputEfforts{};
    o.efforts.parts = std::make_shared<const std::vector<Part>>(s.parts);
    o.efforts.loads = std::make_shared<const Loads>(s.loads);
    o.efforts.constraints = rheonomic_constraints(m);
    o.efforts.power = true;
    // bearings' friction dissipates Σ μ (r |F_r| + r_a |F_a|) |θ̇|, F their joints' reactions (in the joints' axes)
    std::vector<const TorsionalSpring*> bearings;
    if (s.loads.applied)
      for (const TorsionalSpring& t : s.loads.applied->torsional_springs)
        if (t.bearing) {
          const Index c = m.constraint_index(t.bearing->joint);
          o.efforts.reactions.push_back({c, reaction_width(m, c) == 6});
          bearings.push_back(&t);
        }
    o.efforts.reactions_in_joint_axes = true;
    // a gear's losses dissipate (1 − η) of the power its row's multiplier carries into the member it drives: its
    // effort on its first member (the row's −λ) written with the drivers', k times it on the second
    struct Lossy {
      const GearLoss* loss;
      GearMesh mesh;
    };
    std::vector<Lossy> lossy;
    const std::size_t drivers = o.efforts.constraints.size();
    if (s.loads.applied)
      for (const GearLoss& l : s.loads.applied->gear_losses) {
        const Index c = m.constraint_index(l.gear);
        const auto [block, index] = m.constraint_block(c);
        GearMesh g;
        ASSERT_TRUE(block->gear_mesh(index, g) && m.constraints()[static_cast<std::size_t>(c)].rows == 1)
            << "a scene's gear loss on a spatial pair: this balance reads a one-row mesh's effort";
        o.efforts.constraints.push_back(c);
        lossy.push_back({&l, g});
      }
    o.sensitivities.clear();
    o.velocities = o.accelerations = true;
    const std::size_t n = o.efforts.constraints.size();
    ASSERT_GT(n, 0u);
    Workspace ws(m);
    ws.q = square.start;
    double worst = 0.0, scale = 0.0;
    std::size_t rows = 0;
    SweepSummary sum;
    ASSERT_EQ(
        run_sweep(
            m, o, ws,
            [&](const StepView& v) {
              double power = 0.0;
              for (std::size_t i = 0; i < n; ++i) power += v.efforts[n + i];
              if (!std::isfinite(power)) return true;  // a singular row: said so, no power
              double energy_rate = 0.0;
              for (const Part& p : s.parts) {
                if (p.mass_source == MassSource::kNone) continue;
                const PartMotion pm = part_motion(p.frame, v.q.data(), v.qd->data(), v.qdd->data(), v.t);
                const auto [vc, ac] = pm.point(p.mass.center);
                energy_rate += p.mass.mass * kin3::dot(vc, ac) + rotational_energy_rate(p, pm) -
                               p.mass.mass * kin3::dot(s.loads.gravity, vc);
              }
              double loads =
                  s.loads.applied ? applied_power(*s.loads.applied, v.q.data(), v.qd->data(), v.qdd->data(), v.t) : 0.0;
              const double* f = v.efforts + 2 * n;
              for (std::size_t i = 0; i < bearings.size(); ++i) {
                const BearingFriction& b = *bearings[i]->bearing;
                const bool spatial = o.efforts.reactions[i].spatial;
                std::vector<double> gradient;
                // what presses it: a journal's radial force and bending over its arm, a slide's radial force and
                // moment over its arm (BearingFriction)
                const double arm = b.moment_arm > 0.0 ? 1.0 / b.moment_arm : 0.0;
                const double across = std::hypot(f[0], f[1]),
                             load = b.slide ? across + arm * (spatial ? std::hypot(f[3], f[4], f[5]) : std::fabs(f[2]))
                                            : b.radius * (across + arm * (spatial ? std::hypot(f[3], f[4]) : 0.0)) +
                                                  (spatial ? b.thrust_radius * std::fabs(f[2]) : 0.0);
                loads -=
                    b.coefficient * load * std::fabs(angle_rate(*bearings[i], v.q.data(), v.qd->data(), v.t, gradient));
                f += spatial ? 6 : 3;
              }
              auto rate = [&](const Slot& x) { return x.is_coordinate() ? (*v.qd)(x.coord()) : 0.0; };
              for (std::size_t j = 0; j < lossy.size(); ++j) {
                const GearMesh& g = lossy[j].mesh;
                const double e1 = v.efforts[drivers + j], e2 = g.k * e1;
                const double p1 = e1 * (rate(g.first) - rate(g.carrier)), p2 = e2 * (rate(g.second) - rate(g.carrier));
                // the member driven: the first (the second drives: the reverse efficiency), or the second
                if (p1 > 0.0) loads -= (1.0 - lossy[j].loss->reverse_efficiency) * p1;
                if (p2 > 0.0) loads -= (1.0 - lossy[j].loss->efficiency) * p2;
              }
              worst = std::max(worst, std::fabs(power - (energy_rate - loads)));
              scale = std::max({scale, std::fabs(power), std::fabs(energy_rate)});
              ++rows;
              return true;
            },
            &sum),
        SolveStatus::kSuccess);
    EXPECT_GT(rows, 10u);
    EXPECT_GT(scale, 0.1);  // watts: the balance is not of zeros
    EXPECT_LT(worst, 1e-9 * scale);
    checked.push_back(path.filename().string());
  }
  // the scenes with masses today; a new one joins by itself
  for (const char* name :
       {"fourbar_motor_torque.yaml", "fourbar_pin_loads.yaml", "fourbar_pin_friction.yaml", "hoist_gear_losses.yaml",
        "rssr_bearing_loads.yaml", "crank_slider_drag.yaml", "fourbar_gearmotor.yaml"})
    EXPECT_NE(std::find(checked.begin(), checked.end(), name), checked.end()) << name;
}

}  // namespace
}  // namespace phiq
