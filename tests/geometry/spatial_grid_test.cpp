// Tests for geometry/spatial_grid: sphere queries equal brute force, each point once, bad input is harmless.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/spatial_grid.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace pointhaptics {
namespace {

TEST(SpatialGrid, SphereQueriesEqualBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uni(-0.1, 0.1);
  Points x(3, 5000);
  for (Eigen::Index k = 0; k < x.size(); ++k) x.data()[k] = uni(rng);
  for (double cell : {0.005, 0.02, 0.3}) {
    SpatialGrid grid(cell);
    grid.rebuild(x);
    for (int q = 0; q < 50; ++q) {
      const Vec3 c(uni(rng), uni(rng), uni(rng));
      const double r = 0.001 + 0.04 * (q % 5);
      std::vector<index_t> found, expected;
      grid.for_each_within(x, c, r, [&](index_t i) { found.push_back(i); });
      for (index_t i = 0; i < x.cols(); ++i)
        if ((x.col(i) - c).squaredNorm() <= r * r) expected.push_back(i);
      std::sort(found.begin(), found.end());
      EXPECT_EQ(found, expected) << "cell " << cell << " query " << q;  // each point exactly once
    }
  }
}

TEST(SpatialGrid, NonFiniteInputIsHarmless) {
  Points x = Points::Zero(3, 3);
  x(0, 1) = NAN;
  SpatialGrid grid(0.01);
  grid.rebuild(x);
  int seen = 0;
  grid.for_each_within(x, Vec3(NAN, 0, 0), 1.0, [&](index_t) { ++seen; });
  EXPECT_EQ(seen, 0);
  grid.for_each_within(x, Vec3::Zero(), 0.001, [&](index_t) { ++seen; });
  EXPECT_EQ(seen, 2);  // the two finite points at the origin
  EXPECT_THROW(SpatialGrid(0.0), Error);
}

}  // namespace
}  // namespace pointhaptics
