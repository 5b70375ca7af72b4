// Tests for mechanics/energies/mooney_rivlin.hpp: the hyperelastic properties (hyperelastic_properties.hpp), and
// the energy is CalculiX's Mooney-Rivlin, the neo-Hookean one without c01.
#include <pointhaptics/mechanics/energies/mooney_rivlin.hpp>

#include "mechanics/energies/hyperelastic_properties.hpp"

#include <gtest/gtest.h>

namespace pointhaptics::test {
namespace {

INSTANTIATE_TYPED_TEST_SUITE_P(MooneyRivlin, Hyperelastic, ::testing::Types<MooneyRivlin>);

TEST(MooneyRivlin, IsCalculixMooneyRivlinAndNeoHookeanWithoutC01) {
  const MooneyRivlin m = make<MooneyRivlin>(2e4, 0.45);
  EXPECT_NEAR(m.mu(), params(MaterialModel::SVK, 2e4, 0.45).mu(), 1e-9);
  EXPECT_NEAR(m.c10 / m.c01, 0.7 / 0.3, 1e-12);
  std::mt19937 rng(9);
  for (const Mat3& G : sample_gradients(rng)) {
    const Mat3 F = Mat3::Identity() + G, C = F.transpose() * F;
    const double J = F.determinant();
    if (J < PowerOfJ::j_floor) continue;
    const double i1 = C.trace(), i2 = 0.5 * (i1 * i1 - (C * C).trace());
    const double expected = m.c10 * (std::pow(J, -2.0 / 3.0) * i1 - 3) + m.c01 * (std::pow(J, -4.0 / 3.0) * i2 - 3) +
                            0.5 * m.bulk * (J - 1) * (J - 1);
    ASSERT_NEAR(m.energy_density(G), expected, 1e-9 * std::abs(expected) + 1e-9);
  }
  // C01 = 0 is neo-Hookean
  const MooneyRivlin nh_like{m.mu() / 2, 0.0, m.bulk};
  const NeoHookean nh{m.mu(), m.bulk};
  const Mat3 G = test::random_matrix(rng, 0.3);
  EXPECT_LE((nh_like.stress(G) - nh.stress(G)).norm(), 1e-9 * nh.stress(G).norm());
}

}  // namespace
}  // namespace pointhaptics::test
