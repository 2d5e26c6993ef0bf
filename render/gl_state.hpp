// The OpenGL state a draw changes, saved and given back: the renderer
// leaves the context as it found it, as ImGui's OpenGL backend does, so a
// host drawing around it (the workbench's ImGui) needs no repair.
#pragma once

#include <epoxy/gl.h>

#include <array>

namespace scanbench::render {

class GlStateGuard {
 public:
  // Saves what the splat renderer changes: clip control, the enables it
  // toggles (program point size, depth, blending, scissor, culling,
  // stencil), depth mask and
  // function, blend function, colour mask, framebuffer bindings, viewport,
  // program, vertex array, and the textures of units 0 and 1.
  GlStateGuard();
  // Gives all of it back.
  ~GlStateGuard();
  GlStateGuard(const GlStateGuard&) = delete;
  GlStateGuard& operator=(const GlStateGuard&) = delete;

 private:
  GLint clip_origin_ = 0, clip_depth_ = 0;
  GLboolean point_size_ = GL_FALSE, depth_test_ = GL_FALSE, blend_ = GL_FALSE;
  GLboolean scissor_test_ = GL_FALSE, cull_face_ = GL_FALSE, stencil_test_ = GL_FALSE;
  GLboolean depth_mask_ = GL_TRUE;
  GLint depth_func_ = 0;
  std::array<GLint, 4> blend_func_{};  // source and destination, RGB then alpha
  std::array<GLboolean, 4> color_mask_{};
  GLint draw_framebuffer_ = 0, read_framebuffer_ = 0;
  std::array<GLint, 4> viewport_{};
  GLint program_ = 0, vertex_array_ = 0, active_texture_ = 0;
  std::array<GLint, 2> textures_{};  // GL_TEXTURE_2D of units 0 and 1
};

}  // namespace scanbench::render
