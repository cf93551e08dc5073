// Internal: the models along a design parameter as its reach reads them (sensitivity.hpp, ParameterReach,
// ReachedConstraints): which constraints of each differ from the swept model's, where those are, and the reach and
// the kept constraints made of them, whether the models are read in place (parameter_reach(), keep_reached_only())
// or one at a time and released (sensitivity_along(): one model along p in memory at once, not four).
#pragma once

#include <algorithm>
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "phiq/sensitivity.hpp"

namespace phiq::detail {

// The shifts of the four models along a parameter, in units of the step h: p − 2h, p − h, p + h, p + 2h.
inline constexpr std::array<double, 4> kShift = {-2.0, -1.0, 1.0, 2.0};

// What the reach reads of one model along the parameter: which constraints differ from the swept model's, and where
// each that differs is: its block (`source`) and its index there (`at`; empty: the same index, `source` the
// model's own blocks). The swept model's constraint stands for one that does not differ (equal datum by datum).
struct AlongModel {
  std::vector<std::vector<char>> differs;      // [block][constraint]
  std::vector<const ConstraintBlock*> source;  // [block]
  std::vector<std::vector<std::size_t>> at;    // [block][constraint], for those that differ
};

// Whether `a` and `b` hold the same kinds of blocks with the same constraints on the same rows: then constraint i
// of block k is the same constraint in both, and its data can be compared.
bool blocks_match(const Model& a, const Model& b);

// Whether `s` holds only the constraints its reach keeps of its models (keep_reached_only()): its models released.
inline bool models_released(const OutputSensitivity& s) {
  return s.reached && std::none_of(s.models.begin(), s.models.end(), [](const auto& m) { return m != nullptr; });
}

// check_sensitivity_models() for model k (at p + kShift[k] h) alone, `m` standing for s.models[k].
std::string check_model_along(const Model& model, const OutputSensitivity& s, std::size_t k, const Model& m);

// Model `m` along the parameter (its blocks match `model`'s), read in place: it must outlive the result.
AlongModel along_model(const Model& model, const Model& m);

// The same with the constraints that differ copied into `copies` (one block per block of `model`): `m` may go.
AlongModel along_model_copied(const Model& model, const Model& m,
                              std::vector<std::unique_ptr<ConstraintBlock>>& copies);

// The reach of the four models along p (parameter_reach()), h = `step`.
ParameterReach reach_of(const Model& model, const std::array<AlongModel, 4>& along, double step);

// The constraints of `reach` as the four models hold them (keep_reached_only()).
std::shared_ptr<const ReachedConstraints> reached_of(const Model& model, const std::array<AlongModel, 4>& along,
                                                     const std::shared_ptr<const ParameterReach>& reach, double step);

// `s` (name, value and step set) completed with the models along p that read_at(k) gives (k = 0 … 3: at p − 2h,
// − h, + h, + 2h), each read, checked and compared with `model` in turn, so that one is in memory at a time: its
// reach and the constraints that differ (ReachedConstraints), or the four models whole when `keep` or when their
// blocks do not match `model`'s (then p reaches everything). `fail` receives check_sensitivity_models()' line for
// a model that cannot stand for `model` moved along p, and throws (sensitivity_along() of scenes and of models).
void complete_along(const Model& model, OutputSensitivity& s, bool keep,
                    const std::function<std::shared_ptr<const Model>(std::size_t k)>& read_at,
                    const std::function<void(const std::string&)>& fail);

}  // namespace phiq::detail
