// The GiNaC side of expressions: the functions an expression may call (one table for the parser and the tape
// builder) and phiq_pow, the power with a constant exponent that GiNaC differentiates by its closed form. Separate
// from the parser and the tape builder because both speak this vocabulary. Internal to engine/src/expression/.
#pragma once

#include <ginac/ginac.h>

#include <map>
#include <string>

#include "phiq/expression.hpp"

namespace phiq::detail {

// The functions an expression may call: the tape instruction, the number of arguments, and how GiNaC builds the
// call (one of make1, make2). One table for the parser (names, arity, what to build) and the tape builder (what a
// GiNaC function of that name computes).
struct FunctionSpec {
  Tape::Op op;
  int arity;
  GiNaC::ex (*make1)(const GiNaC::ex&) = nullptr;
  GiNaC::ex (*make2)(const GiNaC::ex&, const GiNaC::ex&) = nullptr;
};
const std::map<std::string, FunctionSpec>& supported_functions();
// The names of supported_functions(), space-separated, for messages.
std::string supported_function_list();

// u^p for an exponent p that is a constant of the text, as phiq_pow(u, p) (see symbolic.cpp for why).
GiNaC::ex constant_power(const GiNaC::ex& u, const GiNaC::ex& p);
// |u| as phiq_abs(u), differentiated to phiq_sign(u) u' (symbolic.cpp says why not GiNaC's abs).
GiNaC::ex absolute_value(const GiNaC::ex& u);
// sign(u) as phiq_sign(u) (−1, 0 or 1), its derivative 0: a Coulomb friction's direction, −F sign(der(x)).
GiNaC::ex sign_of(const GiNaC::ex& u);
// A power of either kind: GiNaC's own (numeric exponents from its derivatives, sqrt; exponents that are not
// constant) or phiq_pow; op(0) is the base and op(1) the exponent of both.
bool is_power(const GiNaC::ex& e);

}  // namespace phiq::detail
