#include "render/window/window_device.hpp"

#include <epoxy/gl.h>
// GLFW after epoxy, without its own GL header.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <string>

#include "core/errors.hpp"

namespace scanbench::render {

namespace {

std::string glfw_error() {
  const char* description = nullptr;
  const int code = glfwGetError(&description);
  std::string out = description != nullptr ? description : "unknown GLFW error";
  out.append(" (GLFW error ").append(std::to_string(code)).append(")");
  return out;
}

WindowInput* input_of(GLFWwindow* window) {
  return static_cast<WindowInput*>(glfwGetWindowUserPointer(window));
}

}  // namespace

struct WindowDevice::Window {
  GLFWwindow* handle = nullptr;
};

WindowDevice::WindowDevice(int width, int height, const std::string& title)
    : window_(std::make_unique<Window>()) {
  if (glfwInit() != GLFW_TRUE) {
    throw core::RuntimeFailure("GLFW", {},
                               "cannot open a window: " + glfw_error() +
                                   ". Is there a display? (set DISPLAY, or run under xvfb-run -a)");
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
  if (width <= 0 || height <= 0) {
    // The work area of the screen it opens on (the primary one), maximised.
    int x = 0, y = 0;
    width = 1280, height = 800;
    if (GLFWmonitor* monitor = glfwGetPrimaryMonitor())
      glfwGetMonitorWorkarea(monitor, &x, &y, &width, &height);
    glfwWindowHint(GLFW_MAXIMIZED, GLFW_TRUE);
  }
  window_->handle = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (window_->handle == nullptr) {
    const std::string problem = glfw_error();
    glfwTerminate();
    throw core::RuntimeFailure("GLFW", {}, "no window with an OpenGL 4.5 core context: " + problem);
  }
  glfwMakeContextCurrent(window_->handle);
  glfwSwapInterval(0);
  pin_loaded_libraries();
  GLFWwindow* w = window_->handle;
  glfwSetCursorPosCallback(w, [](GLFWwindow* window, double x, double y) {
    if (WindowInput* in = input_of(window)) in->cursor_moved(x, y);
  });
  glfwSetMouseButtonCallback(w, [](GLFWwindow* window, int button, int action, int mods) {
    if (WindowInput* in = input_of(window)) in->button(button, action == GLFW_PRESS, mods);
  });
  glfwSetScrollCallback(w, [](GLFWwindow* window, double dx, double dy) {
    if (WindowInput* in = input_of(window)) in->scrolled(dx, dy);
  });
  glfwSetKeyCallback(w, [](GLFWwindow* window, int key, int, int action, int mods) {
    if (action == GLFW_REPEAT) action = GLFW_PRESS;
    if (WindowInput* in = input_of(window)) in->key(key, action == GLFW_PRESS, mods);
  });
  glfwSetCharCallback(w, [](GLFWwindow* window, unsigned codepoint) {
    if (WindowInput* in = input_of(window)) in->text(codepoint);
  });
}

WindowDevice::~WindowDevice() {
  glfwDestroyWindow(window_->handle);
  glfwTerminate();
}

void WindowDevice::make_current() {
  glfwMakeContextCurrent(window_->handle);
}

std::string WindowDevice::describe() {
  make_current();
  return describe_current_context();
}

void WindowDevice::set_input(WindowInput* input) {
  glfwSetWindowUserPointer(window_->handle, input);
}

bool WindowDevice::close_requested() const {
  return glfwWindowShouldClose(window_->handle) == GLFW_TRUE;
}

void WindowDevice::poll_events() {
  glfwPollEvents();
}

void WindowDevice::swap_buffers() {
  glfwSwapBuffers(window_->handle);
}

std::array<int, 2> WindowDevice::framebuffer_size() const {
  std::array<int, 2> size{};
  glfwGetFramebufferSize(window_->handle, &size[0], &size[1]);
  return size;
}

}  // namespace scanbench::render
