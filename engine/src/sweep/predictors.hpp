// What the sweep knows of its predictors beyond their public names and choice (phiq/sweep.hpp): how much history
// each formula reads. The names, the choice and the formulas themselves (Sweeper::predict) are in predictors.cpp.
#pragma once

#include "phiq/sweep.hpp"

namespace phiq::detail {

// The rows before the current one that `p` extrapolates from, and one more for its error estimate (0 for kAuto,
// which a sweep resolves first: effective_predictor()).
int predictor_history_depth(Predictor p);

}  // namespace phiq::detail
