// Tests for per-point kernel supports (used by levels of detail): symmetric neighbourhoods by the
// max(h_i, h_j) rule, the same model as a uniform support when all are equal, and the mechanics still
// exact (forces = -grad W, tangent = finite differences of the forces, affine patch test).
#include <pointhaptics/geometry/neighbour_search.hpp>
#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/mechanics/tangent.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

#include <random>

namespace pointhaptics {
namespace {

const double s = 0.01;

PointCloud varied_cloud(unsigned seed = 5) {
  PointCloud cloud = test::jittered_box(6, 5, 5, s, 0.15, seed);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> factor(2.0, 3.2);
  cloud.support.resize(cloud.size());
  for (index_t i = 0; i < cloud.size(); ++i) cloud.support[i] = factor(rng) * s;
  return cloud;
}

TEST(VariableSupport, NeighbourhoodsFollowTheMaxRuleAndAreSymmetric) {
  const PointCloud cloud = varied_cloud();
  const Csr nbr = radius_neighbours(cloud.X, cloud.support);
  for (index_t i = 0; i < cloud.size(); ++i)
    for (index_t j = 0; j < cloud.size(); ++j) {
      if (i == j) continue;
      const bool expected =
          within_support((cloud.X.col(j) - cloud.X.col(i)).squaredNorm(), std::max(cloud.support[i], cloud.support[j]));
      const bool found = std::binary_search(nbr.index.begin() + nbr.begin(i), nbr.index.begin() + nbr.end(i), j);
      ASSERT_EQ(found, expected) << i << " " << j;
    }
}

TEST(VariableSupport, EqualSupportsGiveTheUniformModel) {
  PointCloud cloud = test::jittered_box(6, 5, 5, s, 0.15);
  const Model uniform = build_model(cloud, MaterialParams{}, KernelParams{});
  cloud.support = Eigen::VectorXd::Constant(cloud.size(), uniform.h);
  const Model per_point = build_model(cloud, MaterialParams{}, KernelParams{});
  ASSERT_EQ(uniform.neighbours.index, per_point.neighbours.index);
  EXPECT_LE((uniform.d - per_point.d).norm(), 1e-12 * uniform.d.norm());
  EXPECT_LE((uniform.hg_coef - per_point.hg_coef).norm(), 1e-12 * uniform.hg_coef.norm());
}

TEST(VariableSupport, ForcesAndTangentStayExactAndAffineFieldsAreReproduced) {
  const Model model = build_model(varied_cloud(), MaterialParams{}, KernelParams{});
  Points u = test::random_field(model.n_points, 0.05 * s, 9);
  Workspace ws(model, 1);
  compute_internal_forces(model, u, ws);
  const Points f = ws.f_int;
  // forces against central differences of the energy, on a few components
  const double eps = 1e-7 * s;
  double worst = 0;
  for (Eigen::Index k = 0; k < u.size(); k += 7) {
    const double keep = u.data()[k];
    u.data()[k] = keep + eps;
    const double plus = strain_energy(model, u).total();
    u.data()[k] = keep - eps;
    const double minus = strain_energy(model, u).total();
    u.data()[k] = keep;
    worst = std::max(worst, std::abs(-(plus - minus) / (2 * eps) - f.data()[k]));
  }
  EXPECT_LE(worst, 1e-6 * f.cwiseAbs().maxCoeff());
  // the tangent against central differences of the forces
  Tangent K;
  K.linearise(model, u, TangentMode::EXACT);
  const Points du = test::random_field(model.n_points, s, 10);
  Points Kdu(3, model.n_points);
  K.apply(model, du, ws, Kdu);
  compute_internal_forces(model, u + 1e-6 * du, ws);
  const Points fp = ws.f_int;
  compute_internal_forces(model, u - 1e-6 * du, ws);
  EXPECT_LE((Kdu - (ws.f_int - fp) / 2e-6).norm(), 1e-6 * Kdu.norm());
  // first-order consistency: an affine field has its exact gradient everywhere
  Mat3 A;
  A << 0.01, -0.02, 0.005, 0.003, 0.015, -0.01, 0.002, 0.0, -0.012;
  const Points affine = A * model.X;
  for (index_t i = 0; i < model.n_points; ++i)
    ASSERT_LE((displacement_gradient(model, affine, i) - A).norm(), 1e-10) << "point " << i;
}

}  // namespace
}  // namespace pointhaptics
