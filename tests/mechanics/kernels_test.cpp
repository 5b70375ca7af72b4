// Tests for mechanics/kernels: the seed's Eq. 3-6.
#include <pointhaptics/mechanics/kernels.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace pointhaptics {
namespace {

class KernelTest : public ::testing::TestWithParam<KernelType> {};

TEST_P(KernelTest, IntegratesToOneOverTheBall) {
  for (double h : {0.01, 0.1, 1.0}) {
    // midpoint rule in r of 4 pi r^2 w(r); the viscosity kernel's 1/r singularity is integrable
    const int n = 200000;
    double sum = 0;
    for (int k = 0; k < n; ++k) {
      const double r = (k + 0.5) * h / n;
      sum += 4 * std::numbers::pi * r * r * kernel_value(GetParam(), r, h) * h / n;
    }
    EXPECT_NEAR(sum, 1.0, 1e-6) << "h = " << h;
  }
}

TEST_P(KernelTest, PositiveNonIncreasingAndZeroFromH) {
  const double h = 0.02;
  double previous = std::numeric_limits<double>::infinity();
  for (int k = 1; k < 1000; ++k) {
    const double r = k * h / 1000;
    const double w = kernel_value(GetParam(), r, h);
    EXPECT_GT(w, 0) << "r = " << r;
    EXPECT_LE(w, previous * (1 + 1e-12)) << "r = " << r;
    previous = w;
  }
  EXPECT_EQ(kernel_value(GetParam(), h, h), 0.0);
  EXPECT_EQ(kernel_value(GetParam(), 1.5 * h, h), 0.0);
  EXPECT_EQ(kernel_derivative(GetParam(), 1.5 * h, h), 0.0);
}

TEST_P(KernelTest, DerivativeMatchesFiniteDifferences) {
  const double h = 0.05;
  for (double q : {0.1, 0.3, 0.49, 0.51, 0.7, 0.95}) {
    const double r = q * h, eps = 1e-7 * h;
    const double fd = (kernel_value(GetParam(), r + eps, h) - kernel_value(GetParam(), r - eps, h)) / (2 * eps);
    EXPECT_NEAR(kernel_derivative(GetParam(), r, h), fd, 1e-6 * std::abs(fd) + 1e-9) << "q = " << q;
  }
}

INSTANTIATE_TEST_SUITE_P(SeedKernels, KernelTest,
                         ::testing::Values(KernelType::POLY6, KernelType::SPIKY, KernelType::VISCOSITY,
                                           KernelType::QUADRATIC),
                         [](const auto& info) { return std::string(to_string(info.param)); });

TEST(Kernels, QuadraticBranchesMeetAtHalfSupport) {
  const double h = 0.3;
  EXPECT_NEAR(kernel_value(KernelType::QUADRATIC, 0.5 * h * (1 - 1e-12), h),
              kernel_value(KernelType::QUADRATIC, 0.5 * h * (1 + 1e-12), h), 1e-9);
}

TEST(Kernels, Poly6MatchesTheSeedsFormula) {
  const double h = 0.1, r = 0.04;
  const double expected = 315.0 / (64.0 * std::numbers::pi * std::pow(h, 9)) * std::pow(h * h - r * r, 3);
  EXPECT_DOUBLE_EQ(kernel_value(KernelType::POLY6, r, h), expected);
}

}  // namespace
}  // namespace pointhaptics
