// phiq's expression parser: text → GiNaC expression, with every constant part folded in double precision so that
// GiNaC never does exact arithmetic on numbers (parser.cpp says why). Internal to engine/src/expression/.
#pragma once

#include <ginac/ginac.h>

#include <functional>
#include <map>
#include <optional>
#include <string>

namespace phiq::detail {

// What a name stands for: a constant value, or a GiNaC symbol (a coordinate or t).
struct ParsedName {
  std::optional<double> value;
  GiNaC::ex symbol;
};
// Resolves a name, or throws phiq::Error when it is unknown or not allowed.
using NameLookup = std::function<ParsedName(const std::string&)>;
// The rate d/dt of an expression along the motion (`der(…)`), a GiNaC expression in q, q̇ and t; null where an
// expression may not read velocities.
using RateOf = std::function<GiNaC::ex(const GiNaC::ex&)>;

// The GiNaC expression of `text`. Each folded constant reaches it as a real symbol whose value is entered in
// value_of_constant (for the tape builder). Throws phiq::Error with a one-line message (column, offending token)
// when the text is malformed; GiNaC's own refusals escape as its exceptions. `der(u)` is rate_of(u) (0 for a
// constant u); refused where rate_of is null.
GiNaC::ex parse_expression(const std::string& text, NameLookup name, std::map<std::string, double>& value_of_constant,
                           RateOf rate_of = nullptr);

}  // namespace phiq::detail
