// What `phiq tolerance` writes (tools/README.md, "phiq tolerance"): the CSV of every output's nominal value and
// spreads row by row, the JSON summary (parameters, Σ, samples, failed cases, agreement per output) and the SVG of
// one output with the ±2σ bands of both estimates against t (drawn with tools/plot/'s axes and lines).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "phiq/scene.hpp"
#include "tolerance_input.hpp"
#include "tolerance_spread.hpp"

namespace phiq::tools {

// A sampled case that failed: its index (from 0), parameter values and why.
struct FailedCase {
  std::size_t index = 0;
  std::vector<double> values;  // in the order of ParameterSpread::parameters
  std::string message;
};

// "case 12 (L2 = 0.31, L3 = 0.98)".
std::string case_label(const FailedCase& c, const tolerance::ParameterSpread& spread);

// Header `t,y,y.sd_linear,y.sd_mc,y.mean_mc,...` (each name made an identifier with `identifiers`, as `phiq run
// --names identifiers` does), then one row per row of the nominal sweep, numbers in their shortest exact form.
std::string tolerance_csv(const std::vector<double>& t, const std::vector<tolerance::OutputSpread>& outputs,
                          bool identifiers);

// Everything the summary records (format kToleranceSummaryFormat).
struct ToleranceRun {
  std::string scene_path, scene_name;
  const tolerance::ParameterSpread* spread = nullptr;
  std::vector<double> nominal;  // the parameters' nominal values
  std::string covariance_file;  // empty: none
  long samples = 0;
  std::uint64_t seed = 0;
  double threshold = 4.0;
  double floor = 0.0;
  std::vector<FailedCase> failed;
  std::vector<std::string> independent;  // parameters whose sensitivities are zero at every row
  std::string sensitivity_form;          // how the nominal sweep solved them: "direct" or "adjoint"
  int threads = 1;
  double solve_seconds = 0.0;
};
nlohmann::ordered_json tolerance_summary(const ToleranceRun& run, const std::vector<tolerance::OutputSpread>& outputs);

// The SVG: `s` against t, its nominal curve, nominal ± 2σ_lin (a filled band) and mean_mc ± 2σ_mc (dashed lines).
std::string tolerance_svg(const Scene& scene, const std::vector<double>& t, const tolerance::OutputSpread& s,
                          std::size_t samples);

}  // namespace phiq::tools
