// Tests for mechanics/energies/volume_penalty.hpp: the stress is the energy's gradient, the exact stress
// derivative the stress's, the Gauss-Newton part positive, the stiffness blocks the derivative's
// contraction; rest and rotations cost nothing.
#include <pointhaptics/mechanics/energies/volume_penalty.hpp>

#include "support/finite_differences.hpp"

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

const VolumePenalty volume{3.0e5};

TEST(VolumePenalty, StressIsTheEnergyGradient) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    const Mat3 G = test::random_matrix(rng, 0.4);
    const Mat3 P = volume.stress(G);
    const Mat3 numeric = test::numeric_gradient([](const Mat3& g) { return volume.energy_density(g); }, G);
    ASSERT_LE((P - numeric).norm(), 1e-6 * P.norm() + 1e-9) << "G =\n" << G;
  }
}

TEST(VolumePenalty, StressDerivativeIsTheStressGradientAndItsGaussNewtonPartIsPositive) {
  std::mt19937 rng(12);
  for (int trial = 0; trial < 50; ++trial) {
    const Mat3 G = test::random_matrix(rng, 0.4), dG = test::random_matrix(rng, 1.0);
    const Mat3 F = Mat3::Identity() + G;
    const Mat3 dP = volume.stress_derivative(F, dG, true);
    const Mat3 numeric = test::numeric_directional([](const Mat3& g) { return volume.stress(g); }, G, dG);
    ASSERT_LE((dP - numeric).norm(), 1e-6 * dP.norm() + 1e-9) << "G =\n" << G;
    ASSERT_GE((dG.array() * volume.stress_derivative(F, dG, false).array()).sum(), -1e-9 * volume.stiffness);
  }
}

TEST(VolumePenalty, StiffnessBlockIsTheDerivativeContractedWithTheStencilVector) {
  std::mt19937 rng(13);
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3 F = Mat3::Identity() + test::random_matrix(rng, 0.3);
    const Vec3 d = test::random_matrix(rng, 50.0).col(0);
    for (const bool exact : {true, false}) {
      Mat3 expected;
      for (int b = 0; b < 3; ++b)
        expected.col(b) = volume.stress_derivative(F, Vec3::Unit(b) * d.transpose(), exact) * d;
      ASSERT_LE((volume.stiffness_block(F, d) - expected).norm(), 1e-10 * expected.norm());
    }
  }
}

TEST(VolumePenalty, RestAndRotationsCostNothing) {
  std::mt19937 rng(14);
  EXPECT_EQ(volume.energy_density(Mat3::Zero()), 0.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3 G = test::random_rotation(rng) - Mat3::Identity();
    EXPECT_NEAR(volume.energy_density(G), 0.0, 1e-12 * volume.stiffness);
    EXPECT_LE(volume.stress(G).norm(), 1e-9 * volume.stiffness);
  }
  // a uniform compression to J = 0.9: 0.5 k (0.1)^2
  const double s = std::cbrt(0.9);
  EXPECT_NEAR(volume.energy_density((s - 1) * Mat3::Identity()), 0.5 * volume.stiffness * 0.01,
              1e-9 * volume.stiffness);
}

}  // namespace
}  // namespace pointhaptics
