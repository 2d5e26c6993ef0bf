// Text from outside the program (names typed by users, read from files):
// what it must be before it is stored.
#pragma once

#include <string>
#include <string_view>

namespace scanbench::core {

// True when `text` is well-formed UTF-8: no stray continuation bytes, no
// truncated or overlong sequences, no surrogates, nothing above U+10FFFF.
bool is_valid_utf8(std::string_view text);

// True for a C0 control character (U+0000–U+001F: NUL, newline, ESC …)
// or DEL (U+007F): bytes that would move the cursor or end a line when
// printed.
inline bool is_control_character(char c) {
  const auto byte = static_cast<unsigned char>(c);
  return byte < 0x20 || byte == 0x7F;
}

// True when `text` holds a control character (is_control_character).
bool has_control_characters(std::string_view text);

// `text` with A–Z made a–z, every other byte as it is (names of file
// extensions, format keywords and fields, compared without case).
std::string ascii_lower(std::string_view text);

}  // namespace scanbench::core
