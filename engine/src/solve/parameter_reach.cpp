// What a design parameter reaches (sensitivity.hpp, ParameterReach): the constraints whose data its models change,
// found once per sweep, and the derivatives along the parameter evaluated over those constraints only.
#include <algorithm>
#include <cmath>

#include "phiq/sensitivity.hpp"
#include "solve/sensitivity_internal.hpp"

namespace phiq {

namespace {

// Whether `a` and `b` hold the same kinds of blocks with the same constraints on the same rows: then constraint i
// of block k is the same constraint in both, and its data can be compared.
bool blocks_match(const Model& a, const Model& b) {
  const auto& x = a.blocks();
  const auto& y = b.blocks();
  if (x.size() != y.size()) return false;
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (std::string_view(x[k]->kind()) != y[k]->kind() || x[k]->size() != y[k]->size()) return false;
    for (std::size_t i = 0; i < x[k]->size(); ++i)
      if (x[k]->first_row(i) != y[k]->first_row(i)) return false;
  }
  return true;
}

}  // namespace

ParameterReach whole_model_reach(const Model& model) {
  ParameterReach r;
  r.everything = true;
  const auto& blocks = model.blocks();
  for (std::size_t b = 0; b < blocks.size(); ++b)
    if (blocks[b]->size() > 0) r.spans.push_back({b, 0, blocks[b]->size()});
  r.rows.resize(static_cast<std::size_t>(model.num_equations()));
  for (std::size_t i = 0; i < r.rows.size(); ++i) r.rows[i] = static_cast<Index>(i);
  return r;
}

ParameterReach parameter_reach(const Model& model, const OutputSensitivity& s) {
  for (const auto& m : s.models)
    if (!m || !blocks_match(model, *m)) return whole_model_reach(model);
  ParameterReach r;
  const auto& blocks = model.blocks();
  // Which constraints of each block the parameter reaches: those whose data differ in some model along it.
  std::vector<std::vector<char>> reached(blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const ConstraintBlock& block = *blocks[b];
    reached[b].assign(block.size(), 0);
    for (std::size_t i = 0; i < block.size(); ++i)
      for (const auto& m : s.models)
        if (!block.same_data(i, *m->blocks()[b])) reached[b][i] = 1;
  }
  // The coordinates they add whose scale moves with the parameter (a curve's length), with the relative rate of
  // that scale by the same fourth-order difference as the derivatives.
  constexpr int kCapacity = 4;
  for (std::size_t b = 0; b < blocks.size(); ++b)
    for (std::size_t i = 0; i < blocks[b]->size(); ++i) {
      if (!reached[b][i]) continue;
      Index coordinate[kCapacity];
      double scale[kCapacity], along[4][kCapacity];
      const int added = blocks[b]->added_coordinates(i, coordinate, scale, kCapacity);
      for (std::size_t k = 0; k < 4 && added > 0; ++k)
        s.models[k]->blocks()[b]->added_coordinates(i, coordinate, along[k], kCapacity);
      for (int a = 0; a < added; ++a) {
        const double rate =
            ((along[0][a] - along[3][a]) + 8.0 * (along[2][a] - along[1][a])) / (12.0 * s.step) / scale[a];
        if (coordinate[a] >= 0 && rate != 0.0 && std::isfinite(rate)) r.comotion.push_back({coordinate[a], rate});
      }
    }
  // Every constraint that reads a co-moving coordinate is evaluated along p too (its rows move with the coordinate).
  if (!r.comotion.empty()) {
    std::vector<char> moved_row(static_cast<std::size_t>(model.num_equations()), 0);
    const CscPattern& pattern = model.jacobian_pattern();
    for (const ParameterReach::Comotion& c : r.comotion)
      for (Index k = pattern.col_ptr[c.coordinate]; k < pattern.col_ptr[c.coordinate + 1]; ++k)
        moved_row[static_cast<std::size_t>(pattern.row_idx[k])] = 1;
    for (std::size_t b = 0; b < blocks.size(); ++b)
      for (std::size_t i = 0; i < blocks[b]->size(); ++i)
        for (int k = 0; k < blocks[b]->rows_per_constraint(); ++k)
          if (moved_row[static_cast<std::size_t>(blocks[b]->first_row(i) + k)]) reached[b][i] = 1;
  }
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const ConstraintBlock& block = *blocks[b];
    const std::size_t rows_each = static_cast<std::size_t>(block.rows_per_constraint());
    for (std::size_t i = 0; i < block.size(); ++i) {
      if (!reached[b][i]) continue;
      if (!r.spans.empty() && r.spans.back().block == b && r.spans.back().end == i) ++r.spans.back().end;
      else r.spans.push_back({b, i, i + 1});
      for (std::size_t k = 0; k < rows_each; ++k) r.rows.push_back(block.first_row(i) + static_cast<Index>(k));
    }
  }
  std::sort(r.rows.begin(), r.rows.end());
  return r;
}

void detail::evaluate_over_reach(const ParameterReach& reach, const Model& m, AlongParameter which, const double* q,
                                 const double* qd, const double* qdd, double t, double* f, double* scratch) {
  const auto& blocks = m.blocks();
  if (which != AlongParameter::kResidual)
    for (const Index r : reach.rows) f[r] = 0.0, scratch[r] = 0.0;
  for (const ParameterReach::Span& s : reach.spans) {
    const ConstraintBlock& block = *blocks[s.block];
    switch (which) {
      case AlongParameter::kResidual: block.residual(s.begin, s.end, q, t, f); break;
      case AlongParameter::kVelocityTerm:  // Φq q̇ into f, Φt into the scratch (it writes time-dependent rows only)
        block.add_jacobian_product(s.begin, s.end, q, t, qd, f);
        block.phi_t(s.begin, s.end, q, t, scratch);
        break;
      case AlongParameter::kAccelerationTerm:  // Φq q̈ into f, γ into the scratch
        block.add_jacobian_product(s.begin, s.end, q, t, qdd, f);
        block.gamma(s.begin, s.end, q, qd, t, scratch);
        break;
    }
  }
  if (which == AlongParameter::kVelocityTerm)
    for (const Index r : reach.rows) f[r] += scratch[r];
  if (which == AlongParameter::kAccelerationTerm)
    for (const Index r : reach.rows) f[r] -= scratch[r];
}

}  // namespace phiq
