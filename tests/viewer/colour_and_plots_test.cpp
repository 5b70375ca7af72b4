// Tests for the viewer's colours (viridis ends and monotone lightness, band colours, packing) and live
// plots (the rolling window, the rate meter).
#include "colour_map.hpp"
#include "live_plots.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace pointhaptics::viewer {
namespace {

double luminance(const Rgb& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

TEST(ColourMap, ViridisRunsDarkToLightAndClamps) {
  double last = -1;
  for (int k = 0; k <= 100; ++k) {
    const double l = luminance(viridis(k / 100.0));
    EXPECT_GT(l, last) << k;  // lightness increases: readable in grey too
    last = l;
  }
  EXPECT_EQ(viridis(-1), viridis(0));
  EXPECT_EQ(viridis(2), viridis(1));
  EXPECT_EQ(viridis(NAN), viridis(0));
  EXPECT_NEAR(viridis(1)[0], 0.993f, 1e-6);
}

TEST(ColourMap, BandsDarkenTowardTheContactAndPackForImGui) {
  for (int b = 1; b < 8; ++b) EXPECT_GE(luminance(band_colour(b)), luminance(band_colour(b - 1)));
  EXPECT_EQ(band_colour(-1), unselected_colour);
  EXPECT_EQ(pack_rgba({1.0f, 0.0f, 0.0f}), 0xFF0000FFu);  // IM_COL32(255, 0, 0, 255)
  EXPECT_EQ(pack_rgba({0.0f, 0.0f, 1.0f}, 0.0f), 0x00FF0000u);
}

TEST(RollingSeries, KeepsTheLastWindowOldestFirst) {
  RollingSeries s(1.0, 8);
  std::vector<float> v;
  s.values(v);
  EXPECT_TRUE(v.empty());
  for (int k = 0; k < 20; ++k) s.push(0.25 * k, static_cast<float>(k));
  s.values(v);  // the window [3.75, 4.75]: samples 15 .. 19
  ASSERT_EQ(v.size(), 5u);
  EXPECT_EQ(v.front(), 15.0f);
  EXPECT_EQ(v.back(), 19.0f);
  EXPECT_EQ(s.latest(), 19.0f);
  EXPECT_EQ(s.max(), 19.0f);
  EXPECT_EQ(s.size(), 8u);  // the ring holds 8
}

TEST(RateMeter, CountsPerSecondAndRestartsWithTheCounter) {
  RateMeter m(0.5);
  EXPECT_FALSE(m.update(0.0, 0));
  EXPECT_FALSE(m.update(0.25, 250));
  EXPECT_TRUE(m.update(0.5, 500));
  EXPECT_DOUBLE_EQ(m.rate(), 1000.0);
  EXPECT_FALSE(m.update(0.6, 10));  // a new run: the counter went back
  EXPECT_TRUE(m.update(1.1, 260));
  EXPECT_DOUBLE_EQ(m.rate(), 500.0);
}

}  // namespace
}  // namespace pointhaptics::viewer
