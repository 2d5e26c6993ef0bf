// Shortest exact decimal text for numbers: what the text exporters write, so
// that reading the text back gives the same binary value.
#pragma once

#include <charconv>
#include <string>

namespace scanbench::acquisition {

// Appends `value` to `out`. Integers and finite floats round-trip exactly;
// NaN and infinities are written as "nan" and "inf" (our writers never pass
// them: scans hold no non-finite value).
template <typename Number>
void append_number(std::string& out, Number value) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof text, value);
  out.append(text, result.ptr);
}

}  // namespace scanbench::acquisition
