/// @file
/// The one place where phiq turns numbers into text and makes messages fit one line: every message, CSV cell and
/// generated scene writes its numbers through these functions, so that the same double reads the same everywhere.
#pragma once

#include <cstddef>
#include <string>

namespace phiq {

/// The shortest decimal that reads back as the same double (std::to_chars): what results and scenes are written
/// with, so that a file read back gives the bits that were computed ("0.1", "1e-07", "-1.5599999999999665").
/// Negative zero is written "-0"; see shortest_unsigned_zero(). Thread-safe.
std::string shortest(double v);
/// shortest(), with −0 written as "0" (generated scenes, where the sign of a zero means nothing). Thread-safe.
std::string shortest_unsigned_zero(double v);
/// `v` to `digits` significant digits, as printf's %g writes it ("0.00123", "1.23e+06"): for quantities a person
/// reads in a message (tolerances, condition estimates, lengths), never for data read back. Thread-safe.
std::string significant(double v, int digits);
/// `v` in scientific notation with `digits` digits after the point, as printf's %.Ne ("1.235e-06"): for errors and
/// residuals in messages, which are compared by their exponent. Thread-safe.
std::string scientific(double v, int digits);

/// `text` made fit for a one-line message in UTF-8: control characters escaped as `\\n`, `\\t`, `\\xNN`, and so is
/// each byte that is not part of a well-formed UTF-8 sequence (whole code points are kept). User text quoted in
/// errors (expressions, names from a scene) may contain them. Thread-safe.
std::string single_line(const std::string& text);
/// The length in bytes of the well-formed UTF-8 sequence that starts at `text[i]` (1 for ASCII), or 0 when the
/// bytes there are not one (a lone continuation byte, a truncated or overlong sequence, a surrogate). Thread-safe.
std::size_t utf8_sequence_length(const std::string& text, std::size_t i);

/// A time as phiq's messages write it (`t = …`: sweep and assembly failures, warnings): ten significant digits, so
/// that a time the sweep computes (t_begin + k h) reads as the grid point it is ("0.6", not "0.6000000000000001")
/// and a small start time keeps its digits ("1e-07", where std::to_string would say "0.000000"). Thread-safe.
std::string format_time(double t);

}  // namespace phiq
