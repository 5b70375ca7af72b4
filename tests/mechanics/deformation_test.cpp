// Tests for mechanics/deformation.hpp: the kinematics every material builds on.
#include <pointhaptics/mechanics/deformation.hpp>

#include "support/finite_differences.hpp"

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

TEST(Deformation, GreenStrainIsHalfOfFTransposeFMinusIdentityWithoutCancellation) {
  std::mt19937 rng(31);
  const Mat3 G = test::random_matrix(rng, 0.5);
  const Mat3 F = Mat3::Identity() + G;
  EXPECT_LE((green_strain(G) - 0.5 * (F.transpose() * F - Mat3::Identity())).norm(), 1e-14);
  // at |G| ~ 1e-9 forming F^T F - I keeps ~7 digits; written in G every digit survives
  const Mat3 tiny = 1e-9 * test::random_matrix(rng, 1.0);
  const Mat3 exact = 0.5 * (tiny + tiny.transpose()) + 0.5 * tiny.transpose() * tiny;
  const Mat3 F_tiny = Mat3::Identity() + tiny;
  const Mat3 naive = 0.5 * (F_tiny.transpose() * F_tiny - Mat3::Identity());
  EXPECT_LE((green_strain(tiny) - exact).norm(), 1e-15 * exact.norm());
  EXPECT_GT((naive - exact).norm(), 1e-12 * exact.norm());  // what the naive form loses
}

TEST(Deformation, CofactorIsDeterminantTimesInverseTranspose) {
  std::mt19937 rng(32);
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3 F = Mat3::Identity() + test::random_matrix(rng, 0.5);
    EXPECT_LE((cofactor(F) - F.determinant() * F.inverse().transpose()).norm(), 1e-12 * cofactor(F).norm());
  }
}

TEST(Deformation, PositivePartKeepsTheEigenvectorsAndDropsNegativeEigenvalues) {
  Mat3 S = Mat3::Zero();
  S.diagonal() << 2.0, -1.0, 0.5;
  const Mat3 R = Eigen::AngleAxisd(0.4, Vec3(1, 1, 0).normalized()).toRotationMatrix();
  Mat3 expected = Mat3::Zero();
  expected.diagonal() << 2.0, 0.0, 0.5;
  EXPECT_LE((positive_part(R * S * R.transpose()) - R * expected * R.transpose()).norm(), 1e-12);
}

}  // namespace
}  // namespace pointhaptics
