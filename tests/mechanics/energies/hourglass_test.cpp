// Tests for mechanics/energies/hourglass.hpp: a pair's force is the gradient of its energy, the generic pair
// force is the same on Eigen's vectors as the formula, and the model's precomputed Hessian diagonal is the
// second difference of the hourglass energy.
#include <pointhaptics/mechanics/energies/hourglass.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>

#include "support/finite_differences.hpp"
#include "support/test_models.hpp"

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

TEST(Hourglass, PairForceIsTheGradientOfThePairEnergy) {
  std::mt19937 rng(21);
  for (int trial = 0; trial < 20; ++trial) {
    const double k = 1e3 * (1 + trial);
    const Mat3 G_sum = test::random_matrix(rng, 0.2);
    const Vec3 x = test::random_matrix(rng, 0.01).col(0), du = test::random_matrix(rng, 1e-3).col(1);
    // d/d(du) of (k/2)|r|^2 with G held: k r, which the loop adds to u_i and takes from u_j
    Vec3 numeric;
    const double h = 1e-7;
    for (int a = 0; a < 3; ++a) {
      const Vec3 e = h * Vec3::Unit(a);
      numeric[a] = (hourglass_pair_energy(k, du + e, G_sum, x) - hourglass_pair_energy(k, du - e, G_sum, x)) / (2 * h);
    }
    const Vec3 force =
        hourglass_pair_force(k, du, Vec3(G_sum.col(0)), Vec3(G_sum.col(1)), Vec3(G_sum.col(2)), x[0], x[1], x[2]);
    ASSERT_LE((force - numeric).norm(), 1e-6 * force.norm());
    ASSERT_LE((force - k * hourglass_residual(du, G_sum, x)).norm(), 1e-12 * force.norm());
  }
}

TEST(Hourglass, ZeroForFieldsTheStencilsReproduce) {
  // r vanishes for a linear field: both gradients are exact
  const Mat3 A = Mat3::Identity() * 0.01 + Mat3::Constant(0.002);
  const Vec3 x(0.003, -0.001, 0.002);
  EXPECT_NEAR(hourglass_residual(A * x, 2 * A, x).norm(), 0.0, 1e-18);
}

TEST(Hourglass, PrecomputedDiagonalIsTheSecondDifferenceOfTheEnergy) {
  MaterialParams material;
  material.young = 1e5;
  material.hourglass = 0.5;
  const Model model = build_model(test::jittered_box(5, 4, 4, 0.01, 0.2), material, KernelParams{});
  ASSERT_GT(model.hg_diagonal.size(), 0);
  // the hourglass energy is quadratic in u: W(h e) + W(-h e) = h^2 diag exactly (up to round-off)
  const double h = 1e-4;
  for (const index_t m : {0, 7, 23, 41, model.n_points - 1})
    for (int a = 0; a < 3; ++a) {
      Points u = Points::Zero(3, model.n_points);
      u(a, m) = h;
      const double plus = strain_energy(model, u).hourglass;
      u(a, m) = -h;
      const double minus = strain_energy(model, u).hourglass;
      EXPECT_NEAR((plus + minus) / (h * h), model.hg_diagonal[m], 1e-9 * model.hg_diagonal[m])
          << "point " << m << " axis " << a;
    }
}

}  // namespace
}  // namespace pointhaptics
