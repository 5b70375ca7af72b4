// Tests for mechanics/deformation: the stiffening bound of St. Venant-Kirchhoff that the explicit stable
// step follows.
#include <pointhaptics/mechanics/deformation.hpp>

#include <gtest/gtest.h>

#include <Eigen/SVD>

#include <random>

namespace pointhaptics {
namespace {

const double lambda = 2.0e5, mu = 0.7e5;

// dP/dF (9 x 9, column-major vec) of P = F S(E) at F = I + G, by central differences
Eigen::Matrix<double, 9, 9> piola_derivative(const Mat3& G) {
  const auto piola = [](const Mat3& Gx) { return Mat3((Mat3::Identity() + Gx) * svk_stress(green_strain(Gx), lambda, mu)); };
  Eigen::Matrix<double, 9, 9> D;
  const double h = 1e-6;
  for (int k = 0; k < 9; ++k) {
    Mat3 dG = Mat3::Zero();
    dG(k % 3, k / 3) = h;
    const Mat3 dP = (piola(G + dG) - piola(G - dG)) / (2 * h);
    D.col(k) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(dP.data());
  }
  return D;
}

double spectral_norm(const Eigen::Matrix<double, 9, 9>& D) {
  return Eigen::JacobiSVD<Eigen::Matrix<double, 9, 9>>(D).singularValues()[0];
}

TEST(SvkStiffening, IsOneAtRestAndUnderRotations) {
  EXPECT_DOUBLE_EQ(svk_stiffening(Mat3::Zero()), 1.0);
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  EXPECT_NEAR(svk_stiffening(R - Mat3::Identity()), 1.0, 1e-12);
}

TEST(SvkStiffening, IsTheUniaxialTangentInPureStretch) {
  // with lambda = 0 a pure stretch s along x is uniaxial: dP_xx/dF_xx = 2 mu (3 s^2 - 1) / 2
  for (const double s : {1.2, 1.5, 2.0, 3.0}) {
    Mat3 G = Mat3::Zero();
    G(0, 0) = s - 1;
    EXPECT_NEAR(svk_stiffening(G), (3 * s * s - 1) / 2, 1e-12) << "stretch " << s;
  }
}

TEST(SvkStiffening, BoundsTheTangentOverItsRestValue) {
  // the ratio of |dP/dF| at F to its rest value never exceeds the bound, for stretches, compressions,
  // shears and inversions up to |G| ~ 3, and the bound is not loose by more than a small factor
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const double rest = spectral_norm(piola_derivative(Mat3::Zero()));
  double tightest = 0;
  for (int trial = 0; trial < 300; ++trial) {
    Mat3 G;
    for (int k = 0; k < 9; ++k) G(k % 3, k / 3) = uniform(rng) * (0.05 + trial / 100.0);
    const double ratio = spectral_norm(piola_derivative(G)) / rest;
    const double bound = svk_stiffening(G);
    ASSERT_LE(ratio, bound * (1 + 1e-6)) << "G =\n" << G;
    tightest = std::max(tightest, ratio / bound);
  }
  EXPECT_GT(tightest, 0.4);
}

}  // namespace
}  // namespace pointhaptics
