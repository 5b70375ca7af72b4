#pragma once
/// @file Draws the object's surface: triangles with per-vertex normals and colours, smooth (Phong) shading
/// under a headlight, with OpenGL 3.3 core. Needs a current context.
#include "camera.hpp"

#include <vector>

namespace pointhaptics::viewer {

/// One vertex of the drawn surface: position (m), unit normal, colour.
struct SurfaceVertex {
  float x, y, z;
  float nx, ny, nz;
  float r, g, b;
};

class SurfaceRenderer {
 public:
  SurfaceRenderer();  ///< compiles the shaders; throws Error with the compiler's log if they fail
  ~SurfaceRenderer();
  SurfaceRenderer(const SurfaceRenderer&) = delete;
  SurfaceRenderer& operator=(const SurfaceRenderer&) = delete;

  /// Draw the triangles (three indices into `vertices` each) into the viewport (window pixels times
  /// `pixel_ratio`), depth-tested against what is already drawn (call after PointRenderer::draw, which
  /// clears). The indices are uploaded when they change (a new object), the vertices every frame.
  void draw(const std::vector<SurfaceVertex>& vertices, const std::vector<unsigned>& indices, const OrbitCamera& camera,
            const Viewport& viewport, int fb_width, int fb_height, double pixel_ratio = 1.0);

 private:
  unsigned program_ = 0, vao_ = 0, vbo_ = 0, ebo_ = 0;
  std::size_t vertex_capacity_ = 0;
  std::vector<unsigned> uploaded_indices_;
  int view_, projection_;
};

}  // namespace pointhaptics::viewer
