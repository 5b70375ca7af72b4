#include "surface_renderer.hpp"

#include "gl_program.hpp"

#include <epoxy/gl.h>

#include <cstddef>

namespace pointhaptics::viewer {
namespace {

constexpr const char* vertex_shader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 colour;
uniform mat4 view;
uniform mat4 projection;
out vec3 v_normal;
out vec3 v_colour;
out vec3 v_position;
void main() {
  vec4 p = view * vec4(position, 1.0);
  v_position = p.xyz;
  v_normal = mat3(view) * normal;  // the view is a rotation and a translation
  v_colour = colour;
  gl_Position = projection * p;
}
)";

// Phong shading per pixel: the sphere impostors' light (point_renderer.cpp), so points and surface match;
// both faces lit (a cut or an open input shows its inside)
constexpr const char* fragment_shader = R"(#version 330 core
in vec3 v_normal;
in vec3 v_colour;
in vec3 v_position;
out vec4 fragment;
void main() {
  vec3 n = normalize(v_normal);
  if (!gl_FrontFacing) n = -n;
  vec3 light = normalize(vec3(0.4, 0.6, 0.7));
  float diffuse = max(dot(n, light), 0.0);
  vec3 to_eye = normalize(-v_position);
  float specular = pow(max(dot(reflect(-light, n), to_eye), 0.0), 32.0);
  fragment = vec4(v_colour * (0.35 + 0.65 * diffuse) + vec3(0.2 * specular), 1.0);
}
)";

}  // namespace

SurfaceRenderer::SurfaceRenderer() {
  program_ = link_program(vertex_shader, fragment_shader);
  view_ = glGetUniformLocation(program_, "view");
  projection_ = glGetUniformLocation(program_, "projection");
  glGenVertexArrays(1, &vao_);
  glGenBuffers(1, &vbo_);
  glGenBuffers(1, &ebo_);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo_);  // recorded in the vertex array
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(SurfaceVertex),
                        reinterpret_cast<void*>(offsetof(SurfaceVertex, x)));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(SurfaceVertex),
                        reinterpret_cast<void*>(offsetof(SurfaceVertex, nx)));
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, sizeof(SurfaceVertex),
                        reinterpret_cast<void*>(offsetof(SurfaceVertex, r)));
  glBindVertexArray(0);
}

SurfaceRenderer::~SurfaceRenderer() {
  glDeleteBuffers(1, &ebo_);
  glDeleteBuffers(1, &vbo_);
  glDeleteVertexArrays(1, &vao_);
  glDeleteProgram(program_);
}

void SurfaceRenderer::draw(const std::vector<SurfaceVertex>& vertices, const std::vector<unsigned>& indices,
                           const OrbitCamera& camera, const Viewport& viewport, int fb_width, int fb_height,
                           double pixel_ratio) {
  if (vertices.empty() || indices.empty()) return;
  const Viewport vp = use_viewport(viewport, fb_height, pixel_ratio);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glUseProgram(program_);
  const Eigen::Matrix4f view = camera.view().cast<float>();
  const Eigen::Matrix4f projection = camera.projection(vp.width / vp.height).cast<float>();
  glUniformMatrix4fv(view_, 1, GL_FALSE, view.data());
  glUniformMatrix4fv(projection_, 1, GL_FALSE, projection.data());
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  const auto bytes = static_cast<GLsizeiptr>(vertices.size() * sizeof(SurfaceVertex));
  if (vertices.size() > vertex_capacity_) {
    vertex_capacity_ = vertices.size();
    glBufferData(GL_ARRAY_BUFFER, bytes, vertices.data(), GL_STREAM_DRAW);
  } else {
    glBufferSubData(GL_ARRAY_BUFFER, 0, bytes, vertices.data());
  }
  if (indices != uploaded_indices_) {  // a new object (compared once a frame: cheap beside the upload)
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(unsigned)), indices.data(),
                 GL_STATIC_DRAW);
    uploaded_indices_ = indices;
  }
  glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(indices.size()), GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
  glUseProgram(0);
  glDisable(GL_DEPTH_TEST);
  glViewport(0, 0, fb_width, fb_height);
}

}  // namespace pointhaptics::viewer
