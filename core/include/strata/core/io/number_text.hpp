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

/// Writes one line "index x y z" (coordinates in round-trip form), as gmsh 2.2 and TetGen list
/// their nodes.
template <typename Row>
void write_numbered_point(std::ostream& out, long long index, const Row& point) {
  out << index;
  for (int d = 0; d < 3; ++d) {
    out << ' ';
    write_double(out, point(d));
  }
  out << '\n';
}

}  // namespace strata
