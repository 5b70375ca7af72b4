#pragma once
/// @file The properties every hyperelastic model of mechanics/energies/ must have, as a typed test suite that
/// each model's test file instantiates (neo_hookean_test, mooney_rivlin_test, corotated_test): each stress is
/// its energy's gradient, each derivative the stress's, the projected tangent is positive semi-definite; rest
/// and rotations cost nothing; the small-strain moduli are young's and poisson's; inverted and flattened
/// neighbourhoods stay finite and are pushed back; the stiffening estimate of the explicit stable step covers
/// the tangent. One file per model keeps each under 20 s at -O3 (the three in one took 50 s).
#include "mechanics/energies/material_samples.hpp"

#include <gtest/gtest.h>

namespace pointhaptics::test {

template <class M>
class Hyperelastic : public ::testing::Test {};
TYPED_TEST_SUITE_P(Hyperelastic);

TYPED_TEST_P(Hyperelastic, StressIsTheEnergyGradient) {
  const TypeParam m = make<TypeParam>();
  std::mt19937 rng(1);
  for (const Mat3& G : sample_gradients(rng)) {
    const Mat3 P = m.stress(G);
    const Mat3 numeric = test::numeric_gradient([&](const Mat3& g) { return m.energy_density(g); }, G, 1e-6);
    ASSERT_LE((P - numeric).norm(), 1e-6 * P.norm() + 1e-4) << "G =\n" << G;
  }
}

TYPED_TEST_P(Hyperelastic, StressDerivativeIsTheStressGradient) {
  const TypeParam m = make<TypeParam>();
  std::mt19937 rng(2);
  for (const Mat3& G : sample_gradients(rng)) {
    const Mat3 dG = test::random_matrix(rng, 1.0);
    const Mat3 F = Mat3::Identity() + G;
    const Mat3 dP = m.stress_differential(F, dG);
    const Mat3 numeric = test::numeric_directional([&](const Mat3& g) { return m.stress(g); }, G, dG, 1e-6);
    ASSERT_LE((dP - numeric).norm(), 1e-6 * dP.norm() + 1e-3) << "G =\n" << G;
    // the linearisation applies the same derivative, and its blocks are its contraction with d
    const auto at = m.linearise(G, false);
    ASSERT_LE((m.stress_derivative(at, dG) - dP).norm(), 1e-10 * dP.norm());
    const Vec3 d = test::random_matrix(rng, 50.0).col(0);
    Mat3 expected;
    for (int b = 0; b < 3; ++b) expected.col(b) = m.stress_derivative(at, Vec3::Unit(b) * d.transpose()) * d;
    ASSERT_LE((m.stiffness_block(at, d) - expected).norm(), 1e-10 * expected.norm());
  }
}

TYPED_TEST_P(Hyperelastic, TheProjectedTangentIsPositiveAndExactWhereTheTangentIsPositive) {
  const TypeParam m = make<TypeParam>();
  std::mt19937 rng(3);
  for (const Mat3& G : sample_gradients(rng)) {
    const auto projected = m.linearise(G, true);
    Eigen::SelfAdjointEigenSolver<Mat9> eig(projected.H);
    ASSERT_GE(eig.eigenvalues()[0], -1e-9 * eig.eigenvalues().cwiseAbs().maxCoeff()) << "G =\n" << G;
  }
  // at rest the exact tangent is positive already, and the projection leaves it alone
  const auto exact = m.linearise(Mat3::Zero(), false), projected = m.linearise(Mat3::Zero(), true);
  EXPECT_LE((exact.H - projected.H).norm(), 1e-9 * exact.H.norm());
}

TYPED_TEST_P(Hyperelastic, RestAndRotationsCostNothingAndTheEnergyIsFrameIndifferent) {
  const TypeParam m = make<TypeParam>();
  const double scale = 1e5;
  EXPECT_NEAR(m.energy_density(Mat3::Zero()), 0.0, 1e-12 * scale);
  EXPECT_LE(m.stress(Mat3::Zero()).norm(), 1e-12 * scale);
  std::mt19937 rng(4);
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3 R = test::random_rotation(rng);
    EXPECT_NEAR(m.energy_density(R - Mat3::Identity()), 0.0, 1e-9 * scale);
    EXPECT_LE(m.stress(R - Mat3::Identity()).norm(), 1e-9 * scale);
    const Mat3 G = test::random_matrix(rng, 0.3);
    const Mat3 RG = R * (Mat3::Identity() + G) - Mat3::Identity();
    EXPECT_NEAR(m.energy_density(RG), m.energy_density(G), 1e-9 * m.energy_density(G));
    EXPECT_LE((m.stress(RG) - R * m.stress(G)).norm(), 1e-9 * m.stress(G).norm());
  }
}

TYPED_TEST_P(Hyperelastic, SmallStrainModuliAreYoungsAndPoissons) {
  // dP at rest is linear elasticity's lambda tr(dG) I + mu (dG + dG^T), with lambda and mu from E and nu
  const double young = 3e4, poisson = 0.45;
  const TypeParam m = make<TypeParam>(young, poisson);
  const MaterialParams p = params(MaterialModel::SVK, young, poisson);
  std::mt19937 rng(5);
  for (int trial = 0; trial < 10; ++trial) {
    const Mat3 dG = test::random_matrix(rng, 1.0);
    const Mat3 expected = p.lambda() * dG.trace() * Mat3::Identity() + p.mu() * (dG + dG.transpose());
    ASSERT_LE((m.stress_differential(Mat3::Identity(), dG) - expected).norm(), 1e-9 * expected.norm());
  }
}

TYPED_TEST_P(Hyperelastic, InvertedAndFlattenedNeighbourhoodsStayFiniteAndArePushedBack) {
  const TypeParam m = make<TypeParam>();
  std::mt19937 rng(6);
  std::vector<Mat3> bad = {Mat3(Vec3(-0.5, 1.0, 1.0).asDiagonal()), Mat3(Vec3(1.0, 1.0, 0.0).asDiagonal()),
                           Mat3(Vec3(0.3, -0.2, 0.8).asDiagonal()), Mat3(Vec3(1e-9, 1.0, 1.0).asDiagonal())};
  for (int k = 0; k < 10; ++k) {
    Mat3 F = test::random_rotation(rng) * Mat3(Vec3(-0.3, 0.9, 1.1).asDiagonal()) * test::random_rotation(rng);
    bad.push_back(F);
  }
  for (const Mat3& F : bad) {
    const Mat3 G = F - Mat3::Identity();
    const double W = m.energy_density(G);
    const Mat3 P = m.stress(G);
    ASSERT_TRUE(std::isfinite(W) && P.allFinite()) << "F =\n" << F;
    ASSERT_GT(W, 0.0);
    // moving F along cof F raises J (dJ = cof F : dF): the energy must fall that way
    const Mat3 cof = cofactor(F);
    if (cof.norm() > 0) {
      EXPECT_LT(contract(P, cof), 0.0) << "F =\n" << F;
    }
    ASSERT_TRUE(m.linearise(G, true).H.allFinite());
  }
}

TYPED_TEST_P(Hyperelastic, StiffeningIsOneAtRestAndCoversTheTangent) {
  const TypeParam m = make<TypeParam>();
  EXPECT_NEAR(m.stiffening(Mat3::Zero()), 1.0, 1e-12);
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  EXPECT_NEAR(m.stiffening(R - Mat3::Identity()), 1.0, 1e-9);
  // the explicit step covers a stiffening of 1.25 by its safety factor: the estimate may be below the true
  // ratio by that much, not more; stretches, compressions, shears up to |G| ~ 1.5
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    Mat3 G;
    for (int k = 0; k < 9; ++k) G(k % 3, k / 3) = uniform(rng) * (0.05 + trial / 150.0);
    if ((Mat3::Identity() + G).determinant() < 0.1) continue;
    ASSERT_LE(tangent_ratio(m, G), 1.25 * m.stiffening(G)) << "G =\n" << G;
  }
}

TYPED_TEST_P(Hyperelastic, FourPointStiffeningIsTheOnePointOne) {
  // the explicit step's check takes four points at a time (a vectorised form for neo-Hookean, point by
  // point for the others): every lane must equal the one-point form, including lanes past the floor of J
  // (the one-point form's extension), inverted or not finite ones, and lanes past `count` must be rest
  PointEnergy<TypeParam> energy;
  energy.material = make<TypeParam>();
  std::mt19937 rng(11);
  std::vector<Mat3> gradients = sample_gradients(rng);
  gradients.push_back(Mat3::Constant(std::numeric_limits<double>::quiet_NaN()));
  gradients.push_back(-0.99 * Mat3::Identity());  // J = 1e-6, below the floor
  ASSERT_GT(gradients.size(), 20u);
  for (std::size_t first = 0; first < gradients.size(); first += lane_count) {
    const int count = static_cast<int>(std::min<std::size_t>(lane_count, gradients.size() - first));
    Matrix3<Lanes> G{};
    for (int k = 0; k < count; ++k)
      for (int e = 0; e < 9; ++e) G.m[e][k] = gradients[first + k].data()[e];
    const Lanes s = energy.stiffening(0, count, G);
    for (int k = 0; k < count; ++k) {
      const double expected = energy.stiffening(0, gradients[first + k]);
      if (std::isnan(expected)) {
        EXPECT_TRUE(std::isnan(s[k]));
        continue;
      }
      ASSERT_NEAR(s[k], expected, 1e-12 * expected) << "G =\n" << gradients[first + k];
    }
    for (int k = count; k < lane_count; ++k) EXPECT_NEAR(s[k], 1.0, 1e-12);
  }
}

REGISTER_TYPED_TEST_SUITE_P(Hyperelastic, StressIsTheEnergyGradient, StressDerivativeIsTheStressGradient,
                            TheProjectedTangentIsPositiveAndExactWhereTheTangentIsPositive,
                            RestAndRotationsCostNothingAndTheEnergyIsFrameIndifferent,
                            SmallStrainModuliAreYoungsAndPoissons,
                            InvertedAndFlattenedNeighbourhoodsStayFiniteAndArePushedBack,
                            StiffeningIsOneAtRestAndCoversTheTangent, FourPointStiffeningIsTheOnePointOne);

}  // namespace pointhaptics::test
