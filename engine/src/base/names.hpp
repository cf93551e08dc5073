// The one rule for names: letters, digits and '_', not starting with a digit. Parameters, coordinates, points,
// bodies, vectors, family indices, the names inside family texts and the identifiers of equation texts all follow
// it; it has a file of its own so that the scene's YAML cursor, its family index language and the expression parser
// read names by the same rule.
#pragma once

#include <string>

namespace phiq::detail {

// ASCII, as the "C" locale's isalpha/isalnum say, without a library call per character: families check millions
// of names.
inline bool is_name_start(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
inline bool is_name_char(char c) { return is_name_start(c) || (c >= '0' && c <= '9'); }

// A whole name: letters, digits and '_', not starting with a digit.
inline bool valid_name(const std::string& s) {
  if (s.empty() || !is_name_start(s[0])) return false;
  for (char c : s)
    if (!is_name_char(c)) return false;
  return true;
}

}  // namespace phiq::detail
