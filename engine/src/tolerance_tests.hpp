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

inline constexpr double kUlpFloor = 64.0 * std::numeric_limits<double>::epsilon();

// Rounding floor of lengths and of other quantities at this q: a residual or a step cannot be resolved below a few
// ulps of the coordinates it is computed from, wherever the origin is.
struct Floors {
  double length = 0.0, other = 0.0;
};
// The tests below run every Newton iteration: one vectorised pass each over the model's precomputed scales.
inline Floors rounding_floors(const Model& model, const Eigen::VectorXd& q) {
  Floors f;
  if (q.size() == 0) return f;
  const auto& len = model.tolerance_scales().coordinate_is_length.array();
  f.length = kUlpFloor * (q.array().abs() * len).maxCoeff();
  f.other = kUlpFloor * (q.array().abs() * (1.0 - len)).maxCoeff();
  return f;
}

// Every row |Φ_i| ≤ tol · scale_i + floor_i (false on NaN).
inline bool residual_within(const Model& model, const Eigen::VectorXd& phi, double tol, const Floors& fl) {
  const ToleranceScales& s = model.tolerance_scales();
  return (phi.array().abs() <= tol * s.row_scale.array() + fl.other + (fl.length - fl.other) * s.row_is_length.array())
      .all();
}

// Row i with |Φ_i| / scale_i = `scaled` passes the same test (false on NaN).
inline bool row_within(const Model& model, Index i, double scaled, double tol, const Floors& fl) {
  const ToleranceScales& s = model.tolerance_scales();
  return scaled <= tol + (s.row_is_length(i) > 0.0 ? fl.length : fl.other) / s.row_scale(i);
}

// The rows `rows` (rows k = 0 … when null) of a scaled residual b, b_k = Φ_row / scale_row, pass the test.
inline bool scaled_rows_within(const Model& model, const Eigen::VectorXd& b, const std::vector<Index>* rows, double tol,
                               const Floors& fl) {
  for (Index k = 0; k < b.size(); ++k)
    if (!row_within(model, rows ? (*rows)[static_cast<std::size_t>(k)] : k, std::fabs(b(k)), tol, fl)) return false;
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

// "'name' 1.234e-05, 'other[1]' …" for diagnostics.
inline std::string describe_rows(const Model& model, const std::vector<std::pair<Index, double>>& rows) {
  std::ostringstream s;
  s.precision(3);
  for (std::size_t k = 0; k < rows.size(); ++k)
    s << (k ? ", " : "") << "'" << model.row_name(rows[k].first) << "' " << std::scientific << rows[k].second;
  return s.str();
}

}  // namespace phiq::detail
