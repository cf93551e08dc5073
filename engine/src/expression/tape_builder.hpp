// Compilation of GiNaC expressions into a register tape whose order of operations is phiq's own (the same in
// every process), with constants folded and common subexpressions shared. Internal to engine/src/expression/.
#pragma once

#include <ginac/ginac.h>

#include <map>
#include <string>
#include <vector>

#include "phiq/expression.hpp"

namespace phiq::detail {

// One tape computing `outputs` (in that order) from q, q̇ and t. Symbols are read as coordinates
// (coord_of_symbol), folded constants (value_of_constant), q̇ ("qd:<index>") or t ("t"). Throws phiq::Error naming
// `text` when a term cannot be compiled or the tape grows past CompiledExpression::kMaxTapeSize.
Tape compile_tape(const std::vector<GiNaC::ex>& outputs, const std::map<std::string, Index>& coord_of_symbol,
                  const std::map<std::string, double>& value_of_constant, const std::string& text);

}  // namespace phiq::detail
