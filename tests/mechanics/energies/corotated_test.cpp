// Tests for mechanics/energies/corotated.hpp: the hyperelastic properties (hyperelastic_properties.hpp).
#include <pointhaptics/mechanics/energies/corotated.hpp>

#include "mechanics/energies/hyperelastic_properties.hpp"

#include <gtest/gtest.h>

namespace pointhaptics::test {
namespace {

INSTANTIATE_TYPED_TEST_SUITE_P(Corotated, Hyperelastic, ::testing::Types<Corotated>);

}  // namespace
}  // namespace pointhaptics::test
