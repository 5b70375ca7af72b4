#pragma once
/// @file What one frame of the viewer shows of the object: spheres coloured by displacement (or by
/// level-of-detail band), the marks, the probe, the colour bar; and a JSON account of the frame (camera,
/// viewport, probe) that tests use to check the pixels.
#include "camera.hpp"
#include "point_renderer.hpp"
#include "viewer_session.hpp"

#include <string>
#include <vector>

namespace pointhaptics::viewer {

enum class ColourBy { DISPLACEMENT, LOD_BAND };

/// The viewer's display choices and what it keeps between frames.
struct SceneView {
  OrbitCamera camera;
  ColourBy colour_by = ColourBy::DISPLACEMENT;
  bool auto_scale = true;       ///< the colour bar's top follows the largest displacement
  float scale_max = 1e-3f;      ///< m, the colour bar's top
  float point_scale = 1.0f;     ///< drawn radius / half the spacing
  bool interior = false;        ///< draw the points hidden inside the object too (Prepared::shell)
  std::vector<Sphere> spheres;  ///< reused every frame
  std::vector<char> grabbed;    ///< per point, reused
};

/// The 3-D view's rectangle of a window of width x height (window coordinates): right of the panels.
Viewport scene_viewport(double width, double height, bool panels);
inline constexpr double panel_width = 340;

/// Fill view.spheres for the frame: one per point (held red, grabbed green, else by displacement or band;
/// with levels of detail the points not simulated are paler), then the probe, then the device point when it
/// is apart from the probe.
void build_spheres(const Prepared& prepared, const DisplayFrame& frame, SceneView& view);

/// The colour bar and the frame's caption, drawn with ImGui over the 3-D view (between NewFrame and Render).
void draw_overlay(const Prepared& prepared, const DisplayFrame& frame, const SceneView& view, const Viewport& viewport);

/// The frame as JSON (camera, viewport in framebuffer pixels, probe, displacement), for tests and figures.
void write_frame_info(const std::string& path, const Prepared& prepared, const DisplayFrame& frame, const SceneView& view,
                      const Viewport& viewport_fb, int fb_width, int fb_height, double haptic_rate_hz);

}  // namespace pointhaptics::viewer
