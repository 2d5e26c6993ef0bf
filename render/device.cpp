#include "render/device.hpp"

#include <epoxy/gl.h>

// AddressSanitizer's build: GCC defines __SANITIZE_ADDRESS__, clang 14
// answers __has_feature(address_sanitizer) instead.
#if defined(__SANITIZE_ADDRESS__)
#define SCANBENCH_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SCANBENCH_ADDRESS_SANITIZER 1
#endif
#endif

#if defined(SCANBENCH_ADDRESS_SANITIZER)
#include <dlfcn.h>
#include <link.h>
#endif

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

#if defined(SCANBENCH_ADDRESS_SANITIZER)
void pin_loaded_libraries() {
  dl_iterate_phdr(
      [](dl_phdr_info* info, std::size_t, void*) {
        if (info->dlpi_name != nullptr && info->dlpi_name[0] != '\0')
          dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
        return 0;
      },
      nullptr);
}
#else
void pin_loaded_libraries() {}
#endif

}  // namespace scanbench::render
