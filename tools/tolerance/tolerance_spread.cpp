// First-order and Monte Carlo spreads of an output and their agreement (tolerance_spread.hpp).
#include "tolerance_spread.hpp"

#include <cmath>

namespace phiq::tolerance {

double linear_sd(const Eigen::VectorXd& g, const Eigen::MatrixXd& sigma) {
  if (!g.allFinite()) return std::numeric_limits<double>::quiet_NaN();
  return std::sqrt(std::max(0.0, g.dot(sigma * g)));
}

std::size_t CaseValues::succeeded() const {
  std::size_t n = 0;
  for (const auto& v : values) n += !v.empty();
  return n;
}

void monte_carlo_moments(const CaseValues& cases, std::vector<OutputSpread>& out) {
  const std::size_t n = cases.succeeded();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t o = 0; o < cases.outputs; ++o) {
    out[o].mean_mc.assign(cases.rows, nan);
    out[o].sd_mc.assign(cases.rows, nan);
  }
  if (n < 2) return;
  // two passes (mean, then squared deviations from it), in case order: exact enough and reproducible
  std::vector<double> sum(cases.rows * cases.outputs, 0.0), sq(cases.rows * cases.outputs, 0.0);
  for (const auto& v : cases.values)
    if (!v.empty())
      for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += v[i];
  for (double& s : sum) s /= static_cast<double>(n);
  for (const auto& v : cases.values)
    if (!v.empty())
      for (std::size_t i = 0; i < sq.size(); ++i) sq[i] += (v[i] - sum[i]) * (v[i] - sum[i]);
  for (std::size_t r = 0; r < cases.rows; ++r)
    for (std::size_t o = 0; o < cases.outputs; ++o) {
      const std::size_t i = r * cases.outputs + o;
      out[o].mean_mc[r] = sum[i];
      out[o].sd_mc[r] = std::sqrt(sq[i] / static_cast<double>(n - 1));
    }
}

Agreement agreement(const OutputSpread& s, const std::vector<double>& t, std::size_t samples, double floor,
                    double threshold) {
  Agreement a;
  if (samples < 2) return a;
  const double root = std::sqrt(2.0 * static_cast<double>(samples - 1));
  for (std::size_t r = 0; r < t.size(); ++r) {
    const double lin = s.sd_linear[r], mc = s.sd_mc[r];
    if (!std::isfinite(lin)) {
      ++a.rows_singular;
      continue;
    }
    if (lin <= floor && mc <= floor) {
      ++a.rows_without_spread;
      continue;
    }
    ++a.rows_compared;
    // the standard error under the first-order model; where that model says "no spread" and the samples have
    // one, their own
    const double se = (lin > floor ? lin : mc) / root;
    const double z = std::fabs(mc - lin) / se;
    if (!(z <= a.worst)) {  // (a NaN σ_mc counts as the worst)
      a.worst = std::isnan(z) ? std::numeric_limits<double>::infinity() : z;
      a.worst_t = t[r];
      a.sd_linear_at_worst = lin, a.sd_mc_at_worst = mc;
    }
  }
  a.disagrees = a.worst > threshold;
  return a;
}

}  // namespace phiq::tolerance
