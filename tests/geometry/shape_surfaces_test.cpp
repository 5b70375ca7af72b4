// Tests for geometry/shape_surfaces: the box's, sphere's and half-sphere's surfaces are closed, manifold and
// outward; every vertex lies on the exact boundary; the enclosed volume converges to the solid's; edges stay
// near the asked length.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/shape_surfaces.hpp>

#include <gtest/gtest.h>

#include <numbers>

namespace pointhaptics {
namespace {

struct EdgeRange {
  double shortest = 1e300, longest = 0;
};
EdgeRange edge_range(const TriangleMesh& mesh) {
  EdgeRange r;
  for (const auto& f : mesh.F)
    for (int k = 0; k < 3; ++k) {
      const double l = (mesh.V.col(f[k]) - mesh.V.col(f[(k + 1) % 3])).norm();
      r.shortest = std::min(r.shortest, l), r.longest = std::max(r.longest, l);
    }
  return r;
}

TEST(BoxSurface, IsClosedOutwardOnTheTrueFacesWithTheBoxVolume) {
  const Vec3 origin(-0.02, 0.0, 0.01), size(0.08, 0.04, 0.05);
  for (double edge : {0.01, 0.0031}) {
    const TriangleMesh mesh = box_surface(origin, size, edge);
    EXPECT_NO_THROW(check_closed_manifold(mesh, "box"));
    EXPECT_NEAR(enclosed_volume(mesh), size.prod(), 1e-12 * size.prod());
    for (Eigen::Index v = 0; v < mesh.V.cols(); ++v) {
      const Vec3 p = mesh.V.col(v);
      // on a face: some coordinate exactly at the box's extent, all within it
      bool on_face = false;
      for (int a = 0; a < 3; ++a) {
        EXPECT_GE(p[a], origin[a]);
        EXPECT_LE(p[a], origin[a] + size[a]);
        on_face = on_face || p[a] == origin[a] || p[a] == origin[a] + size[a];
      }
      EXPECT_TRUE(on_face) << "vertex " << v;
    }
    const EdgeRange r = edge_range(mesh);
    EXPECT_LE(r.longest, std::sqrt(2.0) * edge + 1e-12);  // a cell's diagonal
    EXPECT_GE(r.shortest, 0.5 * edge);
  }
}

TEST(SphereSurface, IsClosedOutwardOnTheSphereAndConvergesToItsVolume) {
  const Vec3 centre(0.1, -0.05, 0.0);
  const double radius = 0.05, ball = 4.0 / 3.0 * std::numbers::pi * std::pow(radius, 3);
  double previous_error = 1;
  for (double edge : {0.01, 0.005, 0.0025}) {
    const TriangleMesh mesh = sphere_surface(centre, radius, edge);
    EXPECT_NO_THROW(check_closed_manifold(mesh, "sphere"));
    for (Eigen::Index v = 0; v < mesh.V.cols(); ++v) EXPECT_NEAR((mesh.V.col(v) - centre).norm(), radius, 1e-14);
    const double error = (ball - enclosed_volume(mesh)) / ball;  // inscribed: a little less
    EXPECT_GT(error, 0);
    EXPECT_LT(error, 0.5 * previous_error);  // second order: a quarter per halving
    previous_error = error;
    const EdgeRange r = edge_range(mesh);
    EXPECT_LE(r.longest, 1.6 * edge) << "edge " << edge;
    EXPECT_GE(r.shortest, 0.4 * edge) << "edge " << edge;
  }
  EXPECT_LT(previous_error, 0.01);
}

TEST(HalfSphereSurface, IsClosedOutwardOnTheDomeAndTheDiskAndConvergesToItsVolume) {
  const Vec3 centre(0.0, 0.02, 0.0);
  const double radius = 0.04, half_ball = 2.0 / 3.0 * std::numbers::pi * std::pow(radius, 3);
  double previous_error = 1;
  for (double edge : {0.008, 0.004, 0.002}) {
    const TriangleMesh mesh = half_sphere_surface(centre, radius, edge);
    EXPECT_NO_THROW(check_closed_manifold(mesh, "half-sphere"));
    for (Eigen::Index v = 0; v < mesh.V.cols(); ++v) {
      const Vec3 p = mesh.V.col(v) - centre;
      EXPECT_GE(p.y(), 0);
      if (p.y() > 0) EXPECT_NEAR(p.norm(), radius, 1e-14);  // the dome
      else EXPECT_LE(p.norm(), radius * (1 + 1e-14));       // the disk
    }
    // the disk faces down, the dome up
    for (const auto& f : mesh.F) {
      const Vec3 a = mesh.V.col(f[0]), b = mesh.V.col(f[1]), c = mesh.V.col(f[2]);
      const Vec3 n = (b - a).cross(c - a);
      if (a.y() == centre.y() && b.y() == centre.y() && c.y() == centre.y()) EXPECT_LT(n.y(), 0);
      else EXPECT_GT(n.dot((a + b + c) / 3 - centre), 0);
    }
    const double error = (half_ball - enclosed_volume(mesh)) / half_ball;
    EXPECT_GT(error, 0);
    EXPECT_LT(error, 0.5 * previous_error);
    previous_error = error;
    const EdgeRange r = edge_range(mesh);
    EXPECT_LE(r.longest, 1.7 * edge) << "edge " << edge;
    EXPECT_GE(r.shortest, 0.3 * edge) << "edge " << edge;
  }
}

TEST(ShapeSurfaces, RejectABadEdgeLength) {
  for (double edge : {0.0, -1.0, std::nan(""), 1e-12})
    EXPECT_THROW(box_surface(Vec3::Zero(), Vec3::Ones(), edge), Error) << edge;
  EXPECT_THROW(sphere_surface(Vec3::Zero(), 1.0, 0.0), Error);
  EXPECT_THROW(half_sphere_surface(Vec3::Zero(), 1.0, std::numeric_limits<double>::infinity()), Error);
}

}  // namespace
}  // namespace pointhaptics
