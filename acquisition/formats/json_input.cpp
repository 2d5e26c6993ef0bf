#include "acquisition/formats/json_input.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/errors.hpp"

namespace scanbench::acquisition {
namespace {

using nlohmann::json;

// Finds where a parse failed: nlohmann's DOM parser without exceptions
// says only that it did; its SAX parser hands the position and the reason,
// a number's overflow included, to parse_error.
class ErrorLocator : public nlohmann::json_sax<json> {
 public:
  std::size_t position = 0;  // bytes read when it failed (1-based)
  std::string token;
  bool overflow = false;

  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return true; }
  bool key(string_t&) override { return true; }
  bool end_object() override { return true; }
  bool start_array(std::size_t) override { return true; }
  bool end_array() override { return true; }
  bool parse_error(std::size_t at, const std::string& last_token,
                   const nlohmann::detail::exception& error) override {
    position = at;
    token = last_token;
    overflow = error.id == 406;  // out_of_range.406: number overflow
    return false;
  }
};

}  // namespace

json parse_json(const std::string& text, const std::string& file) {
  json root = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!root.is_discarded()) return root;
  ErrorLocator locator;
  json::sax_parse(text, &locator);
  core::FilePosition position;
  const std::size_t at = std::min(locator.position > 0 ? locator.position - 1 : 0, text.size());
  position.byte_offset = at;
  position.line = 1 + static_cast<std::uint64_t>(std::count(text.begin(), text.begin() + at, '\n'));
  throw core::InputError(
      file, position,
      locator.overflow
          ? "holds a number that is not finite (too large for a double): " + locator.token
          : std::string("not valid JSON (syntax error)"));
}

json read_json_file(const std::filesystem::path& file, std::uintmax_t max_bytes) {
  const std::string name = file.string();
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(file, error);
  if (!std::filesystem::is_regular_file(status)) {
    throw core::InputError(
        name, {}, std::filesystem::exists(status) ? "is not a regular file" : "is missing");
  }
  if (std::filesystem::file_size(file, error) > max_bytes) {
    throw core::InputError(name, {}, "is larger than " + std::to_string(max_bytes >> 20) + " MB");
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) throw core::RuntimeFailure(name, {}, "cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_json(text.str(), name);
}

void JsonPlace::refuse(const std::string& problem) const {
  core::FilePosition position;
  position.detail = where;
  throw core::InputError(file, position, problem);
}

std::int64_t whole_number(const json& value, std::int64_t lo, std::int64_t hi,
                          const JsonPlace& place, std::string_view what) {
  const std::string rule = std::string(what) + " must be a whole number from " +
                           std::to_string(lo) + " to " + std::to_string(hi);
  if (value.is_number_unsigned()) {
    const std::uint64_t n = value.get<std::uint64_t>();
    if (hi < 0 || n > static_cast<std::uint64_t>(hi) || static_cast<std::int64_t>(n) < lo)
      place.refuse(rule);
    return static_cast<std::int64_t>(n);
  }
  if (value.is_number_integer()) {
    const std::int64_t n = value.get<std::int64_t>();
    if (n < lo || n > hi) place.refuse(rule);
    return n;
  }
  if (value.is_number_float()) {
    const double x = value.get<double>();
    // Cast only what an int64 holds (-2^63 ≤ x < 2^63), then compare exactly.
    if (!(x == std::floor(x) && x >= -0x1p63 && x < 0x1p63)) place.refuse(rule);
    const auto n = static_cast<std::int64_t>(x);
    if (n < lo || n > hi) place.refuse(rule);
    return n;
  }
  place.refuse(rule);
}

double finite_number(const json& value, double lo, double hi, const JsonPlace& place,
                     std::string_view what) {
  if (!value.is_number()) place.refuse(std::string(what) + " must be a number");
  const double x = value.get<double>();
  if (!(std::isfinite(x) && x >= lo && x <= hi)) {
    std::ostringstream rule;
    rule << what << " must be a finite number from " << lo << " to " << hi;
    place.refuse(rule.str());
  }
  return x;
}

void refuse_unknown_keys(const json& object, std::initializer_list<std::string_view> known,
                         const JsonPlace& place) {
  for (const auto& [key, value] : object.items()) {
    if (std::find(known.begin(), known.end(), key) == known.end())
      place.refuse("unknown key \"" + key + "\"");
  }
}

}  // namespace scanbench::acquisition
