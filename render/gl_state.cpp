#include "render/gl_state.hpp"

namespace scanbench::render {

namespace {

GLboolean enabled(GLenum capability) {
  return glIsEnabled(capability);
}

void set_enabled(GLenum capability, GLboolean on) {
  if (on) {
    glEnable(capability);
  } else {
    glDisable(capability);
  }
}

}  // namespace

GlStateGuard::GlStateGuard() {
  glGetIntegerv(GL_CLIP_ORIGIN, &clip_origin_);
  glGetIntegerv(GL_CLIP_DEPTH_MODE, &clip_depth_);
  point_size_ = enabled(GL_PROGRAM_POINT_SIZE);
  depth_test_ = enabled(GL_DEPTH_TEST);
  blend_ = enabled(GL_BLEND);
  scissor_test_ = enabled(GL_SCISSOR_TEST);
  cull_face_ = enabled(GL_CULL_FACE);
  stencil_test_ = enabled(GL_STENCIL_TEST);
  glGetBooleanv(GL_DEPTH_WRITEMASK, &depth_mask_);
  glGetIntegerv(GL_DEPTH_FUNC, &depth_func_);
  glGetIntegerv(GL_BLEND_SRC_RGB, &blend_func_[0]);
  glGetIntegerv(GL_BLEND_DST_RGB, &blend_func_[1]);
  glGetIntegerv(GL_BLEND_SRC_ALPHA, &blend_func_[2]);
  glGetIntegerv(GL_BLEND_DST_ALPHA, &blend_func_[3]);
  glGetBooleanv(GL_COLOR_WRITEMASK, color_mask_.data());
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw_framebuffer_);
  glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &read_framebuffer_);
  glGetIntegerv(GL_VIEWPORT, viewport_.data());
  glGetIntegerv(GL_CURRENT_PROGRAM, &program_);
  glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &vertex_array_);
  glGetIntegerv(GL_ACTIVE_TEXTURE, &active_texture_);
  for (GLuint unit = 0; unit < textures_.size(); ++unit) {
    glActiveTexture(GL_TEXTURE0 + unit);
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &textures_[unit]);
  }
  glActiveTexture(static_cast<GLenum>(active_texture_));
}

GlStateGuard::~GlStateGuard() {
  glClipControl(static_cast<GLenum>(clip_origin_), static_cast<GLenum>(clip_depth_));
  set_enabled(GL_PROGRAM_POINT_SIZE, point_size_);
  set_enabled(GL_DEPTH_TEST, depth_test_);
  set_enabled(GL_BLEND, blend_);
  glDepthMask(depth_mask_);
  glDepthFunc(static_cast<GLenum>(depth_func_));
  glBlendFuncSeparate(static_cast<GLenum>(blend_func_[0]), static_cast<GLenum>(blend_func_[1]),
                      static_cast<GLenum>(blend_func_[2]), static_cast<GLenum>(blend_func_[3]));
  glColorMask(color_mask_[0], color_mask_[1], color_mask_[2], color_mask_[3]);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(draw_framebuffer_));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>(read_framebuffer_));
  glViewport(viewport_[0], viewport_[1], viewport_[2], viewport_[3]);
  glUseProgram(static_cast<GLuint>(program_));
  glBindVertexArray(static_cast<GLuint>(vertex_array_));
  // Only the 2D target of each unit: glBindTextureUnit would reset the others.
  for (GLuint unit = 0; unit < textures_.size(); ++unit) {
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(textures_[unit]));
  }
  glActiveTexture(static_cast<GLenum>(active_texture_));
  set_enabled(GL_SCISSOR_TEST, scissor_test_);
  set_enabled(GL_CULL_FACE, cull_face_);
  set_enabled(GL_STENCIL_TEST, stencil_test_);
}

}  // namespace scanbench::render
