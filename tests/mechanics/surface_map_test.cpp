// Tests for mechanics/surface_map: the surface is carried exactly by affine and rigid displacement fields,
// each vertex's weights are a partition of unity (without its negative weights too, which still carries
// translations and pushes every point of a vertex the way the vertex is pushed), forces go to the points with
// the same virtual work as a finite-difference check of a surface potential confirms, every kernel works (the
// viscosity kernel's singular centre included), and a vertex with no points around it is a named error.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/shape_surfaces.hpp>
#include <pointhaptics/mechanics/surface_map.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

#include <algorithm>

namespace pointhaptics {
namespace {

const double spacing = 0.01;

Model model_of(const PointCloud& cloud, KernelType kernel = KernelType::POLY6) {
  KernelParams k;
  k.type = kernel;
  return build_model(cloud, MaterialParams{}, k);
}

struct Case {
  const char* name;
  PointCloud cloud;
  TriangleMesh surface;
};

std::vector<Case> cases() {
  const Vec3 size(0.06, 0.03, 0.04);
  return {{"box", sample_box(Vec3::Zero(), size, spacing), box_surface(Vec3::Zero(), size, spacing / 2)},
          {"jittered box", test::jittered_box(6, 4, 5, spacing, 0.2),
           box_surface(Vec3::Zero(), Vec3(0.05, 0.03, 0.04), spacing / 2)},
          {"sphere", sample_sphere(Vec3::Zero(), 0.03, spacing), sphere_surface(Vec3::Zero(), 0.03, spacing / 2)},
          {"half-sphere", sample_half_sphere(Vec3::Zero(), 0.03, spacing),
           half_sphere_surface(Vec3::Zero(), 0.03, spacing / 2)}};
}

TEST(SurfaceMap, CarriesAffineAndRigidFieldsExactly) {
  for (const Case& c : cases()) {
    for (KernelType kernel : {KernelType::POLY6, KernelType::SPIKY, KernelType::VISCOSITY}) {
      const Model model = model_of(c.cloud, kernel);
      const SurfaceMap map = build_surface_map(model, c.surface.V);
      ASSERT_EQ(map.n_vertices(), c.surface.V.cols());
      for (index_t v = 0; v < map.n_vertices(); ++v) {
        double sum = 0;
        for (index_t e = map.points.begin(v); e < map.points.end(v); ++e) sum += map.weight[e];
        EXPECT_NEAR(sum, 1, 1e-10) << c.name << " vertex " << v;
      }
      Mat3 A;
      A << 0.01, -0.02, 0.005, 0.03, -0.01, 0.002, -0.004, 0.015, 0.02;
      const Vec3 b(0.001, -0.002, 0.0005), centre(0.02, 0.01, 0.0);
      const Mat3 R = test::random_rotation(5);  // a large rotation
      Points affine(3, model.n_points), rigid(3, model.n_points);
      for (index_t i = 0; i < model.n_points; ++i) {
        affine.col(i) = A * model.X.col(i) + b;
        rigid.col(i) = (R - Mat3::Identity()) * (model.X.col(i) - centre) + b;
      }
      Points y;
      carry_surface(map, c.surface.V, affine, y);
      double worst = 0;
      for (Eigen::Index v = 0; v < y.cols(); ++v)
        worst = std::max(worst, (y.col(v) - (c.surface.V.col(v) + A * c.surface.V.col(v) + b)).norm());
      EXPECT_LT(worst, 1e-12) << c.name << " affine";
      carry_surface(map, c.surface.V, rigid, y);
      worst = 0;
      for (Eigen::Index v = 0; v < y.cols(); ++v)
        worst = std::max(worst, (y.col(v) - (centre + R * (c.surface.V.col(v) - centre) + b)).norm());
      EXPECT_LT(worst, 1e-12) << c.name << " rigid";
    }
  }
}

TEST(SurfaceMap, WithoutNegativeWeightsIsANonNegativePartitionOfUnityThatCarriesTranslations) {
  for (const Case& c : cases()) {
    const Model model = model_of(c.cloud);
    const SurfaceMap linear = build_surface_map(model, c.surface.V);
    double most_negative = 0;
    for (const double w : linear.weight) most_negative = std::min(most_negative, w);
    // the surface lies beyond the outer points: the first-order map extrapolates to it with negative weights
    EXPECT_LT(most_negative, -0.01) << c.name;
    const SurfaceMap map = without_negative_weights(linear);
    ASSERT_EQ(map.points.index, linear.points.index) << c.name;
    for (index_t v = 0; v < map.n_vertices(); ++v) {
      double sum = 0;
      for (index_t e = map.points.begin(v); e < map.points.end(v); ++e) {
        EXPECT_GE(map.weight[e], 0.0) << c.name << " vertex " << v;
        sum += map.weight[e];
      }
      EXPECT_NEAR(sum, 1, 1e-12) << c.name << " vertex " << v;
    }
    const Vec3 b(0.001, -0.002, 0.0005);
    Points translation(3, model.n_points), y;
    translation.colwise() = b;
    carry_surface(map, c.surface.V, translation, y);
    EXPECT_LT((y - (c.surface.V.colwise() + b)).cwiseAbs().maxCoeff(), 1e-15) << c.name;
    // a force on a vertex pushes each of its points the same way (the first-order map pulled some back)
    Points on_vertex = Points::Zero(3, map.n_vertices()), on_points = Points::Zero(3, model.n_points);
    on_vertex.col(0) = Vec3(0, -1, 0);
    spread_surface_forces(map, on_vertex, on_points);
    EXPECT_LE(on_points.row(1).maxCoeff(), 0.0) << c.name;
    EXPECT_NEAR(on_points.row(1).sum(), -1.0, 1e-12) << c.name;
  }
}

TEST(SurfaceMap, SpreadsSurfaceForcesWithTheirVirtualWork) {
  // a potential on the deformed surface, V(y) = sum_v k |y_v - target_v|^2 / 2: its force on the points is
  // -dV/du = W^T (-k (y - target)); checked against central differences in u
  const Case c = cases()[2];
  const Model model = model_of(c.cloud);
  const SurfaceMap map = build_surface_map(model, c.surface.V);
  const Points target = c.surface.V + test::random_field(c.surface.V.cols(), 0.002, 8);
  const double k = 50;
  auto potential = [&](const Points& u) {
    Points y;
    carry_surface(map, c.surface.V, u, y);
    return 0.5 * k * (y - target).squaredNorm();
  };
  Points u = test::random_field(model.n_points, 0.001, 9), y;
  carry_surface(map, c.surface.V, u, y);
  Points f = Points::Zero(3, model.n_points);
  spread_surface_forces(map, -k * (y - target), f);
  Points f_fd(3, model.n_points);
  for (Eigen::Index e = 0; e < u.size(); ++e) {
    const double keep = u.data()[e], h = 1e-6;
    u.data()[e] = keep + h;
    const double plus = potential(u);
    u.data()[e] = keep - h;
    const double minus = potential(u);
    u.data()[e] = keep;
    f_fd.data()[e] = -(plus - minus) / (2 * h);
  }
  EXPECT_LT((f - f_fd).norm(), 1e-6 * f.norm());
  EXPECT_GT(f.norm(), 0);
}

TEST(SurfaceMap, WidensAFlatNeighbourhoodAndNamesAnUncarriedVertex) {
  const Case c = cases()[0];
  const Model model = model_of(c.cloud);
  Points far = c.surface.V.leftCols(3);
  far.col(1) += Vec3(0.0, 0.0, 0.5);  // 50 spacings away from the box: beyond its widest search (7.6 h)
  try {
    build_surface_map(model, far);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("surface vertex 1"), std::string::npos) << e.what();
  }
  // a vertex just outside a corner has few points within h: taken from a wider neighbourhood, still exact
  Points near(3, 1);
  near.col(0) = Vec3(-0.012, -0.012, -0.012);
  const SurfaceMap map = build_surface_map(model, near);
  EXPECT_EQ(map.widened, 1);
  Points u(3, model.n_points), y;
  for (index_t i = 0; i < model.n_points; ++i) u.col(i) = 0.01 * model.X.col(i);
  carry_surface(map, near, u, y);
  EXPECT_LT((y.col(0) - 1.01 * near.col(0)).norm(), 1e-12);
}

}  // namespace
}  // namespace pointhaptics
