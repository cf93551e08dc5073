// What a design parameter reaches (sensitivity.hpp, ParameterReach): the constraints whose data its models change,
// found once per sweep, and the derivatives along the parameter evaluated over those constraints only.
#include <algorithm>
#include <cmath>
#include <limits>

#include "phiq/sensitivity.hpp"
#include "phiq/text.hpp"
#include "solve/models_along.hpp"
#include "solve/sensitivity_internal.hpp"

namespace phiq {

// Whether `a` and `b` hold the same kinds of blocks with the same constraints on the same rows: then constraint i
// of block k is the same constraint in both, and its data can be compared.
bool detail::blocks_match(const Model& a, const Model& b) {
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

detail::AlongModel detail::along_model(const Model& model, const Model& m) {
  AlongModel a;
  const auto& blocks = model.blocks();
  a.differs.resize(blocks.size()), a.source.resize(blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    a.source[b] = m.blocks()[b].get();
    a.differs[b].assign(blocks[b]->size(), 0);
    for (std::size_t i = 0; i < blocks[b]->size(); ++i) a.differs[b][i] = !blocks[b]->same_data(i, *a.source[b]);
  }
  return a;  // (`at` empty: constraint i of m is at i)
}

detail::AlongModel detail::along_model_copied(const Model& model, const Model& m,
                                              std::vector<std::unique_ptr<ConstraintBlock>>& copies) {
  AlongModel a = along_model(model, m);
  const auto& blocks = m.blocks();
  copies.clear();
  a.at.resize(blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    copies.push_back(blocks[b]->empty_copy());
    a.at[b].assign(a.differs[b].size(), 0);
    for (std::size_t i = 0; i < a.differs[b].size(); ++i)
      if (a.differs[b][i]) a.at[b][i] = copies[b]->size(), copies[b]->append_copy(*blocks[b], i);
    a.source[b] = copies[b].get();
  }
  return a;
}

namespace {

// Where constraint i of block b is in the model along p that `a` describes, as (block, index): its own copy where
// it differs from the swept model's, the swept model's where it does not (then they are equal, datum by datum).
std::pair<const ConstraintBlock*, std::size_t> constraint_along(const Model& model, const detail::AlongModel& a,
                                                                std::size_t b, std::size_t i) {
  if (!a.differs[b][i]) return {model.blocks()[b].get(), i};
  return {a.source[b], a.at.empty() ? i : a.at[b][i]};
}

}  // namespace

ParameterReach detail::reach_of(const Model& model, const std::array<AlongModel, 4>& along, double step) {
  ParameterReach r;
  const auto& blocks = model.blocks();
  // Which constraints of each block the parameter reaches: those whose data differ in some model along it.
  std::vector<std::vector<char>> reached(blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    reached[b].assign(blocks[b]->size(), 0);
    for (const AlongModel& a : along)
      for (std::size_t i = 0; i < blocks[b]->size(); ++i) reached[b][i] |= a.differs[b][i];
  }
  // The coordinates they add whose scale moves with the parameter (a curve's length), with the relative rate of
  // that scale by the same fourth-order difference as the derivatives.
  constexpr int kCapacity = 4;
  for (std::size_t b = 0; b < blocks.size(); ++b)
    for (std::size_t i = 0; i < blocks[b]->size(); ++i) {
      if (!reached[b][i]) continue;
      Index coordinate[kCapacity];
      double scale[kCapacity], at[4][kCapacity];
      const int added = blocks[b]->added_coordinates(i, coordinate, scale, kCapacity);
      for (std::size_t k = 0; k < 4 && added > 0; ++k) {
        const auto [block, index] = constraint_along(model, along[k], b, i);
        block->added_coordinates(index, coordinate, at[k], kCapacity);
      }
      for (int a = 0; a < added; ++a) {
        const double rate = ((at[0][a] - at[3][a]) + 8.0 * (at[2][a] - at[1][a])) / (12.0 * step) / scale[a];
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
      if (!r.spans.empty() && r.spans.back().block == b && r.spans.back().end == i)
        ++r.spans.back().end;
      else
        r.spans.push_back({b, i, i + 1});
      for (std::size_t k = 0; k < rows_each; ++k) r.rows.push_back(block.first_row(i) + static_cast<Index>(k));
    }
  }
  std::sort(r.rows.begin(), r.rows.end());
  return r;
}

std::shared_ptr<const ReachedConstraints> detail::reached_of(const Model& model, const std::array<AlongModel, 4>& along,
                                                             const std::shared_ptr<const ParameterReach>& reach,
                                                             double step) {
  auto reached = std::make_shared<ReachedConstraints>();
  reached->reach = reach;
  reached->coordinates = model.num_coordinates(), reached->equations = model.num_equations();
  reached->nonzeros = model.jacobian_pattern().nnz();
  for (std::size_t k = 0; k < 4; ++k)
    for (const ParameterReach::Span& span : reach->spans) {
      std::unique_ptr<ConstraintBlock> copy = model.blocks()[span.block]->empty_copy();
      for (std::size_t i = span.begin; i < span.end; ++i) {
        const auto [block, index] = constraint_along(model, along[k], span.block, i);
        copy->append_copy(*block, index);
      }
      reached->along[k].push_back(std::move(copy));
    }
  // the rates of the data of the spans whose kind differentiates its own (the models move no coordinate): then
  // they are all that is read of the span, and its four copies go (one copy kept of the span, not four)
  reached->rates.resize(reach->spans.size());
  if (reach->comotion.empty())
    for (std::size_t j = 0; j < reach->spans.size(); ++j) {
      const ParameterReach::Span& span = reach->spans[j];
      reached->rates[j] =
          model.blocks()[span.block]->data_rates(span.begin, span.end,
                                                 {reached->along[0][j].get(), reached->along[1][j].get(),
                                                  reached->along[2][j].get(), reached->along[3][j].get()},
                                                 step);
      if (reached->rates[j])
        for (auto& copies : reached->along) copies[j] = copies[j]->empty_copy();
    }
  return reached;
}

ParameterReach parameter_reach(const Model& model, const OutputSensitivity& s) {
  if (detail::models_released(s) && s.reach) return *s.reach;  // found before the models went
  for (const auto& m : s.models)
    if (!m || !detail::blocks_match(model, *m)) return whole_model_reach(model);
  std::array<detail::AlongModel, 4> along;
  for (std::size_t k = 0; k < 4; ++k) along[k] = detail::along_model(model, *s.models[k]);
  return detail::reach_of(model, along, s.step);
}

void keep_reached_only(const Model& model, OutputSensitivity& s) {
  if (s.reached) return;
  for (const auto& m : s.models)
    if (!m || !detail::blocks_match(model, *m)) {  // a reach of everything: the models are kept
      if (!s.reach) s.reach = std::make_shared<const ParameterReach>(whole_model_reach(model));
      return;
    }
  // each model compared once: for the reach when it is not given, and for the constraints kept
  std::array<detail::AlongModel, 4> along;
  for (std::size_t k = 0; k < 4; ++k) along[k] = detail::along_model(model, *s.models[k]);
  if (!s.reach) s.reach = std::make_shared<const ParameterReach>(detail::reach_of(model, along, s.step));
  if (s.reach->everything) return;
  s.reached = detail::reached_of(model, along, s.reach, s.step);
  for (auto& m : s.models) m.reset();
}

void detail::evaluate_over_reach(const ParameterReach& reach, const Model* m, const ReachedConstraints* reached,
                                 std::size_t k, AlongParameter which, const double* q, const double* qd,
                                 const double* qdd, double t, double* f, double* scratch, bool skip_rated) {
  if (which != AlongParameter::kResidual)
    for (const Index r : reach.rows) f[r] = 0.0, scratch[r] = 0.0;
  if (!reached && !m) throw Error("a parameter's models along it were released (keep_reached_only())");
  for (std::size_t j = 0; j < reach.spans.size(); ++j) {
    const ParameterReach::Span& s = reach.spans[j];
    if (skip_rated && reached && reached->rates[j]) continue;
    // the span in the model, or its copy (the whole block) in the constraints kept of it
    const ConstraintBlock& block = reached ? *reached->along[k][j] : *m->blocks()[s.block];
    const std::size_t begin = reached ? 0 : s.begin, end = reached ? block.size() : s.end;
    switch (which) {
      case AlongParameter::kResidual:
        block.residual(begin, end, q, t, f);
        break;
      case AlongParameter::kVelocityTerm:  // Φq q̇ into f, Φt into the scratch (it writes time-dependent rows only)
        block.add_jacobian_product(begin, end, q, t, qd, f);
        block.phi_t(begin, end, q, t, scratch);
        break;
      case AlongParameter::kAccelerationTerm:  // Φq q̈ into f, γ into the scratch
        block.add_jacobian_product(begin, end, q, t, qdd, f);
        block.gamma(begin, end, q, qd, t, scratch);
        break;
    }
  }
  if (which == AlongParameter::kVelocityTerm)
    for (const Index r : reach.rows) f[r] += scratch[r];
  if (which == AlongParameter::kAccelerationTerm)
    for (const Index r : reach.rows) f[r] -= scratch[r];
}

void detail::complete_along(const Model& model, OutputSensitivity& s, bool keep,
                            const std::function<std::shared_ptr<const Model>(std::size_t k)>& read_at,
                            const std::function<void(const std::string&)>& fail) {
  // A step that leaves p ± h or p ± 2h on p (or two of them on one double) differences a parameter that did not
  // move: every sensitivity would read 0, and no constraint would seem to read p.
  double below = -std::numeric_limits<double>::infinity();
  for (const double shift : {-2.0, -1.0, 0.0, 1.0, 2.0}) {
    const double at = s.value + shift * s.step;
    if (!(at > below)) {
      const std::string why = "sensitivity to '" + s.name + "': the difference step " + shortest(s.step) +
                              " does not move " + s.name + " = " + shortest(s.value) + " (" + s.name + " ± h, " +
                              s.name + " ± 2h and " + s.name + " must be five doubles; the default step is " +
                              shortest(default_sensitivity_step(s.value)) + ")";
      fail(why);
      throw Error(why);  // (fail throws)
    }
    below = at;
  }
  std::array<AlongModel, 4> along;
  std::array<std::vector<std::unique_ptr<ConstraintBlock>>, 4> copies;
  bool whole = keep;
  for (std::size_t k = 0; k < 4; ++k) {
    std::shared_ptr<const Model> m = read_at(k);
    if (std::string why = check_model_along(model, s, k, *m); !why.empty()) {
      fail(why);
      throw Error(why);  // (fail throws)
    }
    whole = whole || !blocks_match(model, *m);
    if (whole)
      s.models[k] = std::move(m);
    else
      along[k] = along_model_copied(model, *m, copies[k]);
  }
  if (whole) {
    for (std::size_t k = 0; k < 4; ++k)
      if (!s.models[k]) s.models[k] = read_at(k);  // (read before their blocks were found not to match)
    if (const std::string why = check_sensitivity_models(model, s); !why.empty()) {
      fail(why);
      throw Error(why);
    }
    s.reach = std::make_shared<const ParameterReach>(parameter_reach(model, s));
    return;
  }
  s.reach = std::make_shared<const ParameterReach>(reach_of(model, along, s.step));
  s.reached = reached_of(model, along, s.reach, s.step);
}

OutputSensitivity sensitivity_along(const Model& model, const std::string& name, double value,
                                    const ModelAtParameter& build, double step, bool keep_models) {
  if (!build) throw Error("sensitivity to '" + name + "': no function builds the model along it");
  OutputSensitivity s;
  s.name = name, s.value = value, s.step = step > 0.0 ? step : default_sensitivity_step(value);
  if (!std::isfinite(value) || !std::isfinite(s.step))
    throw Error("sensitivity to '" + name + "': its value and step must be finite");
  detail::complete_along(
      model, s, keep_models,
      [&](std::size_t k) { return std::make_shared<const Model>(build(value + detail::kShift[k] * s.step, &model)); },
      [](const std::string& why) { throw Error(why); });
  return s;
}

}  // namespace phiq
