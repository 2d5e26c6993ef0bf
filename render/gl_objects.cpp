#include "render/gl_objects.hpp"

#include <vector>

#include "core/errors.hpp"

namespace scanbench::render {

void delete_buffer(GLuint name) {
  glDeleteBuffers(1, &name);
}
void delete_vertex_array(GLuint name) {
  glDeleteVertexArrays(1, &name);
}
void delete_texture(GLuint name) {
  glDeleteTextures(1, &name);
}
void delete_framebuffer(GLuint name) {
  glDeleteFramebuffers(1, &name);
}
void delete_program(GLuint name) {
  glDeleteProgram(name);
}

GlBuffer make_buffer() {
  GLuint name = 0;
  glCreateBuffers(1, &name);
  return GlBuffer(name);
}

GlVertexArray make_vertex_array() {
  GLuint name = 0;
  glCreateVertexArrays(1, &name);
  return GlVertexArray(name);
}

GlTexture make_texture_2d(GLenum internal_format, int width, int height) {
  GLuint name = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &name);
  glTextureStorage2D(name, 1, internal_format, width, height);
  glTextureParameteri(name, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(name, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTextureParameteri(name, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(name, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return GlTexture(name);
}

GlFramebuffer make_framebuffer() {
  GLuint name = 0;
  glCreateFramebuffers(1, &name);
  return GlFramebuffer(name);
}

namespace {

std::string shader_log(GLuint shader) {
  GLint length = 0;
  glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
  std::vector<char> log(static_cast<std::size_t>(length) + 1, '\0');
  glGetShaderInfoLog(shader, length, nullptr, log.data());
  return log.data();
}

GLuint compile(const std::string& label, GLenum stage, const char* source) {
  const GLuint shader = glCreateShader(stage);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    std::string problem = stage == GL_VERTEX_SHADER ? "vertex" : "fragment";
    problem.append(" shader does not compile: ").append(shader_log(shader));
    glDeleteShader(shader);
    throw core::RuntimeFailure(label, {}, problem);
  }
  return shader;
}

}  // namespace

GlProgram build_program(const std::string& label, const char* vertex_source,
                        const char* fragment_source) {
  const GLuint vertex = compile(label, GL_VERTEX_SHADER, vertex_source);
  GLuint fragment = 0;
  try {
    fragment = compile(label, GL_FRAGMENT_SHADER, fragment_source);
  } catch (...) {
    glDeleteShader(vertex);
    throw;
  }
  GlProgram program(glCreateProgram());
  glAttachShader(program.get(), vertex);
  glAttachShader(program.get(), fragment);
  glLinkProgram(program.get());
  glDeleteShader(vertex);
  glDeleteShader(fragment);
  GLint ok = GL_FALSE;
  glGetProgramiv(program.get(), GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    glGetProgramiv(program.get(), GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(static_cast<std::size_t>(length) + 1, '\0');
    glGetProgramInfoLog(program.get(), length, nullptr, log.data());
    std::string problem = "program does not link: ";
    problem.append(log.data());
    throw core::RuntimeFailure(label, {}, problem);
  }
  return program;
}

}  // namespace scanbench::render
