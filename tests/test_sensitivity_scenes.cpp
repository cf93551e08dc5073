// Sensitivities of every scene of models/ to each of its parameters, against central differences of two sweeps
// re-solved at p ± δ: every kind the scenes use (distances, pins, sliders, angles, natural and reference-point,
// equations, couplers, gears, belts, cams, slots, spatial joints, drivers' laws) with its data moved by the scene's
// own arithmetic. A parameter is left out only for a stated reason (it sets the structure or the time grid, the
// sweeps at p ± δ fail or pass a singular position, where a difference across δ means nothing; one that reaches
// no constraint has its zero sensitivities and its unmoved motion checked instead), and the list is printed.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "cli_test_support.hpp"
#include "phiq/applied_loads.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

namespace fs = std::filesystem;

struct Swept {
  std::vector<double> t;
  std::vector<Eigen::VectorXd> q[3];   // q, q̇, q̈
  std::vector<std::vector<double>> s;  // sensitivities, when asked
  std::string failure;                 // why the sweep failed, else ""
  Index singular_rows = 0;             // rows at a singular position (their sensitivities are NaN)
  double min_rcond = 0.0;              // the smallest reciprocal condition of Φq at a row
  bool passes_singular = false;        // a bifurcation or ill-conditioning warning
  bool no_dependence = false;          // the parameter reaches no constraint (a load's or a part's only)
};

// The scene at parameter = value, swept as `phiq run` sweeps it, with q, q̇, q̈ and, when `sensitivity` is given,
// its sensitivities.
Swept sweep_scene_at(const std::string& text, const std::string& path, const std::string& parameter, double value,
                     const OutputSensitivity* sensitivity) {
  Swept r;
  SceneOverrides o;
  o.parameters = {{parameter, value}};
  o.sensitivity_models = false;
  Scene s = parse_scene(text, path, {}, o);
  s.sweep.velocities = s.sweep.accelerations = true;
  s.sweep.velocity_columns.reset(), s.sweep.acceleration_columns.reset();
  s.sweep.every = 1;
  s.sweep.newton.tolerance = 1e-12;
  if (sensitivity) s.sweep.sensitivities = {*sensitivity};
  // (∂q/∂p is checked here; a bearing's friction or a gear's losses, which read the multipliers, refuse the efforts'
  // ∂τ/∂p)
  if (s.loads.applied) {
    bool losses = !s.loads.applied->gear_losses.empty();
    for (const TorsionalSpring& t : s.loads.applied->torsional_springs) losses = losses || t.bearing.has_value();
    if (losses) s.sweep.efforts = OutputEfforts{};
  }
  SquareScene sq;
  if (prepare_scene(*s.model, s.sweep.t_begin, s.sweep.assembly, &sq) != SolveStatus::kSuccess)
    return r.failure = "prepare: " + sq.assembly.message, r;
  const Model& m = sq.model(*s.model);
  Workspace ws(m);
  ws.q = sq.start;
  SweepSummary sum;
  const Index size = SensitivityLayout{m.num_coordinates()}.size(s.sweep.sensitivities.size());
  const SolveStatus st = run_sweep(
      m, s.sweep, ws,
      [&](const StepView& v) {
        r.t.push_back(v.t);
        r.q[0].push_back(v.q), r.q[1].push_back(*v.qd), r.q[2].push_back(*v.qdd);
        if (v.sensitivities) r.s.emplace_back(v.sensitivities, v.sensitivities + size);
        return true;
      },
      &sum);
  if (st != SolveStatus::kSuccess) r.failure = sum.message;
  r.singular_rows = sum.singular_positions;
  r.min_rcond = sum.min_rcond;
  for (const SweepWarning& w : sum.warnings)
    r.passes_singular |= w.kind == "bifurcation" || w.kind == "ill_conditioned",
        r.no_dependence |= w.kind == "no_dependence";
  return r;
}

TEST(SensitivityScenes, EveryParameterOfEverySceneMatchesResolvedSweeps) {
  std::vector<std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(PHIQ_MODELS_DIR))
    if (e.path().extension() == ".yaml" && e.path().parent_path().filename() != "reference")
      files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  int verified = 0;
  std::vector<std::string> left_out;
  for (const std::string& path : files) {
    const std::string text = test::slurp(path);
    const std::string rel = fs::relative(path, PHIQ_MODELS_DIR).string();
    const Scene scene = load_scene(path);
    for (const auto& [name, value] : scene.parameters) {
      const std::string who = rel + " " + name;
      OutputSensitivity sens;
      std::string why;
      try {
        sens = sensitivity_along(scene, name, value);
      } catch (const SceneError& e) {
        why = e.what();
      }
      if (!why.empty()) {
        left_out.push_back(who + ": structure (" + why.substr(0, 60) + ")");
        continue;
      }
      const Swept base = sweep_scene_at(text, path, name, value, &sens);
      if (!base.failure.empty()) {
        left_out.push_back(who + ": the sweep fails (" + base.failure.substr(0, 80) + ")");
        continue;
      }
      // Near a singular position the sensitivities grow without bound and a difference across δ means nothing
      // (the rows there are the tests of test_sensitivity.cpp and test_singular_positions.cpp).
      if (base.singular_rows || base.min_rcond < 1e-7 || base.passes_singular) {
        left_out.push_back(who + ": the sweep passes a singular position or near one (rcond " +
                           std::to_string(base.min_rcond) + ")");
        continue;
      }
      ASSERT_EQ(base.s.size(), base.t.size()) << who;
      if (base.no_dependence) {  // a drag's coefficient: the motion is the same at every value, ∂q/∂p is 0
        const Swept other = sweep_scene_at(text, path, name, 1.25 * value + 0.5, nullptr);
        for (std::size_t k = 0; k < base.t.size(); ++k) {
          EXPECT_EQ(*std::max_element(base.s[k].begin(), base.s[k].end()), 0.0) << who;
          EXPECT_EQ(*std::min_element(base.s[k].begin(), base.s[k].end()), 0.0) << who;
          for (int order = 0; order < 3; ++order) EXPECT_EQ(other.q[order].at(k), base.q[order][k]) << who;
        }
        left_out.push_back(who + ": reaches no constraint (∂q/∂p is 0 at every row: checked)");
        continue;
      }
      const Index n = static_cast<Index>(base.q[0][0].size());
      const SensitivityLayout layout{n};
      // The reference: central differences at δ and δ/2 extrapolated (Richardson: an error of O(δ⁴), so that a
      // sensitivity that changes fast, a Cardan joint at 57:1, meets a difference that converges), δ relative to
      // the parameter, at 10⁻², 10⁻³, 10⁻⁴ and 2·10⁻⁵ |p|: a small step loses to the rounding of q (a 1 km rod's
      // x_B is known to 10⁻¹⁰ m, a step of 2·10⁻⁸ m on its 1 mm crank reads that as 5·10⁻³), a large one to
      // truncation, each scene where its own scales put it. The best must agree: 1e-6 relative to the largest
      // sensitivity (the closed forms of test_sensitivity.cpp and test_hard_cases.cpp pin the values further).
      std::string reference_failure;
      std::array<double, 3> best{INFINITY, INFINITY, INFINITY}, scales{}, worst_ts{};
      for (double relative_step : {1e-2, 1e-3, 1e-4, 2e-5}) {
        const double delta = value == 0.0 ? relative_step : relative_step * std::fabs(value);
        const Swept up = sweep_scene_at(text, path, name, value + delta, nullptr);
        const Swept down = sweep_scene_at(text, path, name, value - delta, nullptr);
        const Swept up2 = sweep_scene_at(text, path, name, value + delta / 2, nullptr);
        const Swept down2 = sweep_scene_at(text, path, name, value - delta / 2, nullptr);
        const std::string failure = up.failure + down.failure + up2.failure + down2.failure;
        if (!failure.empty())
          reference_failure = "a sweep at p ± δ fails (" + failure.substr(0, 80) + ")";
        else if (up.t != base.t || down.t != base.t || up2.t != base.t || down2.t != base.t)
          reference_failure = "it moves the time grid";
        if (!reference_failure.empty()) break;
        for (int order = 0; order < 3; ++order) {
          double scale = 0.0, worst = 0.0, worst_t = 0.0;
          for (std::size_t k = 0; k < base.t.size(); ++k)
            for (Index j = 0; j < n; ++j) {
              const double exact = base.s[k][static_cast<std::size_t>(layout.offset(0, order) + j)];
              ASSERT_TRUE(std::isfinite(exact)) << who << " t = " << base.t[k];
              scale = std::max(scale, std::fabs(exact));
              const double d1 = (up.q[order][k](j) - down.q[order][k](j)) / (2 * delta);
              const double d2 = (up2.q[order][k](j) - down2.q[order][k](j)) / delta;
              const double fd = (4 * d2 - d1) / 3;
              if (std::fabs(exact - fd) > worst) worst = std::fabs(exact - fd), worst_t = base.t[k];
            }
          scales[order] = scale;
          if (worst < best[order]) best[order] = worst, worst_ts[order] = worst_t;
        }
      }
      if (!reference_failure.empty()) {
        left_out.push_back(who + ": " + reference_failure);
        continue;
      }
      EXPECT_GT(std::max({scales[0], scales[1], scales[2]}), 0.0) << who;  // (a zero column is checked too)
      for (int order = 0; order < 3; ++order)
        EXPECT_LE(best[order], 1e-6 * std::max({scales[order], scales[0], 1e-3}))
            << who << ": order " << order << ", worst at t = " << worst_ts[order] << " (largest sensitivity "
            << scales[order] << ")";
      ++verified;
    }
  }
  std::cout << verified << " parameters verified; left out:\n";
  for (const std::string& l : left_out) std::cout << "  " << l << "\n";
  EXPECT_GE(verified, 40);
}

}  // namespace
}  // namespace phiq
