// How an expression's errors read: "expression "<text>": <what>", one line, with GiNaC's own messages trimmed to
// what a user can act on. Shared by the parser, the tape builder and CompiledExpression::compile, which all refuse
// text. Internal to engine/src/expression/.
#pragma once

#include <algorithm>
#include <sstream>
#include <string>

#include "phiq/text.hpp"
#include "phiq/types.hpp"

namespace phiq::detail {

// "expression "<first 60 characters>...": <what>" — built with a stream: GCC 12 warns falsely (-Wrestrict,
// PR 105329) on "literal" + std::string temporaries.
inline Error expression_error(const std::string& text, const std::string& what) {
  std::size_t cut = std::min<std::size_t>(text.size(), 60);
  // whole code points: never cut inside a UTF-8 sequence
  while (cut > 0 && cut < text.size() && (static_cast<unsigned char>(text[cut]) & 0xc0) == 0x80) --cut;
  std::ostringstream s;
  s << "expression \"" << single_line(text.substr(0, cut)) << (cut < text.size() ? "..." : "")
    << "\": " << single_line(what);
  return Error(s.str());
}

// For a character that looks like an operator, a parenthesis or a space but is not ASCII (text pasted from a
// document: U+2212 for '-', U+00D7 for '*'), what to write instead: "; '−' is U+2212 MINUS SIGN: write '-'".
inline std::string lookalike_hint(const std::string& token) {
  struct Lookalike {
    const char* utf8;
    const char* name;
    const char* ascii;
  };
  static const Lookalike table[] = {
      {"\u2212", "U+2212 MINUS SIGN", "-"},
      {"\u2010", "U+2010 HYPHEN", "-"},
      {"\u2011", "U+2011 NON-BREAKING HYPHEN", "-"},
      {"\u2012", "U+2012 FIGURE DASH", "-"},
      {"\u2013", "U+2013 EN DASH", "-"},
      {"\u2014", "U+2014 EM DASH", "-"},
      {"\ufe63", "U+FE63 SMALL HYPHEN-MINUS", "-"},
      {"\uff0d", "U+FF0D FULLWIDTH HYPHEN-MINUS", "-"},
      {"\u00d7", "U+00D7 MULTIPLICATION SIGN", "*"},
      {"\u22c5", "U+22C5 DOT OPERATOR", "*"},
      {"\u00b7", "U+00B7 MIDDLE DOT", "*"},
      {"\u2217", "U+2217 ASTERISK OPERATOR", "*"},
      {"\u2219", "U+2219 BULLET OPERATOR", "*"},
      {"\u00f7", "U+00F7 DIVISION SIGN", "/"},
      {"\u2215", "U+2215 DIVISION SLASH", "/"},
      {"\u2044", "U+2044 FRACTION SLASH", "/"},
      {"\uff0b", "U+FF0B FULLWIDTH PLUS SIGN", "+"},
      {"\uff08", "U+FF08 FULLWIDTH LEFT PARENTHESIS", "("},
      {"\uff09", "U+FF09 FULLWIDTH RIGHT PARENTHESIS", ")"},
      {"\u00a0", "U+00A0 NO-BREAK SPACE", " "},
      {"\u2009", "U+2009 THIN SPACE", " "},
      {"\u202f", "U+202F NARROW NO-BREAK SPACE", " "},
      {"\u03c0", "U+03C0 GREEK SMALL LETTER PI", "pi"},
      {"\u2032", "U+2032 PRIME", "'"},
      {"\u00b2", "U+00B2 SUPERSCRIPT TWO", "^2"},
      {"\u00b3", "U+00B3 SUPERSCRIPT THREE", "^3"},
      {"\u221a", "U+221A SQUARE ROOT", "sqrt("},
  };
  for (const Lookalike& l : table)
    if (token == l.utf8) return std::string("; '") + l.utf8 + "' is " + l.name + ": write '" + l.ascii + "'";
  if (!token.empty() && static_cast<unsigned char>(token[0]) >= 0x80)
    return "; expressions are written in ASCII (+ - * / ^, parentheses, names, numbers)";
  return "";
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
