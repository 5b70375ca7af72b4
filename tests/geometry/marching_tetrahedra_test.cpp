// Tests for geometry/marching_tetrahedra: the level set of a field on a grid is closed, manifold and
// outward; its vertices lie on the level of the field's linear interpolation; it converges to a known
// surface as the grid is refined; two separate blobs give two closed pieces.
#include <pointhaptics/geometry/marching_tetrahedra.hpp>
#include <pointhaptics/geometry/shape_surfaces.hpp>

#include <gtest/gtest.h>

#include <functional>
#include <numbers>

namespace pointhaptics {
namespace {

GridField sample(const std::function<double(const Vec3&)>& f, const Vec3& lo, const Vec3& hi, double cell) {
  GridField g;
  g.origin = lo;
  g.cell = cell;
  for (int a = 0; a < 3; ++a)
    g.nodes[static_cast<std::size_t>(a)] = static_cast<index_t>(std::ceil((hi[a] - lo[a]) / cell)) + 1;
  for (index_t k = 0; k < g.nodes[2]; ++k)
    for (index_t j = 0; j < g.nodes[1]; ++j)
      for (index_t i = 0; i < g.nodes[0]; ++i)
        g.values.push_back(f(lo + cell * Vec3(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k))));
  return g;
}

TEST(MarchingTetrahedra, ASphereIsClosedOutwardAndConvergesToTheSphere) {
  const double R = 0.3;
  const Vec3 c(0.05, -0.02, 0.01);
  double previous = 1;
  for (double cell : {0.1, 0.05, 0.025}) {
    // a field whose level 0 is the sphere: R - |x - c|, linear along rays
    const GridField g =
        sample([&](const Vec3& x) { return R - (x - c).norm(); }, Vec3::Constant(-0.5), Vec3::Constant(0.5), cell);
    const TriangleMesh mesh = marching_tetrahedra(g, 0.0);
    EXPECT_NO_THROW(check_closed_manifold(mesh, "sphere"));
    double worst = 0;
    for (Eigen::Index v = 0; v < mesh.V.cols(); ++v) worst = std::max(worst, std::abs((mesh.V.col(v) - c).norm() - R));
    EXPECT_LT(worst, 0.5 * cell * cell / R) << cell;  // the linear interpolation along (diagonal) edges: second order
    const double volume = enclosed_volume(mesh), ball = 4.0 / 3.0 * std::numbers::pi * R * R * R;
    EXPECT_GT(volume, 0);
    const double error = std::abs(volume - ball) / ball;
    EXPECT_LT(error, 0.6 * previous) << cell;
    previous = error;
  }
  EXPECT_LT(previous, 0.01);
}

TEST(MarchingTetrahedra, TwoBlobsAreTwoClosedPiecesAndValuesAtTheLevelCountAsOutside) {
  // two balls apart, the field exactly at the level on many nodes (a plane of them)
  const GridField g = sample(
      [](const Vec3& x) {
        const double a = 0.2 - (x - Vec3(-0.3, 0, 0)).norm(), b = 0.2 - (x - Vec3(0.3, 0, 0)).norm();
        return std::abs(x.y()) < 1e-12 ? 0.0 : std::max(a, b);
      },
      Vec3(-0.6, -0.4, -0.4), Vec3(0.6, 0.4, 0.4), 0.05);
  const TriangleMesh mesh = marching_tetrahedra(g, 0.0);
  EXPECT_NO_THROW(check_closed_manifold(mesh, "blobs"));
  int left = 0, right = 0;
  for (Eigen::Index v = 0; v < mesh.V.cols(); ++v) (mesh.V(0, v) < 0 ? left : right)++;
  EXPECT_GT(left, 50);
  EXPECT_GT(right, 50);
  EXPECT_GT(enclosed_volume(mesh), 0);
}

TEST(MarchingTetrahedra, NothingAboveTheLevelGivesNoTriangle) {
  const GridField g = sample([](const Vec3&) { return -1.0; }, Vec3::Zero(), Vec3::Ones(), 0.25);
  EXPECT_TRUE(marching_tetrahedra(g, 0.0).F.empty());
}

}  // namespace
}  // namespace pointhaptics
