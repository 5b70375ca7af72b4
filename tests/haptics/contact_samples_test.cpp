// Tests for haptics/contact_samples: splitting a surface's triangles for a thin tool. Two triangles of a 4 mm
// square split twice (edges of at most 1.5 mm) give the samples a conforming split would (one per edge and
// level, none twice); every sample is the midpoint of its parents and a convex combination of one triangle's
// vertices (so it moves with its triangle); the split triangles cover the square's area once; nothing is
// split where the edges are already short; and a sample's key is the same on any part of the surface whose
// vertices have the same ids, whatever their order, and never one of the surface's ids.
#include <pointhaptics/haptics/contact_samples.hpp>

#include <gtest/gtest.h>

#include <set>

namespace pointhaptics {
namespace {

// the square [0, 4 mm]^2 at y = 0 as two triangles
TriangleMesh square() {
  TriangleMesh mesh;
  mesh.V.resize(3, 4);
  mesh.V << 0, 0.004, 0.004, 0, 0, 0, 0, 0, 0, 0, 0.004, 0.004;
  mesh.F = {{0, 2, 1}, {0, 3, 2}};
  return mesh;
}

// The position of point p of the samples' numbering: the surface's vertices, then the samples
Vec3 position(const TriangleMesh& mesh, const ContactSamples& out, index_t p) {
  return p < mesh.V.cols() ? Vec3(mesh.V.col(p)) : Vec3(out.Y.col(p - mesh.V.cols()));
}

TEST(ContactSamples, SplitsEveryLongEdgeOnceAndCarriesEachSampleByItsTrianglesVertices) {
  const TriangleMesh mesh = square();
  const ContactSamples out = contact_samples(mesh, 0.0015);
  EXPECT_EQ(out.levels, 2);  // diagonals of 5.66 mm -> 2.83 -> 1.41
  // level 1: 5 edges; level 2: the 16 edges of the 8 triangles -> 21 samples, 32 triangles
  ASSERT_EQ(out.Y.cols(), 21);
  ASSERT_EQ(out.samples.size(), 21u);
  ASSERT_EQ(out.parents.size(), 21u);
  EXPECT_EQ(out.triangles.size(), 32u);
  std::set<std::pair<long, long>> places;  // no two points at one place
  for (index_t p = 0; p < 25; ++p)
    places.insert({std::lround(position(mesh, out, p).x() * 1e6), std::lround(position(mesh, out, p).z() * 1e6)});
  EXPECT_EQ(places.size(), 25u);
  double area = 0;
  for (const auto& t : out.triangles) {
    const Vec3 a = position(mesh, out, t[0]), b = position(mesh, out, t[1]), c = position(mesh, out, t[2]);
    const Vec3 n = (b - a).cross(c - a);
    EXPECT_GT(n.y(), 0);  // counter-clockwise seen from +y, as the square's own
    area += 0.5 * n.norm();
    EXPECT_LE(std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()}), 0.0015 + 1e-12);
  }
  EXPECT_NEAR(area, 0.004 * 0.004, 1e-15);
  for (index_t k = 0; k < 21; ++k) {
    // a combination of one triangle's vertices (weights >= 0, summing to 1) that gives the sample's place
    const ContactSample& sample = out.samples[static_cast<std::size_t>(k)];
    Vec3 y = Vec3::Zero();
    double sum = 0;
    for (int i = 0; i < 3; ++i) {
      EXPECT_GE(sample.weight[i], 0.0);
      EXPECT_LT(sample.vertex[i], 4);
      y += sample.weight[i] * mesh.V.col(sample.vertex[i]);
      sum += sample.weight[i];
    }
    EXPECT_NEAR(sum, 1.0, 1e-15);
    EXPECT_LT((y - out.Y.col(k)).norm(), 1e-15);
    // and the midpoint of its parents, both before it
    const auto [a, b] = out.parents[static_cast<std::size_t>(k)];
    EXPECT_LT(a, 4 + k);
    EXPECT_LT(b, 4 + k);
    EXPECT_LT((out.Y.col(k) - 0.5 * (position(mesh, out, a) + position(mesh, out, b))).norm(), 1e-15);
  }
}

TEST(ContactSamples, ShortEdgesAreLeftAsTheyAre) {
  const TriangleMesh mesh = square();
  for (const double max_edge : {0.006, 0.0, -1.0}) {
    const ContactSamples out = contact_samples(mesh, max_edge);
    EXPECT_EQ(out.levels, 0);
    EXPECT_EQ(out.Y.cols(), 0);
    EXPECT_EQ(out.triangles, mesh.F);
    EXPECT_TRUE(out.samples.empty());
  }
  // only the triangles with a long edge: the diagonal (5.66 mm) is, so both split once, the halves' not
  const ContactSamples one = contact_samples(mesh, 0.005);
  EXPECT_EQ(one.levels, 1);
  EXPECT_EQ(one.Y.cols(), 5);
}

TEST(ContactSamples, KeysNameTheSameSampleOnAnyPartOfTheSurface) {
  const TriangleMesh mesh = square();
  const ContactSamples out = contact_samples(mesh, 0.0015);
  const std::vector<std::uint64_t> ids{10, 11, 12, 13};
  const std::vector<std::uint64_t> keys = contact_sample_keys(ids, out.parents);
  ASSERT_EQ(keys.size(), 25u);
  EXPECT_EQ(std::set<std::uint64_t>(keys.begin(), keys.end()).size(), 25u);
  for (std::size_t v = 0; v < 4; ++v) EXPECT_EQ(keys[v], ids[v]);
  for (std::size_t v = 4; v < 25; ++v) EXPECT_GE(keys[v], 1ULL << 63);
  // the same square with its vertices numbered the other way round: each sample at one place has one key
  TriangleMesh turned = mesh;
  const std::array<index_t, 4> order{3, 2, 1, 0};  // turned vertex k is the square's vertex order[k]
  for (index_t k = 0; k < 4; ++k) turned.V.col(k) = mesh.V.col(order[static_cast<std::size_t>(k)]);
  turned.F = {{3, 1, 2}, {3, 0, 1}};
  const ContactSamples other = contact_samples(turned, 0.0015);
  std::vector<std::uint64_t> turned_ids(4);
  for (std::size_t k = 0; k < 4; ++k) turned_ids[k] = ids[static_cast<std::size_t>(order[k])];
  const std::vector<std::uint64_t> other_keys = contact_sample_keys(turned_ids, other.parents);
  ASSERT_EQ(other_keys.size(), 25u);
  int matched = 0;
  for (index_t v = 0; v < 25; ++v)
    for (index_t w = 0; w < 25; ++w)
      if ((position(mesh, out, v) - position(turned, other, w)).norm() < 1e-12) {
        EXPECT_EQ(keys[static_cast<std::size_t>(v)], other_keys[static_cast<std::size_t>(w)]) << v << " " << w;
        ++matched;
      }
  EXPECT_EQ(matched, 25);
}

}  // namespace
}  // namespace pointhaptics
