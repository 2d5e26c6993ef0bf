#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstdio>

#include "core/errors.hpp"
#include "render/device.hpp"

namespace scanbench::render {

namespace {

[[noreturn]] void fail(const std::string& what, EGLint error = eglGetError()) {
  char code[32];
  std::snprintf(code, sizeof code, " (EGL error 0x%04x)", static_cast<unsigned>(error));
  std::string problem = what;
  problem.append(code);
  throw core::RuntimeFailure("EGL", {}, problem);
}

class HeadlessDevice final : public RenderDevice {
 public:
  HeadlessDevice() {
    // Client extensions first: without EGL_MESA_platform_surfaceless there
    // is no display to ask for.
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (client == nullptr || !epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_EXT_platform_base") ||
        !epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_MESA_platform_surfaceless")) {
      throw core::RuntimeFailure("EGL", {},
                                 "the surfaceless platform (EGL_MESA_platform_surfaceless) is not "
                                 "available: install Mesa's EGL (libegl1-mesa, libgl1-mesa-dri)");
    }
    display_ =
        eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    EGLint major = 0, minor = 0;
    if (display_ == EGL_NO_DISPLAY || !eglInitialize(display_, &major, &minor))
      fail("cannot open the surfaceless display");
    if (!eglBindAPI(EGL_OPENGL_API)) fail("no desktop OpenGL through EGL");
    const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                 4,
                                 EGL_CONTEXT_MINOR_VERSION,
                                 5,
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                 EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                 EGL_NONE};
    context_ = eglCreateContext(display_, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
    if (context_ == EGL_NO_CONTEXT) fail("no OpenGL 4.5 core context");
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
      const EGLint error = eglGetError();
      eglDestroyContext(display_, context_);
      fail("cannot make the context current", error);
    }
    pin_loaded_libraries();
  }

  // The display stays initialised: EGL gives every device of the process
  // the same surfaceless display, and terminating it would pull it from
  // under the others (a bench's renderer beside a test's, the workbench's
  // two views).
  ~HeadlessDevice() override {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
  }

  HeadlessDevice(const HeadlessDevice&) = delete;
  HeadlessDevice& operator=(const HeadlessDevice&) = delete;

  void make_current() override {
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
      fail("cannot make the context current");
  }

  std::string describe() override {
    make_current();
    return describe_current_context();
  }

 private:
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
};

}  // namespace

std::unique_ptr<RenderDevice> make_headless_device() {
  return std::make_unique<HeadlessDevice>();
}

}  // namespace scanbench::render
