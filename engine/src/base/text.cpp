// Numbers as text and one-line messages (phiq/text.hpp).
#include "phiq/text.hpp"

#include <charconv>
#include <cstdio>
#include <sstream>

namespace phiq {

std::string shortest(double v) {
  char buf[32];
  auto [p, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc() ? std::string(buf, p) : std::string("?");
}

std::string shortest_unsigned_zero(double v) { return shortest(v == 0.0 ? 0.0 : v); }

std::string significant(double v, int digits) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

std::string scientific(double v, int digits) {
  std::ostringstream s;
  s.precision(digits);
  s << std::scientific << v;
  return s.str();
}

std::string format_time(double t) { return significant(t, 10); }

std::string single_line(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (unsigned char c : text) {
    if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (c == '\t') out += "\\t";
    else if (c < 0x20 || c == 0x7f) {
      const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    } else {
      out += static_cast<char>(c);
    }
  }
  return out;
}

}  // namespace phiq
