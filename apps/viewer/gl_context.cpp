#include "gl_context.hpp"

#include <pointhaptics/core/error.hpp>

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <fmt/format.h>

#include <cstdlib>

namespace pointhaptics::viewer {
namespace {

std::string glfw_error() {
  const char* description = nullptr;
  glfwGetError(&description);
  return description ? description : "unknown error";
}

}  // namespace

Window::Window(int width, int height, const std::string& title, bool visible) {
  if (!glfwInit())
    throw Error(
        fmt::format("viewer: cannot open a window ({}); is there a display (DISPLAY or WAYLAND_DISPLAY)? "
                    "--screenshot renders without one",
                    glfw_error()));
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, visible ? GLFW_TRUE : GLFW_FALSE);
  glfwWindowHint(GLFW_SAMPLES, 4);
  window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window_) {
    const std::string why = glfw_error();
    glfwTerminate();
    throw Error(fmt::format("viewer: cannot create an OpenGL 3.3 core window: {}", why));
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(1);
}

Window::~Window() {
  if (window_) glfwDestroyWindow(window_);
  glfwTerminate();
}

bool Window::should_close() const { return glfwWindowShouldClose(window_); }
void Window::swap() { glfwSwapBuffers(window_); }

int Window::framebuffer_width() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  return w;
}

int Window::framebuffer_height() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  return h;
}

double Window::pixel_ratio() const {
  int w = 0, h = 0;
  glfwGetWindowSize(window_, &w, &h);
  return w > 0 ? static_cast<double>(framebuffer_width()) / w : 1.0;
}

struct HeadlessContext::Egl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
};

HeadlessContext::HeadlessContext(int width, int height)
    : egl_(std::make_unique<Egl>()), width_(width), height_(height) {
  if (width < 16 || height < 16 || width > 8192 || height > 8192)
    throw Error(fmt::format("viewer: a {} x {} image; the size must be 16 to 8192 pixels a side", width, height));
  // Mesa's surfaceless platform needs neither a display server nor a GPU (llvmpipe renders in software)
  if (!epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_MESA_platform_surfaceless"))
    throw Error("viewer: headless rendering needs EGL with EGL_MESA_platform_surfaceless (Debian: libegl-mesa0)");
  egl_->display = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  EGLint major = 0, minor = 0;
  if (egl_->display == EGL_NO_DISPLAY || !eglInitialize(egl_->display, &major, &minor))
    throw Error(fmt::format("viewer: cannot initialise a headless EGL display (EGL error 0x{:x})", eglGetError()));
  if (!eglBindAPI(EGL_OPENGL_API)) throw Error("viewer: this EGL has no desktop OpenGL");
  const EGLint attributes[] = {
      EGL_CONTEXT_MAJOR_VERSION,           3,       EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  egl_->context = eglCreateContext(egl_->display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
  if (egl_->context == EGL_NO_CONTEXT ||
      !eglMakeCurrent(egl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, egl_->context)) {
    eglTerminate(egl_->display);
    throw Error(
        fmt::format("viewer: cannot make a headless OpenGL 3.3 core context (EGL error 0x{:x})", eglGetError()));
  }
  glGenFramebuffers(1, &framebuffer_);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
  glGenRenderbuffers(1, &colour_);
  glBindRenderbuffer(GL_RENDERBUFFER, colour_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_);
  glGenRenderbuffers(1, &depth_);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw Error("viewer: the offscreen framebuffer is incomplete");
}

HeadlessContext::~HeadlessContext() {
  glDeleteFramebuffers(1, &framebuffer_);
  glDeleteRenderbuffers(1, &colour_);
  glDeleteRenderbuffers(1, &depth_);
  eglMakeCurrent(egl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(egl_->display, egl_->context);
  eglTerminate(egl_->display);
}

std::string HeadlessContext::renderer() const { return reinterpret_cast<const char*>(glGetString(GL_RENDERER)); }

}  // namespace pointhaptics::viewer
