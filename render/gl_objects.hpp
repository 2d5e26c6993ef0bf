// Owners of OpenGL objects (one class per kind of name, deleted with it) and
// the shader program builder. Every call needs the device's context current.
#pragma once

#include <epoxy/gl.h>

#include <string>
#include <utility>

namespace scanbench::render {

// A GL name with its deleter: move-only, deleted once.
template <void (*Delete)(GLuint)>
class GlName {
 public:
  GlName() = default;
  explicit GlName(GLuint name) : name_(name) {}
  ~GlName() {
    if (name_ != 0) Delete(name_);
  }
  GlName(GlName&& other) noexcept : name_(std::exchange(other.name_, 0)) {}
  GlName& operator=(GlName&& other) noexcept {
    if (this != &other) {
      if (name_ != 0) Delete(name_);
      name_ = std::exchange(other.name_, 0);
    }
    return *this;
  }
  GlName(const GlName&) = delete;
  GlName& operator=(const GlName&) = delete;

  GLuint get() const { return name_; }

 private:
  GLuint name_ = 0;
};

void delete_buffer(GLuint name);
void delete_vertex_array(GLuint name);
void delete_texture(GLuint name);
void delete_framebuffer(GLuint name);
void delete_program(GLuint name);

using GlBuffer = GlName<delete_buffer>;
using GlVertexArray = GlName<delete_vertex_array>;
using GlTexture = GlName<delete_texture>;
using GlFramebuffer = GlName<delete_framebuffer>;
using GlProgram = GlName<delete_program>;

GlBuffer make_buffer();
GlVertexArray make_vertex_array();
GlTexture make_texture_2d(GLenum internal_format, int width, int height);
GlFramebuffer make_framebuffer();

// Compiles and links a program from GLSL 4.50 sources (the `#version` line
// included). Our sources are compiled in and tested on Mesa; a driver that
// refuses them is this machine's failure: throws core::RuntimeFailure with
// the driver's log, naming `label`.
GlProgram build_program(const std::string& label, const char* vertex_source,
                        const char* fragment_source);

}  // namespace scanbench::render
