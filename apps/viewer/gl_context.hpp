#pragma once
/// @file Where the viewer draws: a GLFW window (OpenGL 3.3 core), or, for screenshots without a display,
/// an EGL context on Mesa's surfaceless platform drawing into an offscreen framebuffer.
#include <memory>
#include <string>

struct GLFWwindow;

namespace pointhaptics::viewer {

/// A window with a current OpenGL 3.3 core context. Throws Error (naming what is missing: a display, the
/// GL version) when it cannot be made.
class Window {
 public:
  Window(int width, int height, const std::string& title, bool visible = true);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;
  GLFWwindow* handle() const { return window_; }
  bool should_close() const;
  void swap();
  int framebuffer_width() const;
  int framebuffer_height() const;
  /// Framebuffer pixels per window coordinate (HiDPI screens have 2).
  double pixel_ratio() const;

 private:
  GLFWwindow* window_ = nullptr;
};

/// A current OpenGL 3.3 core context without any window, and a framebuffer of its own (colour and depth)
/// bound for drawing. Throws Error when EGL or its surfaceless platform is not available.
class HeadlessContext {
 public:
  HeadlessContext(int width, int height);
  ~HeadlessContext();
  HeadlessContext(const HeadlessContext&) = delete;
  HeadlessContext& operator=(const HeadlessContext&) = delete;
  int width() const { return width_; }
  int height() const { return height_; }
  std::string renderer() const;  ///< GL_RENDERER, e.g. "llvmpipe"

 private:
  struct Egl;
  std::unique_ptr<Egl> egl_;
  int width_, height_;
  unsigned framebuffer_ = 0, colour_ = 0, depth_ = 0;
};

}  // namespace pointhaptics::viewer
