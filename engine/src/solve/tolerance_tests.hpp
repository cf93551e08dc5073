// Internal: the tolerance tests and row diagnostics shared by the Newton solve (kinematics.cpp) and the assembly
// (assembly.cpp), so that both accept a position by the same rule and name the same worst constraints. Not installed.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "phiq/model.hpp"

namespace phiq::detail {

inline constexpr double kUlpFloor = ToleranceScales::kUlpFloor;

// The tests below run every Newton iteration: the floor of a row (Model::row_rounding_floor(), from that one
// constraint's Jacobian at (q, t)) is looked at only when the row fails without it.

// Row i with |Φ_i| / scale_i = `scaled` is within tol · scale_i + floor_i at (q, t) (false on NaN).
inline bool row_within(const Model& model, Index i, double scaled, double tol, const Eigen::VectorXd& q, double t) {
  if (scaled <= tol) return true;
  return scaled <= tol + model.row_rounding_floor(i, q.data(), t) / model.tolerance_scales().row_scale(i);
}

// Every row |Φ_i| ≤ tol · scale_i + floor_i at (q, t) (false on NaN).
inline bool residual_within(const Model& model, const Eigen::VectorXd& phi, double tol, const Eigen::VectorXd& q,
                            double t) {
  const Eigen::VectorXd& rs = model.tolerance_scales().row_scale;
  for (Index i = 0; i < phi.size(); ++i) {
    const double a = std::fabs(phi(i));
    if (a <= tol * rs(i)) continue;
    if (!(a <= tol * rs(i) + model.row_rounding_floor(i, q.data(), t))) return false;
  }
  return true;
}

// The rows `rows` (rows k = 0 … when null) of a scaled residual b, b_k = Φ_row / scale_row, pass the test at (q, t).
inline bool scaled_rows_within(const Model& model, const Eigen::VectorXd& b, const std::vector<Index>* rows, double tol,
                               const Eigen::VectorXd& q, double t) {
  for (Index k = 0; k < b.size(); ++k)
    if (!row_within(model, rows ? (*rows)[static_cast<std::size_t>(k)] : k, std::fabs(b(k)), tol, q, t)) return false;
  return true;
}

// The k largest |Φ_i| / scale_i (NaN as +inf) among `among` (all rows when null), largest first.
inline std::vector<std::pair<Index, double>> worst_rows(const Model& model, const Eigen::VectorXd& phi, int k,
                                                        const std::vector<Index>* among = nullptr) {
  const Eigen::VectorXd& rs = model.tolerance_scales().row_scale;
  std::vector<std::pair<Index, double>> rows;
  auto add = [&](Index i) {
    const double r = std::fabs(phi(i)) / rs(i);
    rows.emplace_back(i, std::isnan(r) ? std::numeric_limits<double>::infinity() : r);
  };
  if (among) {
    for (Index i : *among) add(i);
  } else {
    for (Index i = 0; i < phi.size(); ++i) add(i);
  }
  const std::size_t kk = std::min<std::size_t>(static_cast<std::size_t>(k), rows.size());
  std::partial_sort(rows.begin(), rows.begin() + static_cast<std::ptrdiff_t>(kk), rows.end(),
                    [](const auto& a, const auto& b) { return a.second > b.second; });
  rows.resize(kk);
  return rows;
}

// The largest of ratios |e_j| / allowed_j fed one by one (a NaN ratio counts as +inf), dividing only where a ratio
// may exceed the largest so far: the passes that run every drive step (a sweep's predictor and its branch check)
// then divide a few times per pass, not once per coordinate.
struct WorstRatio {
  double worst = 0.0;
  void add(double magnitude, double allowed) {
    if (magnitude <= worst * allowed) return;
    const double r = magnitude / allowed;
    worst = std::isnan(r) ? std::numeric_limits<double>::infinity() : std::max(worst, r);
  }
};

// max_j |a_j − b_j| / (tol · scale_j + floor_j at `at`), the size of a − b in units of the tolerance test
// (scaled_step() of a − b), without forming a − b. NaN gives +inf.
inline double scaled_distance(const Model& model, const double* a, const double* b, const double* at, double tol) {
  const double* cs = model.tolerance_scales().coordinate_scale.data();
  WorstRatio w;
  for (Index j = 0, n = model.num_coordinates(); j < n; ++j)
    w.add(std::fabs(a[j] - b[j]), tol * cs[j] + kUlpFloor * std::fabs(at[j]));
  return w.worst;
}

// "'name' 1.234e-05, 'other[1]' …" for diagnostics.
inline std::string describe_rows(const Model& model, const std::vector<std::pair<Index, double>>& rows) {
  std::ostringstream s;
  s.precision(3);
  for (std::size_t k = 0; k < rows.size(); ++k)
    s << (k ? ", " : "") << "'" << model.row_name(rows[k].first) << "' " << std::scientific << rows[k].second;
  return s.str();
}

}  // namespace phiq::detail
