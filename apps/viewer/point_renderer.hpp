#pragma once
/// @file Draws points as shaded spheres (impostors: one GL point each, shaded and depth-corrected per
/// pixel as the sphere it stands for), with OpenGL 3.3 core. Needs a current context.
#include "camera.hpp"
#include "colour_map.hpp"

#include <cstdint>
#include <vector>

namespace pointhaptics::viewer {

/// One sphere to draw: centre (m), colour, radius (m).
struct Sphere {
  float x, y, z;
  float r, g, b;
  float radius;
};

class PointRenderer {
 public:
  PointRenderer();  ///< compiles the shaders; throws Error with the compiler's log if they fail
  ~PointRenderer();
  PointRenderer(const PointRenderer&) = delete;
  PointRenderer& operator=(const PointRenderer&) = delete;

  /// Clear the framebuffer (height fb_height pixels) and draw the spheres into the viewport (window pixels
  /// times `pixel_ratio`).
  void draw(const std::vector<Sphere>& spheres, const OrbitCamera& camera, const Viewport& viewport, int fb_width,
            int fb_height, double pixel_ratio = 1.0);

 private:
  unsigned program_ = 0, vao_ = 0, vbo_ = 0;
  std::size_t capacity_ = 0;
  int view_, projection_, pixels_per_unit_;
};

/// The framebuffer's pixels as RGB rows from the top (as images store them).
std::vector<std::uint8_t> read_pixels(int width, int height);

/// Write RGB rows (top first) as a PNG; throws Error naming the file when it cannot.
void write_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb);

}  // namespace pointhaptics::viewer
