// Sensitivities of the drivers' powers to the scene's parameters (phiq/effort_sensitivity.hpp, columns
// `NAME.power.d_P`): a pendulum whose driving law reads a parameter against the closed form P = τ θ̇, and a massive
// crank-slider and the massive four-bar of models/dynamics against central differences of whole sweeps re-solved
// at p ± δ, p ± δ/2 (Richardson), every row; the columns written only with the powers, and in HDF5 with units.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "phiq/effort_sensitivity.hpp"
#include "efforts_files.hpp"
#include "phiq/phiq.hpp"
#include "sensitivity_support.hpp"
#include "test_support.hpp"
#include "scratch_path.hpp"

namespace phiq {
namespace {

using PowerSensitivityRows = test::EffortRows;
using test::effort_rows_sweep;

// The first driver's power at every row with `parameter` = value (no sensitivities).
std::vector<double> power_sensitivity_powers_at(const std::string& text, const std::string& parameter, double value) {
  return test::first_driver_values_at(text, parameter, value, true);
}

// Every row's ∂P/∂p of the first driver against re-solved sweeps (Richardson over δ = 10⁻³ |p| and δ/2): within
// 1e-8 of the largest |∂P/∂p|, and that not zero.
void expect_power_sensitivities_match_resolved_sweeps(const std::string& text) {
  const Scene s = parse_scene(text, "power.yaml");
  ASSERT_EQ(s.sweep.efforts.constraints.size(), 1u);
  ASSERT_TRUE(s.sweep.efforts.power);
  const PowerSensitivityRows base = effort_rows_sweep(s);
  const std::size_t np = s.sweep.sensitivities.size(), offset = static_cast<std::size_t>(s.sweep.efforts.size());
  for (std::size_t j = 0; j < np; ++j) {
    const OutputSensitivity& p = s.sweep.sensitivities[j];
    const double delta = 1e-3 * std::fabs(p.value);
    const std::vector<double> up = power_sensitivity_powers_at(text, p.name, p.value + delta),
                              down = power_sensitivity_powers_at(text, p.name, p.value - delta),
                              up2 = power_sensitivity_powers_at(text, p.name, p.value + delta / 2),
                              down2 = power_sensitivity_powers_at(text, p.name, p.value - delta / 2);
    ASSERT_EQ(up.size(), base.t.size());
    double scale = 0.0, worst = 0.0, worst_t = 0.0;
    for (std::size_t k = 0; k < base.t.size(); ++k) {
      const double exact = base.values[k][offset + EffortSensitivityLayout{1}.power_offset(np, j, 0)];
      ASSERT_TRUE(std::isfinite(exact)) << p.name << " t = " << base.t[k];
      const double fd = (4 * (up2[k] - down2[k]) / delta - (up[k] - down[k]) / (2 * delta)) / 3;
      scale = std::max(scale, std::fabs(exact));
      if (std::fabs(exact - fd) > worst) worst = std::fabs(exact - fd), worst_t = base.t[k];
    }
    ::testing::Test::RecordProperty("worst_relative_" + p.name, scientific(worst / scale, 2));
    EXPECT_GT(scale, 1e-2) << p.name;
    EXPECT_LE(worst, 1e-8 * scale) << p.name << ": worst at t = " << worst_t << " (largest " << scale << ")";
  }
}

const char* const kPowerPendulum = R"(phiq: 1
name: pendulum
parameters: {L: 0.8, mb: 1.5, w: 2}
coordinates: {x: 0.8, y: 0.0, th: 0.0}
points: {O: [0, 0], P: [x, y]}
constraints:
  - {name: rod, type: distance, points: [O, P], length: L}
  - {name: rod_angle, type: segment_angle, segment: [O, P], angle: th}
drivers:
  - {name: motor, coordinate: th, law: {type: polynomial, coefficients: [0.3, w, 1.5]}}
parts:
  bob: {frame: {origin: O, x: P}, center_of_mass: [L, 0], mass: mb, inertia: 0.02}
loads: {gravity: [0, -9.81]}
time: {start: 0, end: 2, steps: 40}
output: {efforts: all, power: true, sensitivities: [L, mb, w]}
)";

TEST(PowerSensitivity, APendulumsPowerFollowsItsClosedFormInLengthMassAndRate) {
  // θ = 0.3 + w t + 1.5 t², θ̇ = w + 3t, α = 3: P = τ θ̇ with τ = m g L cos θ + (I + m L²) α, so ∂P/∂L = (m g cos θ
  // + 2 m L α) θ̇, ∂P/∂m = (g L cos θ + L² α) θ̇ and ∂P/∂w = −m g L sin θ t θ̇ + τ (the law's rate reads w: Φt does)
  const Scene s = parse_scene(kPowerPendulum, "pendulum.yaml");
  const PowerSensitivityRows r = effort_rows_sweep(s);
  ASSERT_EQ(r.values.size(), 41u);
  const double g = 9.81, L = 0.8, m = 1.5, I = 0.02, alpha = 3.0, w = 2.0;
  const std::size_t at = static_cast<std::size_t>(s.sweep.efforts.size());
  const EffortSensitivityLayout layout{1};
  double worst[3] = {0, 0, 0};
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    const double t = r.t[k], th = 0.3 + w * t + 1.5 * t * t, rate = w + 3 * t;
    const double tau = m * g * L * std::cos(th) + (I + m * L * L) * alpha;
    const double expected[3] = {(m * g * std::cos(th) + 2 * m * L * alpha) * rate,
                                (g * L * std::cos(th) + L * L * alpha) * rate,
                                -m * g * L * std::sin(th) * t * rate + tau};
    EXPECT_NEAR(r.values[k][1], tau * rate, 1e-9 * std::fabs(tau * rate) + 1e-9) << t;  // the power itself
    for (std::size_t j = 0; j < 3; ++j)
      worst[j] = std::max(worst[j], std::fabs(r.values[k][at + layout.power_offset(3, j, 0)] - expected[j]));
  }
  ::testing::Test::RecordProperty(
      "worst_L_m_w", scientific(worst[0], 2) + " " + scientific(worst[1], 2) + " " + scientific(worst[2], 2));
  // scales: |∂P/∂L| up to ~200, |∂P/∂m| ~100, |∂P/∂w| ~100
  for (double e : worst) EXPECT_LT(e, 1e-7);
}

TEST(PowerSensitivity, AStepperDeliversThePendulumsClosedForm) {
  const Scene s = parse_scene(kPowerPendulum, "pendulum.yaml");
  StepperOptions o;
  o.sensitivities = s.sweep.sensitivities;
  o.efforts = s.sweep.efforts;
  Stepper stepper(*s.model, o);
  const double g = 9.81, L = 0.8, m = 1.5, I = 0.02, alpha = 3.0, w = 2.0;
  const std::size_t at = static_cast<std::size_t>(s.sweep.efforts.size());
  const EffortSensitivityLayout layout{1};
  for (const double t : {0.0, 0.35, 1.4}) {
    ASSERT_EQ(stepper.step(t), SolveStatus::kSuccess) << t;
    ASSERT_NE(stepper.efforts(), nullptr);
    const double th = 0.3 + w * t + 1.5 * t * t, rate = w + 3 * t;
    const double tau = m * g * L * std::cos(th) + (I + m * L * L) * alpha;
    EXPECT_NEAR(stepper.efforts()[at + layout.power_offset(3, 0, 0)], (m * g * std::cos(th) + 2 * m * L * alpha) * rate,
                1e-7)
        << t;
    EXPECT_NEAR(stepper.efforts()[at + layout.power_offset(3, 2, 0)], -m * g * L * std::sin(th) * t * rate + tau, 1e-7)
        << t;
  }
}

TEST(PowerSensitivity, AMassiveCrankSlidersPowerMatchesResolvedSweeps) {
  // a polar crank driven at a rate that reads a parameter, massive crank and rod, a load on the slider's pin
  expect_power_sensitivities_match_resolved_sweeps(R"(phiq: 1
name: crank_slider
parameters: {L2: 0.3, L3: 1.0, w: 2}
coordinates: {theta2: 0.0, xA: 0.28, yA: 0.03, xB: 1.25}
points: {O: [0, 0], A: [xA, yA], B: [xB, 0]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}
  - {name: rod, type: distance, points: [A, B], length: L3}
drivers:
  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: w}}
parts:
  crank: {frame: {origin: O, x: A}, center_of_mass: [L2/2, 0], mass: 0.5, inertia: 0.5*L2*L2/12}
  rod: {frame: {origin: A, x: B}, center_of_mass: [L3/2, 0], mass: 1.2, inertia: 1.2*L3*L3/12}
loads:
  gravity: [0, -9.81]
  forces: [{name: push, part: rod, at: [L3, 0], force: [-5, 0]}]
time: {start: 0, end: 1.5, steps: 30}
output: {efforts: all, power: true, sensitivities: [L2, L3, w]}
)");
}

TEST(PowerSensitivity, TheMassiveFourBarsPowerMatchesResolvedSweeps) {
  // models/dynamics/fourbar_motor_torque.yaml (natural coordinates; centres and inertias read L2, L3, L4)
  const std::string text = test::model_file_text("dynamics/fourbar_motor_torque.yaml", "output:");
  expect_power_sensitivities_match_resolved_sweeps(text +
                                                   "output: {efforts: all, power: true, sensitivities: [L1, L3]}\n");
}

TEST(PowerSensitivity, TheColumnsAreWrittenWithThePowersOnlyAndHoldTheRowsValues) {
  Scene s = parse_scene(kPowerPendulum, "pendulum.yaml");
  for (const bool power : {true, false}) {
    s.sweep.efforts.power = power;
    const CsvFormat f(*s.model, s.sweep);
    const std::vector<std::string> names = f.column_names();
    const std::size_t powers = power ? 3 : 0;
    ASSERT_GE(names.size(), 3 + powers);
    EXPECT_EQ(names[names.size() - powers - 1], "motor.effort.d_w") << power;
    if (power) {
      EXPECT_EQ(names[names.size() - 3], "motor.power.d_L");
      EXPECT_EQ(names[names.size() - 1], "motor.power.d_w");
    }
    Workspace ws(*s.model);
    int rows = 0;
    ASSERT_EQ(run_sweep(
                  *s.model, s.sweep, ws,
                  [&](const StepView& v) {
                    std::vector<double> row(f.num_values());
                    f.append_values(v, row.data());
                    const std::size_t end = static_cast<std::size_t>(effort_values(s.sweep.efforts, 3));
                    EXPECT_EQ(row.back(), v.efforts[power ? end - 1 : end - 4]);
                    ++rows;
                    return true;
                  },
                  nullptr),
              SolveStatus::kSuccess);
    EXPECT_EQ(rows, 41);
  }
}

TEST(PowerSensitivity, AnHdf5FileHoldsTheColumnsOfTheCsvWithTheirUnits) {
  // the efforts dataset: motor.effort (N m), motor.power (W), ∂τ/∂p per parameter ("N m/L" …), ∂P/∂p ("W/L" …)
  const Scene s = parse_scene(kPowerPendulum, "pendulum.yaml");
  const std::filesystem::path path = phiq::test::scratch_path("phiq_power_sensitivity").concat(".h5");
  const std::string csv = test::write_efforts_files(s, path.string());
  const CsvTable a = read_hdf5_table(path.string()), b = parse_csv_table(csv, "r.csv");
  EXPECT_EQ(a.columns, b.columns);
  ASSERT_EQ(a.rows.size(), 41u);
  EXPECT_EQ(a.rows.back().back(), b.rows.back().back());
  EXPECT_EQ(test::hdf5_strings(path.string(), "efforts", "columns"),
            (std::vector<std::string>{"motor.effort", "motor.power", "motor.effort.d_L", "motor.effort.d_mb",
                                      "motor.effort.d_w", "motor.power.d_L", "motor.power.d_mb", "motor.power.d_w"}));
  EXPECT_EQ(test::hdf5_strings(path.string(), "efforts", "units"),
            (std::vector<std::string>{"N m", "W", "N m/L", "N m/mb", "N m/w", "W/L", "W/mb", "W/w"}));
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace phiq
