#pragma once
/// @file The viewer's panels (Dear ImGui, a column left of the 3-D view): the scene's parameters, edited
/// and applied by a rebuild; display choices; live plots of the force, the simulation rate and the haptic
/// rate; counts; and the controls.
#include "live_plots.hpp"
#include "scene_view.hpp"

namespace pointhaptics::viewer {

/// The live measurements behind the plots, fed once a frame.
struct LiveStats {
  RollingSeries force{10.0, 4096};        ///< |F| on the hand, N
  RollingSeries step_rate{10.0, 4096};    ///< simulation steps per wall second
  RollingSeries haptic_rate{10.0, 4096};  ///< haptic ticks per wall second
  RateMeter steps, ticks;
  double frames_per_s = 0;
  std::vector<float> scratch;
  /// Sample the frame at wall time t.
  void sample(double t, const DisplayFrame& frame);
};

/// The panels' own state: the scene being edited (applied with a rebuild).
struct PanelState {
  Scene edit;
  bool apply = false;  ///< set by the panel when the user applies the edits; the caller rebuilds and clears it
  std::string screenshot_message;
  int drive = -1;  ///< set by the panel to the hand the cursor should drive; the caller switches and clears it
};

/// Draw the panels for a window of `width` x `height` (between ImGui::NewFrame and Render). `session` may
/// be null (a headless frame: nothing to rebuild, no live data).
void draw_panels(const ViewerSession* session, const Prepared& prepared, const DisplayFrame& frame, SceneView& view,
                 PanelState& state, LiveStats& live, double width, double height);

}  // namespace pointhaptics::viewer
