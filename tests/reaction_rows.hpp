// A sweep's rows with efforts and reactions, as `phiq run` sweeps them (the model with redundant rows left out):
// what the joint-reaction, gear-mesh and bearing tests read; and the massive four-bar's Newton–Euler check.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq::test {

struct ReactionRows {
  std::vector<Eigen::VectorXd> q, qd, qdd;
  std::vector<std::vector<double>> values;  // efforts, powers, reactions, losses
};

// The rows of `s` (its output asks for velocities and accelerations), its summary into `sum` and the model swept
// (the scene's, its redundant rows left out; it outlives the call) into `swept`, when not null.
inline ReactionRows sweep_reactions(const Scene& s, SweepSummary* sum = nullptr, const Model** swept = nullptr) {
  ReactionRows r;
  static std::vector<SquareScene> kept;  // the reduced models the callers read after the sweep
  kept.emplace_back();
  SquareScene& square = kept.back();
  EXPECT_EQ(prepare_scene(*s.model, s.sweep.t_begin, s.sweep.assembly, &square), SolveStatus::kSuccess);
  const Model& m = square.model(*s.model);
  if (swept) *swept = &m;
  Workspace ws(m);
  ws.q = square.start;
  const std::size_t n = static_cast<std::size_t>(s.sweep.efforts.size());
  EXPECT_EQ(run_sweep(
                m, s.sweep, ws,
                [&](const StepView& v) {
                  r.q.push_back(v.q), r.qd.push_back(*v.qd), r.qdd.push_back(*v.qdd);
                  r.values.emplace_back(v.efforts, v.efforts + n);
                  return true;
                },
                sum),
            SolveStatus::kSuccess);
  return r;
}

// The massive four-bar of models/dynamics/fourbar_pin_loads.yaml (reference-point links centred on their points,
// masses 1, 2, 1.5 kg, lengths 0.4, 1.2, 1.0 m, slender bars, gravity 9.81 down) at one row: each link's
// Newton–Euler equations, to `tolerance` relative, with the pins' forces read from the row's values after the effort
// and its power (O, A, B, C, each on its side a: O and A on the crank, B on the coupler, C on the rocker) and
// `torque[l]` the couples on link l (crank, coupler, rocker; the motor's on the crank).
inline void expect_fourbar_links_balance(const Model& m, const Eigen::VectorXd& q, const Eigen::VectorXd& qdd,
                                         const std::vector<double>& v, const std::array<double, 3>& torque,
                                         double tolerance, std::size_t row) {
  const double mass[3] = {1.0, 2.0, 1.5}, length[3] = {0.4, 1.2, 1.0}, g = 9.81;
  const char* names[3][3] = {{"x2", "y2", "psi2"}, {"x3", "y3", "psi3"}, {"x4", "y4", "psi4"}};
  auto c = [&](const char* n) { return m.coordinate_index(n); };
  auto at = [&](int l, double s_local) {  // a point of link l, s_local along it from its centre
    const double psi = q(c(names[l][2]));
    return Eigen::Vector2d(q(c(names[l][0])) + s_local * std::cos(psi), q(c(names[l][1])) + s_local * std::sin(psi));
  };
  auto F = [&](int j) { return Eigen::Vector2d(v[2 + 3 * j], v[3 + 3 * j]); };
  const Eigen::Vector2d O = at(0, -length[0] / 2), A = at(0, length[0] / 2), B = at(1, length[1] / 2),
                        C = at(2, -length[2] / 2);
  const std::pair<Eigen::Vector2d, Eigen::Vector2d> forces[3][2] = {
      {{O, F(0)}, {A, F(1)}}, {{A, -F(1)}, {B, F(2)}}, {{B, -F(2)}, {C, F(3)}}};  // (point, force)
  for (int l = 0; l < 3; ++l) {
    const Eigen::Vector2d G(q(c(names[l][0])), q(c(names[l][1]))), a(qdd(c(names[l][0])), qdd(c(names[l][1])));
    Eigen::Vector2d sum = Eigen::Vector2d(0, -mass[l] * g);
    double moment = torque[static_cast<std::size_t>(l)];
    for (const auto& [P, f] : forces[l]) {
      const Eigen::Vector2d arm = P - G;
      sum += f, moment += arm.x() * f.y() - arm.y() * f.x();
    }
    EXPECT_NEAR((sum - mass[l] * a).norm(), 0.0, tolerance * (1.0 + sum.norm())) << names[l][0] << " row " << row;
    EXPECT_NEAR(moment, mass[l] * length[l] * length[l] / 12 * qdd(c(names[l][2])),
                tolerance * (1.0 + std::fabs(moment)))
        << names[l][0] << " row " << row;
  }
}

// models/transmissions/bevel_gears.yaml made a worm pair, up to its `output:` (to be written by the caller): a
// one-start worm of pitch radius 0.01 about x at the origin, its 30-tooth wheel of 0.05 about y through (0, 0, 0.06),
// the worm turned at θ1 = 30 t + 15 t², `steps` rows over one second.
inline std::string worm_scene_text(int steps) {
  std::string text = model_file_text("transmissions/bevel_gears.yaml", "output:");
  text = replace_first(text, "{body: ground, axis: [0, 1, 0]}", "{body: ground, at: [0, 0, 0.06], axis: [0, 1, 0]}");
  text = replace_first(text, "s2_z: 0", "s2_z: 0.06");
  text = replace_first(text, "teeth: [15, 30]", "teeth: [1, 30], pitch_radii: [0.01, 0.05]");
  text = replace_first(text, "coefficients: [0, 2, 0.5]", "coefficients: [0, 30, 15]");
  return replace_first(text, "time: {start: 0, end: 3, steps: 60}",
                       "time: {start: 0, end: 1, steps: " + std::to_string(steps) + "}");
}

// A 2 kg block (a carriage) pushed along x at 0.5 m/s on a spatial prismatic slide, side 1 its origin (the
// reaction's point: the carriage's bearing), its centre at (d, e, 0) (parameters), under gravity along −z, with a
// slide bearing of μ (parameter mu = 0.2) and moment arm 0.15, and `output`.
inline std::string spatial_slide_text(double d, double e, const std::string& output) {
  return "phiq: 1\nname: block\ndimension: 3\nparameters: {d: " + std::to_string(d) + ", e: " + std::to_string(e) +
         ", mu: 0.2}\n"
         "coordinates: {x: 0.1, y: 0, z: 0, e0: 1, e1: 0, e2: 0, e3: 0}\nbodies: {block: [x, y, z, e0, e1, e2, e3]}\n"
         "constraints:\n  - {name: slide, type: prismatic, between: [{body: block, axis: [1, 0, 0]}, {body: ground, "
         "axis: [1, 0, 0]}]}\n"
         "drivers:\n  - {name: push, joint: slide, law: {type: linear, initial: -0.1, rate: -0.5}}\n"
         "parts:\n  block: {mass: 2.0, center_of_mass: [d, e, 0], inertia: [0.01, 0.02, 0.03]}\n"
         "loads:\n  gravity: [0, 0, -9.81]\n"
         "  torsional_springs: [{name: guide, coordinate: x, bearing: {joint: slide, coefficient: mu, moment_arm: "
         "0.15}}]\n"
         "time: {start: 0, end: 1, steps: 10}\n" +
         output;
}

}  // namespace phiq::test
