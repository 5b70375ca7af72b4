#pragma once
/// @file Colours of the viewer: displacement magnitude on a perceptually uniform scale (viridis), the
/// marks (held, grabbed) and the level-of-detail bands (seed Fig. 6).
#include <array>
#include <cstdint>

namespace pointhaptics::viewer {

using Rgb = std::array<float, 3>;  ///< components in [0, 1]

/// Viridis at s in [0, 1] (clamped; NaN gives the low end).
Rgb viridis(double s);

inline constexpr Rgb held_colour{0.85f, 0.12f, 0.10f};            ///< fixed points: red
inline constexpr Rgb grabbed_colour{0.15f, 0.85f, 0.25f};         ///< grabbed by the probe: green
inline constexpr Rgb probe_colour{0.92f, 0.35f, 0.78f};           ///< the probe: magenta (in no colour map here)
inline constexpr Rgb probe_colour_on_bands{0.25f, 0.75f, 0.95f};  ///< the probe over band colours: sky blue
inline constexpr Rgb unselected_colour{0.62f, 0.64f, 0.68f};      ///< not simulated (levels of detail)
inline constexpr Rgb obstacle_colour{0.45f, 0.47f, 0.52f};        ///< planes and boxes: slate grey
inline constexpr Rgb posed_tool_colour{0.95f, 0.62f, 0.18f};      ///< tools the scene poses: amber

/// A level-of-detail band (0: T_r1, 1: T_r2, 1 + i: level i), darkest near the contact; -1: not
/// simulated.
Rgb band_colour(int band);

/// Pack into the 0xAABBGGRR order of ImGui's IM_COL32.
std::uint32_t pack_rgba(const Rgb& c, float alpha = 1.0f);

}  // namespace pointhaptics::viewer
