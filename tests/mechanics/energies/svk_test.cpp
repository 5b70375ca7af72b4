// Tests for mechanics/energies/svk.hpp: St. Venant-Kirchhoff's stress is its energy's gradient, its stress
// derivative the stress's, its stiffness blocks the derivative's contraction; rest and rotations cost
// nothing; the stiffening bound the explicit stable step follows holds.
#include <pointhaptics/mechanics/energies/svk.hpp>

#include "support/finite_differences.hpp"

#include <gtest/gtest.h>

#include <Eigen/SVD>

namespace pointhaptics {
namespace {

const StVenantKirchhoff svk{2.0e5, 0.7e5};

TEST(Svk, StressIsTheEnergyGradient) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 50; ++trial) {
    const Mat3 G = test::random_matrix(rng, 0.4);
    const Mat3 P = svk.stress(G);
    const Mat3 numeric = test::numeric_gradient([](const Mat3& g) { return svk.energy_density(g); }, G);
    ASSERT_LE((P - numeric).norm(), 1e-6 * P.norm()) << "G =\n" << G;
  }
}

TEST(Svk, StressDerivativeIsTheStressGradientAndItsProjectionIsPositive) {
  std::mt19937 rng(2);
  for (int trial = 0; trial < 50; ++trial) {
    const Mat3 G = test::random_matrix(rng, 0.4), dG = test::random_matrix(rng, 1.0);
    const Mat3 dP = svk.stress_derivative(svk.linearise(G, false), dG);
    const Mat3 numeric = test::numeric_directional([](const Mat3& g) { return svk.stress(g); }, G, dG);
    ASSERT_LE((dP - numeric).norm(), 1e-6 * dP.norm()) << "G =\n" << G;
    // the projected derivative: dG : dP(dG) >= 0 for every dG, also under compression
    const Mat3 compressed = -0.3 * Mat3::Identity() + 0.1 * test::random_matrix(rng, 1.0);
    const auto projected = svk.linearise(compressed, true);
    ASSERT_GE((dG.array() * svk.stress_derivative(projected, dG).array()).sum(), -1e-9 * dG.squaredNorm() * svk.mu);
  }
}

TEST(Svk, StiffnessBlockIsTheDerivativeContractedWithTheStencilVector) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3 G = test::random_matrix(rng, 0.3);
    const Vec3 d = test::random_matrix(rng, 50.0).col(0);
    for (const bool projected : {false, true}) {
      const auto at = svk.linearise(G, projected);
      const Mat3 K = svk.stiffness_block(at, d);
      Mat3 expected;
      for (int b = 0; b < 3; ++b) expected.col(b) = svk.stress_derivative(at, Vec3::Unit(b) * d.transpose()) * d;
      ASSERT_LE((K - expected).norm(), 1e-10 * expected.norm());
    }
  }
}

TEST(Svk, RestAndRotationsCostNothingAndTheEnergyIsFrameIndifferent) {
  EXPECT_EQ(svk.energy_density(Mat3::Zero()), 0.0);
  EXPECT_EQ(svk.stress(Mat3::Zero()).norm(), 0.0);
  std::mt19937 rng(4);
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3 R = test::random_rotation(rng);
    EXPECT_NEAR(svk.energy_density(R - Mat3::Identity()), 0.0, 1e-9 * svk.mu);
    EXPECT_LE(svk.stress(R - Mat3::Identity()).norm(), 1e-9 * svk.mu);
    // W(R F) = W(F), P(R F) = R P(F)
    const Mat3 G = test::random_matrix(rng, 0.3);
    const Mat3 RG = R * (Mat3::Identity() + G) - Mat3::Identity();
    EXPECT_NEAR(svk.energy_density(RG), svk.energy_density(G), 1e-9 * svk.energy_density(G));
    EXPECT_LE((svk.stress(RG) - R * svk.stress(G)).norm(), 1e-9 * svk.stress(G).norm());
  }
}

// dP/dF (9 x 9, column-major vec) at F = I + G, by central differences
Eigen::Matrix<double, 9, 9> piola_derivative(const StVenantKirchhoff& m, const Mat3& G) {
  Eigen::Matrix<double, 9, 9> D;
  for (int k = 0; k < 9; ++k) {
    Mat3 dG = Mat3::Zero();
    dG(k % 3, k / 3) = 1;
    const Mat3 dP = test::numeric_directional([&m](const Mat3& g) { return m.stress(g); }, G, dG, 1e-6);
    D.col(k) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(dP.data());
  }
  return D;
}

double spectral_norm(const Eigen::Matrix<double, 9, 9>& D) {
  return Eigen::JacobiSVD<Eigen::Matrix<double, 9, 9>>(D).singularValues()[0];
}

TEST(SvkStiffening, IsOneAtRestAndUnderRotations) {
  EXPECT_DOUBLE_EQ(StVenantKirchhoff::stiffening(Mat3::Zero()), 1.0);
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  EXPECT_NEAR(StVenantKirchhoff::stiffening(R - Mat3::Identity()), 1.0, 1e-12);
}

TEST(SvkStiffening, IsTheUniaxialTangentInPureStretch) {
  // with lambda = 0 a pure stretch s along x is uniaxial: dP_xx/dF_xx = 2 mu (3 s^2 - 1) / 2
  for (const double s : {1.2, 1.5, 2.0, 3.0}) {
    Mat3 G = Mat3::Zero();
    G(0, 0) = s - 1;
    EXPECT_NEAR(StVenantKirchhoff::stiffening(G), (3 * s * s - 1) / 2, 1e-12) << "stretch " << s;
  }
}

TEST(SvkStiffening, BoundsTheTangentOverItsRestValue) {
  // the ratio of |dP/dF| at F to its rest value never exceeds the bound, for stretches, compressions,
  // shears and inversions up to |G| ~ 3, and the bound is not loose by more than a small factor
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const double rest = spectral_norm(piola_derivative(svk, Mat3::Zero()));
  double tightest = 0;
  for (int trial = 0; trial < 300; ++trial) {
    Mat3 G;
    for (int k = 0; k < 9; ++k) G(k % 3, k / 3) = uniform(rng) * (0.05 + trial / 100.0);
    const double ratio = spectral_norm(piola_derivative(svk, G)) / rest;
    const double bound = StVenantKirchhoff::stiffening(G);
    ASSERT_LE(ratio, bound * (1 + 1e-6)) << "G =\n" << G;
    tightest = std::max(tightest, ratio / bound);
  }
  EXPECT_GT(tightest, 0.4);
}

}  // namespace
}  // namespace pointhaptics
