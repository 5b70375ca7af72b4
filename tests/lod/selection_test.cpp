// Tests for lod/selection: band membership, the selection probability of each band (statistically),
// held points always selected, reproducibility, and parameter validation.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/lod/selection.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace pointhaptics {
namespace {

const double s = 0.002;

Model cube() {
  return build_model(test::jittered_box(30, 30, 30, s, 0.0), MaterialParams{}, KernelParams{});
}  // 27k points

LodParams seed_params() {
  LodParams p;
  p.k1 = 1.0;
  p.k2 = 1.5;
  p.levels = {{3.0, 6}, {6.0, 8}};
  p.seed = 7;
  return p;
}

TEST(LodSelection, BandsFollowTheDistances) {
  const Model model = cube();
  const Vec3 c = model.X.col(0) + Vec3(0.029, 0.029, 0.029) * 0.5;
  std::mt19937_64 rng(1);
  const Selection sel = select_points(model, c, seed_params(), rng);
  for (index_t i = 0; i < model.n_points; ++i) {
    const double d = (model.X.col(i) - c).norm() / model.h;
    const int expected = d <= 1.0 ? 0 : d <= 1.5 ? 1 : d <= 3.0 ? 2 : d <= 6.0 ? 3 : -1;
    ASSERT_EQ(sel.band[i], expected) << "point " << i << " at " << d << " h";
  }
  // within T_r1 everything is selected, beyond the last level nothing (no point is held here)
  EXPECT_EQ(sel.band_selected[0], sel.band_count[0]);
  for (index_t i : sel.selected) EXPECT_GE(sel.band[i], 0);
  EXPECT_TRUE(std::is_sorted(sel.selected.begin(), sel.selected.end()));
}

TEST(LodSelection, DitherSelectsEachWeightExactlyAndEvenlyOnALattice) {
  // on a lattice, every 4x4x4 block of a band holds exactly round(64 (10 - K) / 10) selected points with
  // the dithered scheme, for every K
  const Model model = build_model(test::jittered_box(16, 16, 16, s, 0.0), MaterialParams{}, KernelParams{});
  for (int K = 0; K <= 10; ++K) {
    int per_block[64] = {};
    for (index_t i = 0; i < model.n_points; ++i) {
      const double r = dither_threshold(model.X.col(i), s);
      ASSERT_GE(r, 0.0);
      ASSERT_LT(r, 10.0);
      if (r < K) continue;
      int block = 0;
      for (int a = 0; a < 3; ++a) block = 4 * block + static_cast<int>(std::floor(model.X(a, i) / s + 0.5)) / 4;
      ++per_block[block];
    }
    // thresholds 10 (v + 0.5) / 64 >= K  <=>  v >= 6.4 K - 0.5
    const int expected = 64 - static_cast<int>(std::ceil(6.4 * K - 0.5));
    for (int b = 0; b < 64; ++b) ASSERT_EQ(per_block[b], expected) << "K = " << K << ", block " << b;
  }
  // and evenly: at weight 1/8 (values 56..63) the selected points form a lattice of twice the spacing,
  // so no two are closer than 2 s
  std::vector<Vec3> eighth;
  for (index_t i = 0; i < model.n_points; ++i)
    if (dither_threshold(model.X.col(i), s) >= 10.0 * 56.0 / 64.0) eighth.push_back(model.X.col(i));
  double closest = INFINITY;
  for (std::size_t a = 0; a < eighth.size(); ++a)
    for (std::size_t b = a + 1; b < eighth.size(); ++b) closest = std::min(closest, (eighth[a] - eighth[b]).norm());
  EXPECT_NEAR(closest, 2 * s, 1e-12);
}

TEST(LodSelection, DitherSchemeKeepsTheBandsAndIsTheSameForEverySeed) {
  const Model model = cube();
  const Vec3 c = model.X.rowwise().mean();
  LodParams p = seed_params();
  p.scheme = LodScheme::DITHER;
  std::mt19937_64 a(1), b(99);
  const Selection s1 = select_points(model, c, p, a), s2 = select_points(model, c, p, b);
  EXPECT_EQ(s1.selected, s2.selected);
  EXPECT_EQ(s1.band_selected[0], s1.band_count[0]);
  const double expected[] = {1.0, 0.8, 0.4, 0.2};
  for (int band = 1; band < 4; ++band)
    EXPECT_NEAR(static_cast<double>(s1.band_selected[band]) / s1.band_count[band], expected[band], 0.08)
        << "band " << band;
}

TEST(LodSelection, EachBandIsSelectedWithTheSeedsProbability) {
  const Model model = cube();
  const Vec3 c = model.X.rowwise().mean();
  LodParams p = seed_params();
  p.k2 = 3.0;  // wide bands: enough points in each for the statistics
  p.levels = {{5.0, 6}, {7.0, 8}};
  std::mt19937_64 rng(p.seed);
  const Selection sel = select_points(model, c, p, rng);
  // band: probability 0.8 (Ran > 2), 0.4 (K = 6), 0.2 (K = 8); within 4 standard deviations
  const double expected[] = {1.0, 0.8, 0.4, 0.2};
  for (int b = 1; b < 4; ++b) {
    const double n = sel.band_count[b], q = expected[b];
    ASSERT_GT(n, 200) << "band " << b;
    const double rate = sel.band_selected[b] / n;
    EXPECT_NEAR(rate, q, 4 * std::sqrt(q * (1 - q) / n)) << "band " << b << " over " << n << " points";
  }
}

TEST(LodSelection, HeldPointsAreAlwaysSelectedAndASeedGivesOneSelection) {
  Model model = cube();
  for (index_t i = 0; i < model.n_points; i += 97) model.fixed[i] = 1;
  const Vec3 c = model.X.col(0);
  std::mt19937_64 a(3), b(3), other(4);
  const Selection s1 = select_points(model, c, seed_params(), a), s2 = select_points(model, c, seed_params(), b),
                  s3 = select_points(model, c, seed_params(), other);
  EXPECT_EQ(s1.selected, s2.selected);
  EXPECT_NE(s1.selected, s3.selected);
  for (index_t i = 0; i < model.n_points; i += 97)
    EXPECT_TRUE(std::binary_search(s1.selected.begin(), s1.selected.end(), i));
}

TEST(LodSelection, BadParametersAreNamedErrors) {
  LodParams p = seed_params();
  p.k2 = 0.5;
  EXPECT_THROW(validate(p), Error);
  p = seed_params();
  p.levels[1].distance = 2.0;
  try {
    validate(p);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("lod.levels[1].distance"), std::string::npos) << e.what();
  }
  p = seed_params();
  p.levels[0].K = 11;
  EXPECT_THROW(validate(p), Error);
  p = seed_params();
  p.levels[1].K = 2;  // decreasing
  EXPECT_THROW(validate(p), Error);
  const Model model = cube();
  std::mt19937_64 rng(1);
  EXPECT_THROW(select_points(model, Vec3(NAN, 0, 0), seed_params(), rng), Error);
}

}  // namespace
}  // namespace pointhaptics
