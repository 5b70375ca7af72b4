// Tests for geometry/mesh_distance: the signed distance to a box's surface mesh equals the box's exact signed
// distance everywhere (inside, outside, beside faces, edges and corners), and a sphere's mesh is signed right;
// the nearest point within a radius (a moving surface's, without set-up) is MeshDistance's where it sees one.
#include <pointhaptics/geometry/mesh_distance.hpp>
#include <pointhaptics/geometry/shape_surfaces.hpp>

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace pointhaptics {
namespace {

double box_signed_distance(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  const Vec3 centre = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
  const Vec3 q = (p - centre).cwiseAbs() - half;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

// the box both tests measure against, and points around it: each coordinate from `from` to `to` of its size
const Vec3 origin(-0.02, 0.0, 0.01), size(0.08, 0.04, 0.05);
const TriangleMesh& box_mesh() {
  static const TriangleMesh mesh = box_surface(origin, size, 0.007);
  return mesh;
}
std::vector<Vec3> points_around_the_box(double from, double to, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(from, to);
  std::vector<Vec3> points(3000);
  for (Vec3& p : points) p = origin + Vec3(unit(rng), unit(rng), unit(rng)).cwiseProduct(size);
  return points;
}

TEST(MeshDistance, EqualsABoxsExactSignedDistanceInsideOutsideAndNearEdgesAndCorners) {
  const TriangleMesh& mesh = box_mesh();
  const MeshDistance distance(mesh);
  int inside = 0;
  for (const Vec3& p : points_around_the_box(-0.3, 1.3, 7)) {
    const double exact = box_signed_distance(p, origin, origin + size);
    ASSERT_NEAR(distance.signed_distance(p), exact, 1e-12) << p.transpose();
    inside += exact < 0;
  }
  EXPECT_GT(inside, 500);
  // on a vertex, an edge's middle and a corner, just inside and just outside
  for (const Vec3& on : {origin, Vec3(origin + Vec3(0.5 * size.x(), 0, 0)), Vec3(origin + size)}) {
    const Vec3 centre = origin + 0.5 * size;
    EXPECT_LT(distance.signed_distance(on + 1e-6 * (centre - on).normalized()), 0);
    EXPECT_GT(distance.signed_distance(on - 1e-6 * (centre - on).normalized()), 0);
  }
}

TEST(MeshDistance, SignsASpheresMeshRight) {
  const TriangleMesh mesh = sphere_surface(Vec3(0.01, 0.02, 0.03), 0.05, 0.004);
  const MeshDistance distance(mesh);
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  for (int k = 0; k < 1000; ++k) {
    const Vec3 direction = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
    for (const double r : {0.0, 0.02, 0.045, 0.055, 0.08}) {
      const double d = distance.signed_distance(Vec3(0.01, 0.02, 0.03) + r * direction);
      EXPECT_EQ(d < 0, r < 0.05) << r;
      EXPECT_NEAR(d, r - 0.05, 0.05 * 0.02) << r;  // the mesh's chords lie within a small part of the radius
    }
  }
}

// What a moving surface's test sees (nearest_surface_within: the triangles within a radius, the pseudo-normal
// made on the spot) is what MeshDistance sees with its set-up, near faces, edges and corners, in and out; and
// nothing beyond the radius.
TEST(MeshDistance, TheNearestPointWithinARadiusIsSignedAsTheWholeMeshsDistance) {
  const TriangleMesh& mesh = box_mesh();
  const MeshDistance distance(mesh);
  const double radius = 0.01;
  int seen = 0, inside = 0;
  for (const Vec3& p : points_around_the_box(-0.2, 1.2, 11)) {
    const double exact = distance.signed_distance(p);
    const std::optional<SurfaceSide> side = nearest_surface_within(p, mesh.V, mesh.F, radius);
    ASSERT_EQ(side.has_value(), std::abs(exact) < radius) << p.transpose();
    if (!side) continue;
    ++seen;
    inside += exact < 0;
    ASSERT_NEAR(side->distance, exact, 1e-12) << p.transpose();
    ASSERT_NEAR((side->point - p).norm(), std::abs(exact), 1e-12);
  }
  EXPECT_GT(seen, 500);
  EXPECT_GT(inside, 100);
  // just inside and just outside a corner and an edge's middle: the pseudo-normal of a corner, of an edge
  for (const Vec3& on : {origin, Vec3(origin + Vec3(0.5 * size.x(), 0, 0))}) {
    const Vec3 in = (origin + 0.5 * size - on).normalized();
    EXPECT_LT(nearest_surface_within(on + 1e-6 * in, mesh.V, mesh.F, radius)->distance, 0);
    EXPECT_GT(nearest_surface_within(on - 1e-6 * in, mesh.V, mesh.F, radius)->distance, 0);
    EXPECT_TRUE(nearest_surface_within(on + 1e-6 * in, mesh.V, mesh.F, radius)->sure);
  }
  // a part of the surface (the top face's triangles): in front of and behind a face the sign is sure, beside
  // its edge or corner, where the part ends, it is not
  TriangleMesh top = mesh;
  std::erase_if(top.F, [&](const std::array<index_t, 3>& f) {
    return mesh.V(1, f[0]) < size.y() - 1e-12 || mesh.V(1, f[1]) < size.y() - 1e-12 ||
           mesh.V(1, f[2]) < size.y() - 1e-12;
  });
  ASSERT_GT(top.F.size(), 10u);
  const Vec3 middle = origin + Vec3(0.31 * size.x(), size.y(), 0.43 * size.z());
  for (const double off : {-0.002, 0.002}) {
    const std::optional<SurfaceSide> side = nearest_surface_within(middle + Vec3(0, off, 0), top.V, top.F, radius);
    EXPECT_TRUE(side->sure);
    EXPECT_NEAR(side->distance, off, 1e-12);
  }
  EXPECT_FALSE(nearest_surface_within(origin + Vec3(-0.001, size.y() - 0.002, 0.5 * size.z()), top.V, top.F, radius)
                   ->sure);  // an edge
  EXPECT_FALSE(
      nearest_surface_within(origin + Vec3(-0.001, size.y() - 0.002, -0.001), top.V, top.F, radius)->sure);  // a corner
}

}  // namespace
}  // namespace pointhaptics
