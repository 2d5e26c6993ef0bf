#include "render/object_palette.hpp"

#include <cmath>

namespace scanbench::render {

// Knuth's multiplicative hash: the id's bits spread over all 32.
constexpr std::uint32_t kScatter = 2654435761u;
constexpr double kLow = 0.25;   // the darkest a channel gets
constexpr double kSpan = 0.7;   // and how much brighter it may be
constexpr double kNone = 0.55;  // grey: no object

std::array<std::uint8_t, 3> object_color(std::uint32_t id) {
  const auto channel = [](double v) { return static_cast<std::uint8_t>(std::lround(255.0 * v)); };
  if (id == 0) return {channel(kNone), channel(kNone), channel(kNone)};
  const std::uint32_t h = id * kScatter;
  const auto c = [&](std::uint32_t v) { return channel(kLow + kSpan * (v & 255u) / 255.0); };
  return {c(h), c(h >> 8), c(h >> 16)};
}

// The constants above, written out for the shaders.
const char* object_color_glsl() {
  return R"glsl(
vec3 object_color(uint id) {
  if (id == 0u) return vec3(0.55);
  uint h = id * 2654435761u;
  return 0.25 + 0.7 * vec3(float(h & 255u), float((h >> 8) & 255u), float((h >> 16) & 255u)) / 255.0;
}
)glsl";
}

}  // namespace scanbench::render
