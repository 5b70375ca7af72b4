#pragma once
/// @file Compiling and linking a GLSL program (vertex and fragment shader), and the 3-D view's viewport, for
/// the viewer's renderers. Needs a current OpenGL 3.3 context.
#include "camera.hpp"

namespace pointhaptics::viewer {

/// The linked program of the two shaders; throws Error with the compiler's or linker's log if they fail.
unsigned link_program(const char* vertex_source, const char* fragment_source);

/// Sets GL's viewport to `viewport` (window pixels from the top left, times `pixel_ratio`) in a framebuffer of
/// fb_height pixels, and returns it in framebuffer pixels.
Viewport use_viewport(const Viewport& viewport, int fb_height, double pixel_ratio);

}  // namespace pointhaptics::viewer
