// GLSL 4.50 sources of the splat passes (splat_passes.hpp): one vertex
// and one fragment stage for every splat pass, and the resolve.
#pragma once

#include <string>

namespace scanbench::render::shaders {

// The splat vertex stage, with the object palette's GLSL in it, reading a
// level-of-detail store's points as stored (lod_point.hpp).
std::string splat_vertex();
extern const char* const kSplatFragment;
extern const char* const kResolveVertex;
extern const char* const kResolveFragment;

// u_pass of the splat fragment stage.
inline constexpr int kPassVisibility = 0;
inline constexpr int kPassAccumulate = 1;
inline constexpr int kPassOpaque = 2;
inline constexpr int kPassPoints = 3;

}  // namespace scanbench::render::shaders
