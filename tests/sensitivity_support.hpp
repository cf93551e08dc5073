// Helpers shared by the sensitivity tests (test_sensitivity*.cpp): the crank-slider's closed form by nested dual
// numbers, its scene, and a sweep's rows with their sensitivities (or with their efforts' values).
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq::test {

// Forward-mode dual numbers, nested for mixed higher derivatives: Dual<Dual<double>> carries ∂/∂a, ∂/∂b and
// ∂²/∂a∂b exactly. Only what the closed forms below use.
template <class T>
struct Dual {
  T v{}, d{};
};
template <class T>
Dual<T> operator+(Dual<T> a, Dual<T> b) {
  return {a.v + b.v, a.d + b.d};
}
template <class T>
Dual<T> operator-(Dual<T> a, Dual<T> b) {
  return {a.v - b.v, a.d - b.d};
}
template <class T>
Dual<T> operator*(Dual<T> a, Dual<T> b) {
  return {a.v * b.v, a.d * b.v + a.v * b.d};
}
template <class T>
Dual<T> operator/(Dual<T> a, Dual<T> b) {
  return {a.v / b.v, (a.d * b.v - a.v * b.d) / (b.v * b.v)};
}
inline double sqrt_(double x) { return std::sqrt(x); }
inline double sin_(double x) { return std::sin(x); }
inline double cos_(double x) { return std::cos(x); }
template <class T>
Dual<T> sqrt_(Dual<T> a) {
  const T r = sqrt_(a.v);
  return {r, a.d / (r + r)};
}
template <class T>
Dual<T> sin_(Dual<T> a) {
  return {sin_(a.v), a.d * cos_(a.v)};
}
template <class T>
Dual<T> cos_(Dual<T> a) {
  return {cos_(a.v), T{} - a.d * sin_(a.v)};
}

// The slider of the notes' crank-slider: x_B = L2 cos θ + √(L3² − L2² sin² θ).
template <class T>
T slider(T theta, T l2, T l3) {
  const T s = sin_(theta);
  return l2 * cos_(theta) + sqrt_(l3 * l3 - l2 * l2 * s * s);
}

using D1 = Dual<double>;
using D2 = Dual<D1>;
using D3 = Dual<D2>;

// ∂x_B/∂L, ∂²x_B/∂θ∂L and ∂³x_B/∂θ²∂L at (θ, L2, L3), `which` = 2 for L2, 3 for L3: θ carries the two inner
// directions, L the outer one.
inline std::array<double, 3> slider_derivatives(double theta, double l2, double l3, int which) {
  auto constant = [](double x) { return D3{D2{D1{x, 0}, D1{0, 0}}, D2{D1{0, 0}, D1{0, 0}}}; };
  const D3 th{D2{D1{theta, 1}, D1{1, 0}}, D2{D1{0, 0}, D1{0, 0}}};
  D3 a = constant(l2), b = constant(l3);
  (which == 2 ? a : b).d = D2{D1{1, 0}, D1{0, 0}};
  const D3 x = slider(th, a, b);
  return {x.d.v.v, x.d.v.d, x.d.d.d};
}

// x_B's derivatives in θ alone, x′, x″, x‴ at (θ, L2, L3): θ carries all three directions.
inline std::array<double, 3> slider_theta_derivatives(double theta, double l2, double l3) {
  auto constant = [](double x) { return D3{D2{D1{x, 0}, D1{0, 0}}, D2{D1{0, 0}, D1{0, 0}}}; };
  const D3 th{D2{D1{theta, 1}, D1{1, 0}}, D2{D1{1, 0}, D1{0, 0}}};
  const D3 x = slider(th, constant(l2), constant(l3));
  return {x.d.v.v, x.d.d.v, x.d.d.d};
}

// ∂x_B/∂L, ∂ẋ_B/∂L, ∂ẍ_B/∂L of kCrankSlider (L2 = 0.3, L3 = 1) at time t: θ = 2t, θ̈ = 0, so 1, 2 and 4 times the
// θ-derivatives above.
inline std::array<double, 3> slider_sensitivities(double t, int which) {
  const auto d = slider_derivatives(2.0 * t, 0.3, 1.0, which);
  return {d[0], 2.0 * d[1], 4.0 * d[2]};
}

inline const char* const kCrankSlider = R"(phiq: 1
name: crank_slider
parameters: {L2: 0.3, L3: 1.0}
coordinates: {theta2: 0.0, xA: 0.28, yA: 0.03, xB: 1.25}
points: {O: [0, 0], A: [xA, yA], B: [xB, 0]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}
  - {name: rod, type: distance, points: [A, B], length: L3}
drivers:
  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 2}}
time: {start: 0, end: pi, steps: 90}
output: {velocities: true, accelerations: true, sensitivities: [L2, {parameter: L3, step: 1e-3}]}
)";

// kCrankSlider's mechanism (crank L2, rod L3, θ = 2t) with more `parameters` (", c: 4") and `rest` (parts, loads,
// time, output).
inline std::string crank_slider_scene(const std::string& parameters, const std::string& rest) {
  return "phiq: 1\nname: crank_slider\nparameters: {L2: 0.3, L3: 1.0" + parameters +
         "}\n"
         "coordinates: {theta2: 0.0, xA: 0.28, yA: 0.03, xB: 1.25}\n"
         "points: {O: [0, 0], A: [xA, yA], B: [xB, 0]}\n"
         "constraints:\n"
         "  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}\n"
         "  - {name: rod, type: distance, points: [A, B], length: L3}\n"
         "drivers:\n"
         "  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 2}}\n" +
         rest;
}

// Every delivered row's sensitivities, with the row's time and state.
struct SensitivityTrace {
  Trace rows;
  std::vector<std::vector<double>> s;
  SweepSummary summary;
};

inline SensitivityTrace sweep_sensitivities(const Model& model, const SweepOptions& o,
                                            const Eigen::VectorXd* start = nullptr) {
  SensitivityTrace r;
  Workspace ws(model);
  if (start) ws.q = *start;
  const Index size = SensitivityLayout{model.num_coordinates()}.size(o.sensitivities.size());
  const SolveStatus st = run_sweep(
      model, o, ws,
      [&](const StepView& v) {
        r.rows.t.push_back(v.t);
        r.rows.q.push_back(v.q);
        if (v.qd) r.rows.qd.push_back(*v.qd);
        if (v.qdd) r.rows.qdd.push_back(*v.qdd);
        EXPECT_NE(v.sensitivities, nullptr);
        if (v.sensitivities) r.s.emplace_back(v.sensitivities, v.sensitivities + size);
        return true;
      },
      &r.summary);
  EXPECT_EQ(st, SolveStatus::kSuccess) << r.summary.message;
  return r;
}

// The models along `parameter` at `value` of `scene` (read with `read_with`), built through the C++ API as the
// scene's `output.sensitivities` builds them.
inline OutputSensitivity along(const Scene& scene, const std::string& parameter, double value,
                               SceneOverrides read_with = {}) {
  read_with.sensitivity_models = false;
  const OutputSensitivity s = sensitivity_along(scene, parameter, value, 0.0, {}, read_with);
  EXPECT_EQ(s.step, default_sensitivity_step(value));
  EXPECT_EQ(check_sensitivity_models(*scene.model, s), "");
  return s;
}

// Every row's time and its effort values (effort_values(): efforts, powers, reactions, then their sensitivities) of
// a sweep of `s` at Newton's tolerance 1e-12 (the differences across δ read the positions' error over δ).
struct EffortRows {
  std::vector<double> t;
  std::vector<std::vector<double>> values;
  SweepSummary summary;
};

inline EffortRows effort_rows_sweep(const Scene& s) {
  EffortRows r;
  Workspace ws(*s.model);
  SweepOptions o = s.sweep;
  o.newton.tolerance = 1e-12;
  const std::size_t size = static_cast<std::size_t>(effort_values(o.efforts, o.sensitivities.size()));
  const SolveStatus st = run_sweep(
      *s.model, o, ws,
      [&](const StepView& v) {
        r.t.push_back(v.t);
        EXPECT_NE(v.efforts, nullptr);
        if (v.efforts) r.values.emplace_back(v.efforts, v.efforts + size);
        return true;
      },
      &r.summary);
  EXPECT_EQ(st, SolveStatus::kSuccess) << r.summary.message;
  return r;
}

// The scene `text` with `parameter` = value and no sensitivities: its first driver's effort (or, with `power`, its
// power) at every row.
inline std::vector<double> first_driver_values_at(const std::string& text, const std::string& parameter, double value,
                                                  bool power) {
  SceneOverrides o;
  o.parameters = {{parameter, value}};
  o.sensitivity_models = false;
  Scene s = parse_scene(text, "efforts.yaml", {}, o);
  s.sweep.sensitivities.clear();
  const EffortRows r = effort_rows_sweep(s);
  const std::size_t at = power ? s.sweep.efforts.constraints.size() : 0;
  std::vector<double> out;
  for (const auto& v : r.values) out.push_back(v[at]);
  return out;
}

// models/spatial/rssr.yaml with massive bodies under gravity and damped torsional springs on both hinges' angles,
// the rocker's constants the parameters kt, th0, ct: swept over t in [0, end] with `output`.
inline std::string rssr_with_joint_springs(const std::string& end, const std::string& output) {
  std::string text = model_file_text("spatial/rssr.yaml", "time:");
  const std::string own = "L: 0.92}";
  text.replace(text.find(own), own.size(), "L: 0.92, kt: 15, th0: 0.4, ct: 3, J: 0.4, f: 0.6}");
  return text +
         "parts:\n"
         "  crank: {mass: 0.8, center_of_mass: [a/2, 0, 0], inertia: [0.001, 0.8*a*a/12, 0.8*a*a/12]}\n"
         "  rocker: {mass: 1.1, center_of_mass: [0, b/2, 0], inertia: [1.1*b*b/12, 0.001, 1.1*b*b/12]}\n"
         "loads:\n"
         "  gravity: [0, -9.81, 0]\n"
         "  torsional_springs:\n"
         "    - {name: t1, joint: rocker_hinge, stiffness: kt, free_angle: th0, damping: ct}\n"
         "    - {name: t2, joint: crank_hinge, stiffness: 7, free_angle: -1.5, damping: 0.5}\n"
         "time: {start: 0, end: " +
         end + ", steps: 12}\noutput: " + output + "\n";
}

// A crank-slider with an arm on a frame of expressions (products and sines of its coordinates and t; the parameter d
// and the rod's length L3 in them) that carries a mass, a force and a torque in its axes: parts/expression_rate.hpp.
inline std::string crank_slider_with_expression_frame(const std::string& output) {
  std::string text(kCrankSlider);
  text.erase(text.find("drivers:"));
  const std::string own = "L3: 1.0}";
  text.replace(text.find(own), own.size(), "L3: 1.0, d: 0.25, m2: 0.9, F: 4}");
  return text + R"(drivers:
  - {name: motor, coordinate: theta2, law: {type: polynomial, coefficients: [0.2, 2, 0.8]}}
parts:
  rod: {frame: {origin: A, x: B}, center_of_mass: [L3/2, 0], mass: 1.2, inertia: 1.2*L3*L3/12}
  arm: {frame: {at: [xA + d*cos(theta2)*xB, yA*sin(theta2 + t) + d*xA*yA + 0.1*L3*xB],
                angle: theta2 + d*sin(xB*yA + t)}, center_of_mass: [0.1, 0.05], mass: m2, inertia: 0.03}
loads:
  gravity: [0, -9.81]
  forces: [{name: push, part: arm, at: [d, 0.1], force: [-F*cos(theta2), F*xB]}]
  torques: [{name: turn, part: arm, torque: F*xA*d, axes: part}]
time: {start: 0, end: 0.9, steps: 9}
output: )" +
         output + "\n";
}

// models/spatial/rssr.yaml with a massive crank and an arm on a frame of expressions of both bodies' coordinates, t,
// a and b, turned about `axis`, carrying a mass, a force and a torque in its axes: swept over t in [0, 1.3].
inline std::string rssr_with_expression_frame(const std::string& axis, const std::string& output) {
  return model_file_text("spatial/rssr.yaml", "time:") +
         "parts:\n"
         "  crank: {mass: 0.8, center_of_mass: [a/2, 0, 0], inertia: [0.001, 0.8*a*a/12, 0.8*a*a/12]}\n"
         "  arm: {frame: {at: [a*crank_e0*cos(t) + rocker_y, rocker_z*crank_e3 + a*sin(rocker_e1),\n"
         "                     rocker_x*rocker_e0 - b], angle: 2*crank_e3*rocker_e1 + a*t, axis: " +
         axis +
         "},\n"
         "        center_of_mass: [0.05, 0.02, -0.03], mass: 0.7, inertia: [0.01, 0.02, 0.015]}\n"
         "loads:\n"
         "  gravity: [0, -9.81, 0]\n"
         "  forces: [{name: push, part: arm, at: [0.1, 0, a], force: [3, -a*crank_e3, rocker_e1]}]\n"
         "  torques: [{name: turn, part: arm, torque: [0.2, b*rocker_e0, -crank_e3], axes: part}]\n"
         "time: {start: 0, end: 1.3, steps: 13}\noutput: " +
         output + "\n";
}

// The scene with `parameter` = value, without sensitivities: its first effort at every row.
inline std::vector<double> effort_sensitivity_efforts_at(const std::string& text, const std::string& parameter,
                                                         double value) {
  return first_driver_values_at(text, parameter, value, false);
}

// Every row's ∂τ/∂p of the first effort against central differences of re-solved sweeps (Richardson over δ and
// δ/2, δ = 10⁻³ |p|): within 1e-8 of the largest |∂τ/∂p|, and that not zero.
inline void expect_effort_sensitivities_match_resolved_sweeps(const std::string& text) {
  const Scene s = parse_scene(text, "efforts.yaml");
  ASSERT_EQ(s.sweep.efforts.constraints.size(), 1u);
  ASSERT_FALSE(s.sweep.sensitivities.empty());
  const EffortRows base = effort_rows_sweep(s);
  EXPECT_EQ(base.summary.sensitivity_form, SensitivityForm::kDirect);
  const std::size_t offset = static_cast<std::size_t>(s.sweep.efforts.size());
  for (std::size_t j = 0; j < s.sweep.sensitivities.size(); ++j) {
    const OutputSensitivity& p = s.sweep.sensitivities[j];
    const double delta = 1e-3 * std::fabs(p.value);
    const std::vector<double> up = effort_sensitivity_efforts_at(text, p.name, p.value + delta);
    const std::vector<double> down = effort_sensitivity_efforts_at(text, p.name, p.value - delta);
    const std::vector<double> up2 = effort_sensitivity_efforts_at(text, p.name, p.value + delta / 2);
    const std::vector<double> down2 = effort_sensitivity_efforts_at(text, p.name, p.value - delta / 2);
    ASSERT_EQ(up.size(), base.t.size());
    ASSERT_EQ(up2.size(), base.t.size());
    double scale = 0.0, worst = 0.0, worst_t = 0.0;
    for (std::size_t k = 0; k < base.t.size(); ++k) {
      const double exact = base.values[k][offset + j];
      ASSERT_TRUE(std::isfinite(exact)) << p.name << " t = " << base.t[k];
      const double d1 = (up[k] - down[k]) / (2 * delta), d2 = (up2[k] - down2[k]) / delta;
      const double fd = (4 * d2 - d1) / 3;
      scale = std::max(scale, std::fabs(exact));
      if (std::fabs(exact - fd) > worst) worst = std::fabs(exact - fd), worst_t = base.t[k];
    }
    ::testing::Test::RecordProperty("worst_relative_" + p.name, scientific(worst / scale, 2));
    EXPECT_GT(scale, 1e-2) << p.name;
    EXPECT_LE(worst, 1e-8 * scale) << p.name << ": worst at t = " << worst_t << " (largest " << scale << ")";
  }
}

}  // namespace phiq::test
