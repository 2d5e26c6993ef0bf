#include "render/device.hpp"

#include <epoxy/gl.h>

namespace scanbench::render {

std::string describe_current_context() {
  const auto text = [](GLenum name) {
    const auto* value = reinterpret_cast<const char*>(glGetString(name));
    return std::string(value != nullptr ? value : "unknown");
  };
  std::string out = "OpenGL ";
  out.append(text(GL_VERSION)).append(" | ").append(text(GL_RENDERER));
  return out;
}

}  // namespace scanbench::render
