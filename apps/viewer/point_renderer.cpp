#include "point_renderer.hpp"

#include "gl_program.hpp"

#include <pointhaptics/core/error.hpp>

#include <epoxy/gl.h>
#include <fmt/format.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cstddef>

namespace pointhaptics::viewer {
namespace {

constexpr const char* vertex_shader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 colour;
layout(location = 2) in float radius;
uniform mat4 view;
uniform mat4 projection;
uniform float pixels_per_unit;  // viewport height / (2 tan(fov / 2)): pixels per metre at unit depth
out vec3 v_colour;
out vec3 v_centre;
out float v_radius;
void main() {
  vec4 c = view * vec4(position, 1.0);
  v_centre = c.xyz;
  v_colour = colour;
  v_radius = radius;
  gl_Position = projection * c;
  gl_PointSize = max(2.0, 2.0 * radius * pixels_per_unit / max(-c.z, 1e-6));
}
)";

// the pixel's point on the sphere, its normal, and its true depth (so that spheres intersect properly)
constexpr const char* fragment_shader = R"(#version 330 core
in vec3 v_colour;
in vec3 v_centre;
in float v_radius;
uniform mat4 projection;
out vec4 fragment;
void main() {
  vec2 q = gl_PointCoord * 2.0 - 1.0;
  q.y = -q.y;
  float r2 = dot(q, q);
  if (r2 > 1.0) discard;
  vec3 n = vec3(q, sqrt(1.0 - r2));
  vec4 clip = projection * vec4(v_centre + v_radius * n, 1.0);
  gl_FragDepth = 0.5 * clip.z / clip.w + 0.5;
  vec3 light = normalize(vec3(0.4, 0.6, 0.7));
  float diffuse = max(dot(n, light), 0.0);
  float specular = pow(max(dot(reflect(-light, n), vec3(0.0, 0.0, 1.0)), 0.0), 32.0);
  fragment = vec4(v_colour * (0.35 + 0.65 * diffuse) + vec3(0.25 * specular), 1.0);
}
)";

}  // namespace

PointRenderer::PointRenderer() {
  program_ = link_program(vertex_shader, fragment_shader);
  view_ = glGetUniformLocation(program_, "view");
  projection_ = glGetUniformLocation(program_, "projection");
  pixels_per_unit_ = glGetUniformLocation(program_, "pixels_per_unit");
  glGenVertexArrays(1, &vao_);
  glGenBuffers(1, &vbo_);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Sphere), reinterpret_cast<void*>(offsetof(Sphere, x)));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Sphere), reinterpret_cast<void*>(offsetof(Sphere, r)));
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, sizeof(Sphere), reinterpret_cast<void*>(offsetof(Sphere, radius)));
  glBindVertexArray(0);
}

PointRenderer::~PointRenderer() {
  glDeleteBuffers(1, &vbo_);
  glDeleteVertexArrays(1, &vao_);
  glDeleteProgram(program_);
}

void PointRenderer::draw(const std::vector<Sphere>& spheres, const OrbitCamera& camera, const Viewport& viewport,
                         int fb_width, int fb_height, double pixel_ratio) {
  glViewport(0, 0, fb_width, fb_height);
  glDisable(GL_SCISSOR_TEST);
  glClearColor(0.13f, 0.14f, 0.17f, 1.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  if (spheres.empty()) return;
  const Viewport vp = use_viewport(viewport, fb_height, pixel_ratio);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glEnable(GL_PROGRAM_POINT_SIZE);
  glDisable(GL_BLEND);
  glUseProgram(program_);
  const Eigen::Matrix4f view = camera.view().cast<float>();
  const Eigen::Matrix4f projection = camera.projection(vp.width / vp.height).cast<float>();
  glUniformMatrix4fv(view_, 1, GL_FALSE, view.data());  // Eigen is column-major, as GL wants
  glUniformMatrix4fv(projection_, 1, GL_FALSE, projection.data());
  glUniform1f(pixels_per_unit_, static_cast<float>(camera.pixels_per_metre(1.0, vp)));
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  const auto bytes = static_cast<GLsizeiptr>(spheres.size() * sizeof(Sphere));
  if (spheres.size() > capacity_) {
    capacity_ = spheres.size();
    glBufferData(GL_ARRAY_BUFFER, bytes, spheres.data(), GL_STREAM_DRAW);
  } else {
    glBufferSubData(GL_ARRAY_BUFFER, 0, bytes, spheres.data());
  }
  glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(spheres.size()));
  glBindVertexArray(0);
  glUseProgram(0);
  glDisable(GL_DEPTH_TEST);
  glViewport(0, 0, fb_width, fb_height);
}

std::vector<std::uint8_t> read_pixels(int width, int height) {
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(width) * height * 3), row(static_cast<std::size_t>(width) * 3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, rgb.data());
  for (int y = 0; y < height / 2; ++y) {  // GL counts rows from the bottom
    auto* a = rgb.data() + static_cast<std::size_t>(y) * width * 3;
    auto* b = rgb.data() + static_cast<std::size_t>(height - 1 - y) * width * 3;
    std::swap_ranges(a, a + static_cast<std::ptrdiff_t>(width) * 3, b);
  }
  return rgb;
}

void write_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb) {
  if (!stbi_write_png(path.c_str(), width, height, 3, rgb.data(), width * 3))
    throw Error(fmt::format("{}: cannot write the PNG image", path));
}

}  // namespace pointhaptics::viewer
