// The colours of objects, the one palette of the renderer's object colour
// mode, the panoramic view's overlays and the workbench: one colour per
// node id, scattered by a multiplicative hash so that neighbouring ids
// differ, each channel within [0.25, 0.95] so that none is black or white.
// Node 0 (no object) is grey.
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace scanbench::render {

// Node `id`'s colour, 8 bits a channel.
std::array<std::uint8_t, 3> object_color(std::uint32_t id);

// The same palette as GLSL: `vec3 object_color(uint id)`, channels in [0, 1].
const char* object_color_glsl();

}  // namespace scanbench::render
