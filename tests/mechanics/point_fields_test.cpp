// Tests for mechanics/point_fields: exact stress and energy density for a homogeneous stretch and shear.
#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/energies/svk.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>
#include <pointhaptics/mechanics/point_fields.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

TEST(PointFields, HomogeneousDeformationGivesTheAnalyticStressEverywhere) {
  MaterialParams material;
  material.young = 2e5;
  material.poisson = 0.3;
  const Model m = build_model(test::jittered_box(6, 5, 4, 0.01, 0.2), material, KernelParams{});
  Mat3 F;
  F << 1.05, 0.02, 0.0, 0.0, 0.98, 0.01, 0.0, 0.0, 1.01;  // stretch and shear
  const Points u = (F - Mat3::Identity()) * m.X;
  const PointFields f = point_fields(m, u);
  const Mat3 E = green_strain(F - Mat3::Identity());
  const Mat3 S = StVenantKirchhoff{m.lambda, m.mu}.second_piola(E);
  const Mat3 sigma = F * S * F.transpose() / F.determinant();
  const Mat3 dev = sigma - sigma.trace() / 3 * Mat3::Identity();
  for (index_t i = 0; i < m.n_points; ++i) {
    // MLS reproduces linear fields exactly, at the surface too
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> got(f.cauchy_stress.col(i).data());
    ASSERT_LE((got - sigma).norm(), 1e-8 * sigma.norm()) << "point " << i;
    EXPECT_NEAR(f.von_mises[i], std::sqrt(1.5 * (dev.array() * dev.array()).sum()), 1e-8 * sigma.norm());
    EXPECT_NEAR(f.energy_density[i], 0.5 * (S.array() * E.array()).sum(), 1e-8 * S.norm() * E.norm());
  }
  // at rest: nothing
  const PointFields rest = point_fields(m, Points::Zero(3, m.n_points));
  EXPECT_EQ(rest.cauchy_stress.norm(), 0.0);
  EXPECT_EQ(rest.energy_density.norm(), 0.0);
}

}  // namespace
}  // namespace pointhaptics
