// What the measurement of `phiq sweep-accuracy` and its reports (CSV, JSON, progress lines) write the same way:
// the name of a Newton setting, and a number to a few digits that is an empty cell when it was not measured (NaN).
#pragma once

#include <cmath>
#include <string>

#include "phiq/phiq.hpp"
#include "phiq/text.hpp"

namespace phiq::tools::detail {

// The words of --newton: "modified" (the Jacobian kept while Newton converges fast) or "full".
inline const char* newton_name(JacobianUpdate u) { return u == JacobianUpdate::kWhenSlow ? "modified" : "full"; }

// `v` to `digits` significant digits (phiq::significant), or "" for NaN: an error the setting has none of.
inline std::string significant_or_empty(double v, int digits) {
  return std::isnan(v) ? std::string() : significant(v, digits);
}

}  // namespace phiq::tools::detail
