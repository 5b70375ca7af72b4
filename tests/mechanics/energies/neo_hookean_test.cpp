// Tests for mechanics/energies/neo_hookean.hpp: the hyperelastic properties (hyperelastic_properties.hpp), and
// the energy is CalculiX's neo-Hooke.
#include <pointhaptics/mechanics/energies/neo_hookean.hpp>

#include "mechanics/energies/hyperelastic_properties.hpp"

#include <gtest/gtest.h>

namespace pointhaptics::test {
namespace {

INSTANTIATE_TYPED_TEST_SUITE_P(NeoHookean, Hyperelastic, ::testing::Types<NeoHookean>);

TEST(NeoHookean, IsCalculixNeoHookeForPositiveJ) {
  // W = C10 (J^-2/3 I1 - 3) + (J - 1)^2 / D1, C10 = mu / 2, D1 = 2 / K
  const NeoHookean m = make<NeoHookean>(2e4, 0.45);
  const double c10 = m.mu / 2, d1 = 2 / m.bulk;
  std::mt19937 rng(8);
  for (const Mat3& G : sample_gradients(rng)) {
    const Mat3 F = Mat3::Identity() + G;
    const double J = F.determinant();
    if (J < PowerOfJ::j_floor) continue;
    const double expected = c10 * (std::pow(J, -2.0 / 3.0) * F.squaredNorm() - 3) + (J - 1) * (J - 1) / d1;
    ASSERT_NEAR(m.energy_density(G), expected, 1e-9 * std::abs(expected) + 1e-9);
  }
}

}  // namespace
}  // namespace pointhaptics::test
