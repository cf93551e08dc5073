// How an expression's errors read: "expression "<text>": <what>", one line, with GiNaC's own messages trimmed to
// what a user can act on. Shared by the parser, the tape builder and CompiledExpression::compile, which all refuse
// text. Internal to engine/src/expression/.
#pragma once

#include <sstream>
#include <string>

#include "phiq/text.hpp"
#include "phiq/types.hpp"

namespace phiq::detail {

// "expression "<first 60 characters>...": <what>" — built with a stream: GCC 12 warns falsely (-Wrestrict,
// PR 105329) on "literal" + std::string temporaries.
inline Error expression_error(const std::string& text, const std::string& what) {
  std::ostringstream s;
  s << "expression \"" << single_line(text.substr(0, 60)) << (text.size() > 60 ? "..." : "") << "\": "
    << single_line(what);
  return Error(s.str());
}

// GiNaC's messages carry its own source location; keep what a user can act on.
inline std::string clean_ginac_message(std::string m) {
  const auto p = m.find('\n');
  if (p != std::string::npos) m = m.substr(0, p);
  const std::string prefix = "GiNaC: ";
  if (m.rfind(prefix, 0) == 0) m = m.substr(prefix.size());
  return m;
}

}  // namespace phiq::detail
