#pragma once
/// @file `pointhaptics view`: the interactive viewer, and its headless screenshots.
#include <string>

namespace pointhaptics::viewer {

struct ViewerOptions {
  std::string scene;       ///< scene file; empty: the default demo scene (the seed's beam, both ends held)
  std::string screenshot;  ///< PNG to write: headless (one frame, then exit), or with run_for the window's last frame
  std::string info;        ///< JSON with the camera, the viewport and where the probe and the object are
  double time = 0;         ///< headless: simulated seconds before the frame (deterministic)
  double run_for = 0;      ///< window: close after this many seconds of wall time (0: when the user closes it)
  int width = 1280, height = 800;
  std::string probe = "auto";  ///< auto | mouse | script | device
  std::string tool;  ///< the device-driven [[tool]] that source drives (empty: the first); the others keep theirs
  int threads = 0;
  int frames = 1;      ///< headless: draw this many frames (the camera turning) and report the time per frame
  bool panels = true;  ///< draw the panels (left column)
  std::string colour = "displacement";  ///< displacement | von_mises | band (levels of detail, seed Fig. 6)
  std::string draw = "surface";         ///< surface (the object's, when it has one) | points
};

/// The default scene file: scenes/beam_probe.toml from the source tree, else the installed copy.
std::string default_scene();

/// Open the window and run until it is closed (or run_for). Returns the exit code; throws Error for a
/// scene that cannot be read or a window that cannot be opened.
int run_window(const ViewerOptions& options);

/// Render one frame without a window (EGL) after options.time simulated seconds, write it to
/// options.screenshot. Returns the exit code; throws Error on failure.
int render_screenshot(const ViewerOptions& options);

}  // namespace pointhaptics::viewer
