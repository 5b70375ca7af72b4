#pragma once
/// @file What one frame of the viewer shows of the object: its surface (or its points as spheres) coloured by
/// displacement, von Mises stress or level-of-detail band, the marks, the probe, the colour bar; and a JSON
/// account of the frame (camera, viewport, probe) that tests use to check the pixels.
#include "camera.hpp"
#include "point_renderer.hpp"
#include "surface_renderer.hpp"
#include "viewer_session.hpp"

#include <string>
#include <vector>

namespace pointhaptics::viewer {

enum class ColourBy { DISPLACEMENT, LOD_BAND, VON_MISES };

/// The viewer's display choices and what it keeps between frames.
struct SceneView {
  OrbitCamera camera;
  ColourBy colour_by = ColourBy::DISPLACEMENT;
  bool auto_scale = true;                       ///< the colour bar's top follows the largest displacement
  float scale_max = 1e-3f;                      ///< m, the colour bar's top (displacement)
  float stress_max = 1e3f;                      ///< Pa, the colour bar's top (von Mises stress)
  bool draw_surface = true;                     ///< the object's surface when it has one (else its points)
  bool points_too = false;                      ///< the points as well as the surface
  float point_scale = 1.0f;                     ///< drawn radius / half the spacing
  bool interior = false;                        ///< draw the points hidden inside the object too (Prepared::shell)
  std::vector<Sphere> spheres;                  ///< reused every frame
  std::vector<char> grabbed;                    ///< per point, reused
  Eigen::VectorXd von_mises;                    ///< per point, Pa, when coloured by it (reused)
  std::vector<SurfaceVertex> surface_vertices;  ///< the drawn surface, reused every frame (empty: none drawn)
  std::vector<unsigned> surface_indices;
  const ObjectSurface* indexed_surface = nullptr;  ///< whose triangles surface_indices holds
  Points surface_positions, surface_normals;       ///< reused
  Eigen::MatrixXd surface_stress;                  ///< von Mises stress at the vertices (1 x m), reused
};

/// The 3-D view's rectangle of a window of width x height (window coordinates): right of the panels.
Viewport scene_viewport(double width, double height, bool panels);
inline constexpr double panel_width = 340;

/// Fill view.spheres for the frame: one per point (held red, grabbed green, else by displacement, stress or
/// band; with levels of detail the points not simulated are paler) unless the surface is drawn without
/// them, then the probe, then the device point when it is apart from the probe.
void build_spheres(const Prepared& prepared, const DisplayFrame& frame, SceneView& view);
/// A rigid shape (another hand's probe, an obstacle, a posed tool) as spheres: a sphere, a capsule's axis, a box's
/// edges, a plane's grid of dots under the objects (between lo and hi).
void add_rigid_shape(const DisplayFrame::RigidShape& shape, const Rgb& colour, const Vec3& lo, const Vec3& hi,
                     double dot_radius, std::vector<Sphere>& spheres);

/// Fill view.surface_vertices (and, for a new object, view.surface_indices) for the frame: the surface
/// carried by the frame's displacements, smooth normals (area-weighted), each vertex coloured as its
/// heaviest point would be; empty when the surface is not drawn. After build_spheres (grabs, scales).
void build_surface(const Prepared& prepared, const DisplayFrame& frame, SceneView& view);

/// Both, in order.
void build_scene(const Prepared& prepared, const DisplayFrame& frame, SceneView& view);

/// The renderers of the 3-D view: the spheres (which clear it), then the surface.
struct Renderers {
  PointRenderer points;
  SurfaceRenderer surface;
  void draw(const SceneView& view, const Viewport& viewport, int fb_width, int fb_height, double pixel_ratio = 1.0);
};

/// The colour bar and the frame's caption, drawn with ImGui over the 3-D view (between NewFrame and Render).
void draw_overlay(const Prepared& prepared, const DisplayFrame& frame, const SceneView& view, const Viewport& viewport);

/// The frame as JSON (camera, viewport in framebuffer pixels, probe, displacement), for tests and figures.
void write_frame_info(const std::string& path, const Prepared& prepared, const DisplayFrame& frame,
                      const SceneView& view, const Viewport& viewport_fb, int fb_width, int fb_height,
                      double haptic_rate_hz);

}  // namespace pointhaptics::viewer
