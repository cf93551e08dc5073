// The spread of one output of a sweep over the toleranced parameters, two ways: first order from the exact
// sensitivities (σ_lin = sqrt(gᵀ Σ g), g = ∂y/∂p) and Monte Carlo from the swept samples (their sample standard
// deviation and mean), and how well the two agree row by row, in units of the Monte Carlo standard error.
#pragma once

#include <Eigen/Dense>

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace phiq::tolerance {

// sqrt(gᵀ Σ g); NaN when g is not finite (a singular position, where the sensitivities are not defined).
double linear_sd(const Eigen::VectorXd& g, const Eigen::MatrixXd& sigma);

// The Monte Carlo samples of a sweep: `values[c]` holds case c's rows (rows × outputs, row after row; empty for a
// case that failed), cases in sample order.
struct CaseValues {
  std::size_t rows = 0, outputs = 0;
  std::vector<std::vector<double>> values;
  std::size_t succeeded() const;
};

// How the two estimates of one output agree.
struct Agreement {
  // max over the rows compared of |σ_mc − σ_lin| / se, se = σ_lin / sqrt(2 (N − 1)) (σ_mc's where σ_lin is below
  // the floor): the standard error of the sample standard deviation of N normal values. 0 when no row is compared.
  double worst = 0.0;
  double worst_t = std::numeric_limits<double>::quiet_NaN();  // where (t), NaN when no row is compared
  double sd_linear_at_worst = 0.0, sd_mc_at_worst = 0.0;
  bool disagrees = false;               // worst > the threshold
  std::size_t rows_compared = 0;        // rows where either spread is above the floor
  std::size_t rows_without_spread = 0;  // both at or below the floor (a driven coordinate: no spread to compare)
  std::size_t rows_singular = 0;        // σ_lin not finite: the sensitivities are not defined there
};

// One output over the sweep's rows.
struct OutputSpread {
  std::string name;  // dotted (`xB`, `xB.v`)
  std::vector<double> nominal, sd_linear, sd_mc, mean_mc;
  Agreement agreement;
};

// Fills out[o].sd_mc and mean_mc from the cases that succeeded (summed in case order: the same bytes whatever the
// threads); NaN with fewer than two.
void monte_carlo_moments(const CaseValues& cases, std::vector<OutputSpread>& out);

// The agreement of `s` at the rows of `t`, from `samples` successful cases. A row whose spreads are both at or
// below `floor` (the solver's noise: a sample spread that small measures convergence, not the tolerances) is not
// compared.
Agreement agreement(const OutputSpread& s, const std::vector<double>& t, std::size_t samples, double floor,
                    double threshold);

}  // namespace phiq::tolerance
