#include "gl_program.hpp"

#include <pointhaptics/core/error.hpp>

#include <epoxy/gl.h>
#include <fmt/format.h>

namespace pointhaptics::viewer {
namespace {

// The status of a shader or program step, and its log when it failed (glGetShaderiv and glGetShaderInfoLog,
// or their program versions).
template <class GetStatus, class GetLog>
void check(unsigned object, unsigned what, GetStatus get_status, GetLog get_log, const char* step) {
  GLint ok = 0;
  get_status(object, what, &ok);
  if (ok) return;
  char log[2048] = {};
  get_log(object, static_cast<GLsizei>(sizeof log), nullptr, log);
  throw Error(fmt::format("viewer: the shaders failed to {}: {}", step, log));
}

unsigned compile(unsigned kind, const char* source) {
  const unsigned shader = glCreateShader(kind);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  check(shader, GL_COMPILE_STATUS, glGetShaderiv, glGetShaderInfoLog, "compile");
  return shader;
}

}  // namespace

unsigned link_program(const char* vertex_source, const char* fragment_source) {
  const unsigned vs = compile(GL_VERTEX_SHADER, vertex_source), fs = compile(GL_FRAGMENT_SHADER, fragment_source);
  const unsigned program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  check(program, GL_LINK_STATUS, glGetProgramiv, glGetProgramInfoLog, "link");
  return program;
}

Viewport use_viewport(const Viewport& viewport, int fb_height, double pixel_ratio) {
  const Viewport vp{viewport.x * pixel_ratio, viewport.y * pixel_ratio, viewport.width * pixel_ratio,
                    viewport.height * pixel_ratio};
  glViewport(static_cast<GLint>(vp.x), static_cast<GLint>(fb_height - vp.y - vp.height), static_cast<GLsizei>(vp.width),
             static_cast<GLsizei>(vp.height));
  return vp;
}

}  // namespace pointhaptics::viewer
