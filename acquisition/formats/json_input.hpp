// JSON input files (view files, triplet sidecars, segment scripts, replays,
// point-pair files), read one way: errors name the file, the position and
// the problem, and typed reads refuse what does not fit instead of wrapping
// or truncating it (4294967297 is not 1, 2.7 is not 2, 1e400 is not a
// library's exception text).
#pragma once

#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace scanbench::acquisition {

// Parses `text`, the contents of `file` (named in messages). Throws
// core::InputError with the line and byte of the problem: a syntax error
// ("not valid JSON"), or a number too large for a double ("1e400": "not
// finite").
nlohmann::json parse_json(const std::string& text, const std::string& file);

// Reads and parses `file`. Throws core::InputError when it is not a
// regular file (a pipe, a folder, missing), is larger than `max_bytes`, or
// does not parse (parse_json); core::RuntimeFailure when it cannot be read.
nlohmann::json read_json_file(const std::filesystem::path& file, std::uintmax_t max_bytes);

// Where a value sits: the file and a place in it ("key \"width\"",
// "op 3 (grow)", "events[4]"), for the messages of the reads below.
struct JsonPlace {
  std::string file;
  std::string where;

  // Throws core::InputError naming the file, the place and `problem`.
  [[noreturn]] void refuse(const std::string& problem) const;
};

// `value` (named `what` in messages) as a whole number in [lo, hi]: a JSON
// integer, or a number without a fraction (640.0). Anything else (2.7, a
// string, 4294967297 where hi is 100000) is refused, never wrapped.
std::int64_t whole_number(const nlohmann::json& value, std::int64_t lo, std::int64_t hi,
                          const JsonPlace& place, std::string_view what);

// `value` as a finite number in [lo, hi].
double finite_number(const nlohmann::json& value, double lo, double hi, const JsonPlace& place,
                     std::string_view what);

// Refuses the first key of `object` that is not in `known`: a misspelt key
// is named, not silently left at its default.
void refuse_unknown_keys(const nlohmann::json& object,
                         std::initializer_list<std::string_view> known, const JsonPlace& place);

}  // namespace scanbench::acquisition
