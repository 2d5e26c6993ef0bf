// The window backend of the render device (device.hpp): a GLFW window with
// an OpenGL 4.5 core context. Input arrives through a WindowInput listener,
// in window coordinates (pixels, origin at the top left, y down); a replay
// calls the same listener, so recorded input takes the path live input does.
#pragma once

#include <array>
#include <memory>
#include <string>

#include "render/device.hpp"

namespace scanbench::render {

// GLFW's key codes and modifier bits, so that listeners need not include GLFW.
namespace keys {
inline constexpr int kModShift = 0x0001;
inline constexpr int kModControl = 0x0002;
inline constexpr int kModAlt = 0x0004;
inline constexpr int kSpace = 32;
inline constexpr int kEscape = 256;
inline constexpr int kEnter = 257;
inline constexpr int kTab = 258;
inline constexpr int kBackspace = 259;
inline constexpr int kDelete = 261;
inline constexpr int kRight = 262;
inline constexpr int kLeft = 263;
inline constexpr int kDown = 264;
inline constexpr int kUp = 265;
inline constexpr int kHome = 268;
inline constexpr int kEnd = 269;
inline constexpr int kLeftShift = 340;
inline constexpr int kLeftControl = 341;
inline constexpr int kLeftAlt = 342;
inline constexpr int kRightShift = 344;
inline constexpr int kRightControl = 345;
inline constexpr int kRightAlt = 346;
// Letters and digits are their ASCII upper-case codes ('A' = 65, '0' = 48).
}  // namespace keys

class WindowInput {
 public:
  virtual ~WindowInput() = default;
  virtual void cursor_moved(double x, double y) = 0;
  virtual void button(int button, bool pressed, int mods) = 0;  // 0 left, 1 right, 2 middle
  virtual void scrolled(double dx, double dy) = 0;
  virtual void key(int key, bool pressed, int mods) = 0;
  virtual void text(unsigned codepoint) = 0;
};

class WindowDevice final : public RenderDevice {
 public:
  // Opens a resizable window of width × height pixels (either 0: the work
  // area of the primary screen) with a 4.5 core context, made current.
  // Throws core::RuntimeFailure when there is no display (set DISPLAY, or
  // run under xvfb-run) or no such context.
  WindowDevice(int width, int height, const std::string& title);
  ~WindowDevice() override;
  WindowDevice(const WindowDevice&) = delete;
  WindowDevice& operator=(const WindowDevice&) = delete;

  void make_current() override;
  std::string describe() override;

  // Where input goes (nullptr: nowhere). Not owned.
  void set_input(WindowInput* input);
  bool close_requested() const;
  // Delivers pending window-system events to the input listener.
  void poll_events();
  void swap_buffers();
  // The default framebuffer's size [pixels].
  std::array<int, 2> framebuffer_size() const;

 private:
  struct Window;
  std::unique_ptr<Window> window_;
};

}  // namespace scanbench::render
