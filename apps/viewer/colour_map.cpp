#include "colour_map.hpp"

#include <algorithm>
#include <cmath>

namespace pointhaptics::viewer {

Rgb viridis(double s) {
  // matplotlib's viridis at 0, 1/8, ..., 1; linear in between (its own table has 256 entries)
  static constexpr std::array<Rgb, 9> table{{{0.267f, 0.005f, 0.329f},
                                             {0.283f, 0.141f, 0.458f},
                                             {0.254f, 0.265f, 0.530f},
                                             {0.207f, 0.372f, 0.553f},
                                             {0.164f, 0.471f, 0.558f},
                                             {0.128f, 0.567f, 0.551f},
                                             {0.135f, 0.659f, 0.518f},
                                             {0.478f, 0.821f, 0.318f},
                                             {0.993f, 0.906f, 0.144f}}};
  if (!(s > 0)) return table.front();
  if (s >= 1) return table.back();
  const double x = s * (table.size() - 1);
  const auto k = static_cast<std::size_t>(x);
  const auto w = static_cast<float>(x - static_cast<double>(k));
  Rgb c;
  for (int i = 0; i < 3; ++i) c[i] = (1 - w) * table[k][i] + w * table[k + 1][i];
  return c;
}

Rgb band_colour(int band) {
  if (band < 0) return unselected_colour;
  // T_r1, T_r2 and the levels from dark to light, as the seed's Fig. 6 shades them
  static constexpr std::array<Rgb, 6> bands{{{0.55f, 0.05f, 0.05f},
                                             {0.85f, 0.30f, 0.08f},
                                             {0.95f, 0.60f, 0.15f},
                                             {0.98f, 0.82f, 0.35f},
                                             {0.99f, 0.92f, 0.62f},
                                             {1.00f, 0.97f, 0.85f}}};
  return bands[std::min<std::size_t>(static_cast<std::size_t>(band), bands.size() - 1)];
}

std::uint32_t pack_rgba(const Rgb& c, float alpha) {
  const auto byte = [](float v) { return static_cast<std::uint32_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); };
  return byte(c[0]) | byte(c[1]) << 8 | byte(c[2]) << 16 | byte(alpha) << 24;
}

}  // namespace pointhaptics::viewer
