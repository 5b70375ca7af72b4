// Tests for geometry/sampling.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/sampling.hpp>

#include <gtest/gtest.h>

#include <numbers>

namespace pointhaptics {
namespace {

TEST(SampleBox, VertexGridIncludesFacesAndVolumesSumToTheBox) {
  const Vec3 origin(0.1, -0.2, 0.3), size(0.06, 0.02, 0.02);
  const PointCloud c = sample_box(origin, size, 0.005);
  ASSERT_EQ(c.size(), 13 * 5 * 5);
  EXPECT_NEAR(c.volume.sum(), size.prod(), 1e-15);
  // the far corner lies exactly on the box
  EXPECT_EQ((c.X.rowwise().maxCoeff() - (origin + size)).norm(), 0.0);
  EXPECT_EQ((c.X.rowwise().minCoeff() - origin).norm(), 0.0);
  // interior, face, edge and corner points own 1, 1/2, 1/4, 1/8 cells
  const double cell = 0.005 * 0.005 * 0.005;
  EXPECT_NEAR(c.volume.maxCoeff(), cell, 1e-18);
  EXPECT_NEAR(c.volume.minCoeff(), cell / 8, 1e-18);
  EXPECT_NEAR(c.volume[0], cell / 8, 1e-18);  // a corner
  int surface = 0;
  for (auto s : c.surface) surface += s;
  EXPECT_EQ(surface, 13 * 5 * 5 - 11 * 3 * 3);
}

TEST(SampleBox, RoundsToWholeIntervals) {
  const PointCloud c = sample_box(Vec3::Zero(), Vec3(0.15, 0.03, 0.03), 0.015);
  EXPECT_EQ(c.size(), 11 * 3 * 3);
  const PointCloud d = sample_box(Vec3::Zero(), Vec3(0.1, 0.1, 0.1), 0.03);  // 3.33 intervals -> 3
  EXPECT_EQ(d.size(), 4 * 4 * 4);
  EXPECT_NEAR(d.volume.sum(), 1e-3, 1e-15);
}

TEST(SampleBox, RejectsBadInput) {
  EXPECT_THROW(sample_box(Vec3::Zero(), Vec3(0.1, 0, 0.1), 0.01), Error);
  EXPECT_THROW(sample_box(Vec3::Zero(), Vec3::Constant(0.1), -0.01), Error);
  EXPECT_THROW(sample_box(Vec3::Zero(), Vec3::Constant(0.1), std::nan("")), Error);
  EXPECT_THROW(sample_box(Vec3::Zero(), Vec3::Constant(10.0), 1e-5), Error);
}

TEST(SampleSphere, PointsInsideAndVolumesSumToTheBall) {
  const Vec3 centre(0.01, 0.02, 0.03);
  const double r = 0.05, s = 0.01;
  const PointCloud c = sample_sphere(centre, r, s);
  EXPECT_GT(c.size(), 400);
  for (index_t i = 0; i < c.size(); ++i) EXPECT_LE((c.X.col(i) - centre).norm(), r * (1 + 1e-9));
  EXPECT_NEAR(c.volume.sum(), 4.0 / 3.0 * std::numbers::pi * r * r * r, 1e-12);
  EXPECT_GT(c.volume.minCoeff(), 0);
  // interior points own a cell (up to the final rescaling); surface points own what lies beyond the grid too
  for (index_t i = 0; i < c.size(); ++i)
    if (!c.surface[i]) {
      EXPECT_NEAR(c.volume[i], s * s * s, 0.05 * s * s * s) << "point " << i;
    }
}

TEST(SampleHalfSphere, FlatFaceDownVolumesSumToHalfBall) {
  const Vec3 centre(0, 0, 0);
  const double r = 0.04, s = 0.005;
  const PointCloud c = sample_half_sphere(centre, r, s);
  for (index_t i = 0; i < c.size(); ++i) {
    EXPECT_GE(c.X(1, i), -1e-12);
    EXPECT_LE(c.X.col(i).norm(), r * (1 + 1e-9));
  }
  EXPECT_NEAR(c.volume.sum(), 2.0 / 3.0 * std::numbers::pi * r * r * r, 1e-12);
  // the flat face y = 0 is sampled
  EXPECT_EQ(c.X.row(1).minCoeff(), 0.0);
  // flat-face points own about half a cell
  for (index_t i = 0; i < c.size(); ++i)
    if (c.X(1, i) == 0.0 && c.X.col(i).norm() < 0.5 * r) {
      EXPECT_NEAR(c.volume[i], 0.5 * s * s * s, 0.1 * s * s * s);
    }
}

}  // namespace
}  // namespace pointhaptics
