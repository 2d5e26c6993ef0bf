// The render device: whatever gives the renderer a current OpenGL 4.5 core
// context. The renderer draws into framebuffers of its own (gl_objects.hpp)
// either way, so the same code serves the headless device below and a
// window backend (GLFW, which only that backend includes) that shows the
// target on screen.
#pragma once

#include <memory>
#include <string>

namespace scanbench::render {

class RenderDevice {
 public:
  virtual ~RenderDevice() = default;
  // Makes the device's context current on the calling thread.
  virtual void make_current() = 0;
  // "OpenGL 4.5 (Core Profile) Mesa … | llvmpipe …": what draws the frames.
  // Makes the device's context current.
  virtual std::string describe() = 0;
};

// describe() of the context current on the calling thread.
std::string describe_current_context();

// Under AddressSanitizer: pins every library loaded so far (the GL driver
// that EGL, GLFW and ImGui's loader open, and close again at exit), so that
// LeakSanitizer can still name them at exit, tests/lsan.supp applies to the
// allocations the driver keeps for the process's life, and the thread-local
// blocks they registered are still mapped when LeakSanitizer scans them.
// Does nothing in other builds. Called by each device once its context is
// current.
void pin_loaded_libraries();

// A context without any surface, on EGL's surfaceless platform (Mesa;
// llvmpipe on machines without a GPU), made current on return. Throws
// core::RuntimeFailure naming what is missing (EGL, the platform, a 4.5
// core context) when the machine cannot give one.
std::unique_ptr<RenderDevice> make_headless_device();

}  // namespace scanbench::render
