// Tests for haptics/contact_samples: splitting a surface's triangles for a thin tool. Two triangles of a 4 mm
// square split twice (edges of at most 1.5 mm) give the vertices a conforming split would (one sample per
// edge and level, none twice); every sample is the mean of its two ends, in position and in its map row (so
// it moves with its triangle); the split triangles cover the square's area once; nothing is split where the
// edges are already short; and a sample's key is the same on any part of the surface whose vertices have the
// same ids, whatever their order, and never one of the surface's ids.
#include <pointhaptics/haptics/contact_samples.hpp>

#include <gtest/gtest.h>

#include <set>

namespace pointhaptics {
namespace {

// the square [0, 4 mm]^2 at y = 0 as two triangles, each vertex carried by its own "point" (map row: itself)
struct Square {
  TriangleMesh mesh;
  SurfaceMap map;
};

Square square() {
  Square s;
  s.mesh.V.resize(3, 4);
  s.mesh.V << 0, 0.004, 0.004, 0, 0, 0, 0, 0, 0, 0, 0.004, 0.004;
  s.mesh.F = {{0, 2, 1}, {0, 3, 2}};
  for (index_t v = 0; v < 4; ++v) {
    s.map.points.index.push_back(v);
    s.map.weight.push_back(1.0);
    s.map.points.offset.push_back(v + 1);
  }
  return s;
}

TEST(ContactSamples, SplitsEveryLongEdgeOnceAndCarriesEachSampleAsItsEndsMean) {
  const Square s = square();
  const ContactSamples out = contact_samples(s.mesh, s.map, 0.0015);
  EXPECT_EQ(out.levels, 2);  // diagonals of 5.66 mm -> 2.83 -> 1.41
  // level 1: 5 edges; level 2: the 16 edges of the 8 triangles -> 25 vertices, 32 triangles
  EXPECT_EQ(out.mesh.V.cols(), 25);
  EXPECT_EQ(out.mesh.F.size(), 32u);
  ASSERT_EQ(out.parents.size(), 21u);
  ASSERT_EQ(out.map.n_vertices(), 25);
  std::set<std::pair<long, long>> places;  // no two vertices at one place
  for (index_t v = 0; v < 25; ++v) places.insert({std::lround(out.mesh.V(0, v) * 1e6), std::lround(out.mesh.V(2, v) * 1e6)});
  EXPECT_EQ(places.size(), 25u);
  double area = 0;
  for (const auto& t : out.mesh.F) {
    const Vec3 n = (out.mesh.V.col(t[1]) - out.mesh.V.col(t[0])).cross(out.mesh.V.col(t[2]) - out.mesh.V.col(t[0]));
    EXPECT_GT(n.y(), 0);  // counter-clockwise seen from +y, as the square's own
    area += 0.5 * n.norm();
    for (int k = 0; k < 3; ++k) EXPECT_LE((out.mesh.V.col(t[(k + 1) % 3]) - out.mesh.V.col(t[k])).norm(), 0.0015 + 1e-12);
  }
  EXPECT_NEAR(area, 0.004 * 0.004, 1e-15);
  // each sample: the mean of its ends, and its row their rows' mean (merged by point, summing to 1; W applied
  // to the points' positions, point v being the square's vertex v, gives the sample's)
  for (index_t v = 0; v < 25; ++v) {
    Vec3 y = Vec3::Zero();
    double sum = 0;
    for (index_t e = out.map.points.begin(v); e < out.map.points.end(v); ++e) {
      y += out.map.weight[e] * s.mesh.V.col(out.map.points.index[e]);
      sum += out.map.weight[e];
      if (e > out.map.points.begin(v)) {
        EXPECT_LT(out.map.points.index[e - 1], out.map.points.index[e]);
      }
    }
    EXPECT_NEAR(sum, 1.0, 1e-15);
    EXPECT_LT((y - out.mesh.V.col(v)).norm(), 1e-15);
  }
  for (std::size_t k = 0; k < out.parents.size(); ++k) {
    const index_t v = 4 + static_cast<index_t>(k);
    const auto [a, b] = out.parents[k];
    EXPECT_LT(a, v);
    EXPECT_LT(b, v);
    EXPECT_LT((out.mesh.V.col(v) - 0.5 * (out.mesh.V.col(a) + out.mesh.V.col(b))).norm(), 1e-15);
  }
}

TEST(ContactSamples, ShortEdgesAreLeftAsTheyAre) {
  const Square s = square();
  for (const double max_edge : {0.006, 0.0, -1.0}) {
    const ContactSamples out = contact_samples(s.mesh, s.map, max_edge);
    EXPECT_EQ(out.levels, 0);
    EXPECT_EQ(out.mesh.V.cols(), 4);
    EXPECT_EQ(out.mesh.F, s.mesh.F);
    EXPECT_TRUE(out.parents.empty());
  }
  // only the triangles with a long edge: the diagonal (5.66 mm) split, the sides (4 mm) not
  const ContactSamples one = contact_samples(s.mesh, s.map, 0.005);
  EXPECT_EQ(one.levels, 1);
  EXPECT_EQ(one.mesh.V.cols(), 4 + 5);
}

TEST(ContactSamples, KeysNameTheSameSampleOnAnyPartOfTheSurface) {
  const Square s = square();
  const ContactSamples out = contact_samples(s.mesh, s.map, 0.0015);
  const std::vector<std::uint64_t> ids{10, 11, 12, 13};
  const std::vector<std::uint64_t> keys = contact_sample_keys(ids, out.parents);
  ASSERT_EQ(keys.size(), 25u);
  EXPECT_EQ(std::set<std::uint64_t>(keys.begin(), keys.end()).size(), 25u);
  for (std::size_t v = 0; v < 4; ++v) EXPECT_EQ(keys[v], ids[v]);
  for (std::size_t v = 4; v < 25; ++v) EXPECT_GE(keys[v], 1ULL << 63);
  // the same square with its vertices numbered the other way round: each sample at one place has one key
  Square turned = s;
  const std::array<index_t, 4> order{3, 2, 1, 0};  // turned vertex k is the square's vertex order[k]
  for (index_t k = 0; k < 4; ++k) turned.mesh.V.col(k) = s.mesh.V.col(order[k]);
  turned.mesh.F = {{3, 1, 2}, {3, 0, 1}};
  const ContactSamples other = contact_samples(turned.mesh, turned.map, 0.0015);
  std::vector<std::uint64_t> turned_ids(4);
  for (index_t k = 0; k < 4; ++k) turned_ids[k] = ids[order[k]];
  const std::vector<std::uint64_t> other_keys = contact_sample_keys(turned_ids, other.parents);
  ASSERT_EQ(other_keys.size(), 25u);
  for (index_t v = 0; v < 25; ++v)
    for (index_t w = 0; w < 25; ++w)
      if ((out.mesh.V.col(v) - other.mesh.V.col(w)).norm() < 1e-12) {
        EXPECT_EQ(keys[v], other_keys[w]) << v << " " << w;
      }
}

}  // namespace
}  // namespace pointhaptics
