// Tests for the registry that mixes the materials of mechanics/energies/ (material.hpp): under compression the
// hyperelastic models stiffen where St Venant-Kirchhoff collapses, and a mixed object dispatches each point to
// its own material. Each model's own properties are tested in its file (neo_hookean_test.cpp, ...).
#include <pointhaptics/mechanics/energies/material.hpp>

#include "mechanics/energies/material_samples.hpp"

#include <gtest/gtest.h>

namespace pointhaptics::test {
namespace {

TEST(Materials, UniaxialCompressionStiffensNeoHookeanWhereStVenantKirchhoffCollapses) {
  // the nominal stress of a uniaxial compression (lateral faces free: the lateral stretch relaxes to zero
  // lateral stress) of SVK turns back towards zero beyond a stretch of ~0.58 (1/sqrt(3) with nu = 0): the
  // collapse of issue 17; neo-Hookean's keeps growing
  auto axial = [](const auto& m, double s) {
    double lateral = 1.0, lo = 1.0, hi = 3.0;  // compressed along x, the lateral stretch is >= 1
    for (int b = 0; b < 80; ++b) {             // bisection for zero lateral stress
      lateral = 0.5 * (lo + hi);
      const Mat3 G = Vec3(s - 1, lateral - 1, lateral - 1).asDiagonal();
      (m.stress(G)(1, 1) > 0 ? hi : lo) = lateral;
    }
    return m.stress(Mat3(Vec3(s - 1, lateral - 1, lateral - 1).asDiagonal()))(0, 0);
  };
  const MaterialParams p = params(MaterialModel::SVK, 1e4, 0.3);
  const StVenantKirchhoff svk{p.lambda(), p.mu()};
  const NeoHookean nh{p.mu(), p.bulk_modulus()};
  double previous_nh = 0;
  for (double s = 0.95; s > 0.2; s -= 0.05) {
    const double now = axial(nh, s);
    EXPECT_LT(now, previous_nh) << "stretch " << s;  // more compressive at every stretch
    previous_nh = now;
  }
  EXPECT_GT(axial(svk, 0.3), axial(svk, 0.6));  // SVK's compressive stress falls off
}

TEST(MixedEnergy, DispatchesEachPointToItsOwnMaterial) {
  Model model;
  model.material = params(MaterialModel::SVK);
  model.point_materials = {model.material, params(MaterialModel::NEO_HOOKEAN, 1e6),
                           params(MaterialModel::COROTATED, 3e5)};
  model.material_of = {0, 1, 2, 1};
  std::mt19937 rng(10);
  const Mat3 G = test::random_matrix(rng, 0.2), dG = test::random_matrix(rng, 1.0);
  with_material(model, [&](const auto& energy) {
    for (index_t i = 0; i < 4; ++i) {
      const AnyMaterial own = material_constants(model.point_materials[model.material_of[i]]);
      std::visit(
          [&](const auto& m) {
            EXPECT_LE((energy.stress(i, G) - m.stress(G)).norm(), 1e-12 * m.stress(G).norm()) << "point " << i;
            EXPECT_NEAR(energy.energy_density(i, G), m.energy_density(G), 1e-12 * m.energy_density(G));
            const Mat3 expected = test::numeric_directional([&](const Mat3& g) { return m.stress(g); }, G, dG);
            const auto at = energy.linearise(i, G, false);
            EXPECT_LE((energy.stress_derivative(i, at, dG, false) - expected).norm(), 1e-6 * expected.norm());
          },
          own);
    }
  });
}

}  // namespace
}  // namespace pointhaptics::test
