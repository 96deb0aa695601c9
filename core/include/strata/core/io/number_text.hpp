#pragma once
/// \file number_text.hpp
/// Writing doubles as text that reads back to the identical value.
#include <charconv>
#include <ostream>

namespace strata {

/// Writes `value` in the shortest decimal form that parses back to exactly `value` (round trip,
/// like %.17g but without trailing noise digits). Non-finite values are written as nan / inf.
inline void write_double(std::ostream& out, double value) {
  char buffer[32];
  const std::to_chars_result result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out.write(buffer, result.ptr - buffer);
}

}  // namespace strata
