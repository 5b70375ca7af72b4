// Tests for the four-point stresses of mechanics/energies/lanes.hpp: J^-1/3 to a few ulps over any J; each
// model's stress of four points at once equals each point's own (one-point form) in every regime, including
// the lanes the four-point form hands back (J below the floor, inverted, not finite), partial groups, the
// added terms, and objects that mix models.
#include <pointhaptics/mechanics/energies/material.hpp>

#include "support/finite_differences.hpp"

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <limits>

namespace pointhaptics {
namespace {

Matrix3<Lanes> lanes_of(const std::array<Mat3, 4>& G) {
  Matrix3<Lanes> out{};
  for (int k = 0; k < lane_count; ++k)
    for (int e = 0; e < 9; ++e) out.m[e][k] = G[k].data()[e];
  return out;
}
Mat3 lane(const Matrix3<Lanes>& A, int k) {
  Mat3 out;
  for (int e = 0; e < 9; ++e) out.data()[e] = A.m[e][k];
  return out;
}

TEST(InverseCubeRoot, IsWithinAFewUlpsOfTheLibraryCubeRootForAnyPositiveJ) {
  double worst = 0;
  for (double J = 1e-6; J < 1e6; J *= 1.0137) {
    const Lanes J4 = {J, J * 1.001, 0.5 + std::fmod(J, 1.5), 1 + 1e-9 * J};  // the polynomial's range and beyond
    const Lanes y = inverse_cube_root(J4);
    for (int k = 0; k < lane_count; ++k) worst = std::max(worst, std::abs(y[k] * std::cbrt(J4[k]) - 1));
  }
  EXPECT_LT(worst, 1e-15);
}

/// Groups of four gradients over every regime: near rest, large stretch and shear, deep compression, J below
/// PowerOfJ::j_floor, inverted, and one not finite.
std::vector<std::array<Mat3, 4>> regimes() {
  std::mt19937 rng(31);
  std::vector<std::array<Mat3, 4>> groups;
  for (double scale : {1e-6, 0.05, 0.4}) {
    std::array<Mat3, 4> g;
    for (Mat3& G : g) G = test::random_matrix(rng, scale);
    groups.push_back(g);
  }
  std::array<Mat3, 4> compressed;
  for (Mat3& G : compressed) G = -0.45 * Mat3::Identity() + test::random_matrix(rng, 0.1);
  groups.push_back(compressed);
  // one lane of each kind the four-point form hands back, among ordinary ones
  std::array<Mat3, 4> mixed = {test::random_matrix(rng, 0.1), test::random_matrix(rng, 0.02),
                               test::random_matrix(rng, 0.1), test::random_matrix(rng, 0.2)};
  mixed[1](1, 1) -= 0.97;  // J ~ 0.03, below the floor
  groups.push_back(mixed);
  std::array<Mat3, 4> inverted = mixed;
  inverted[2] = -2 * Mat3::Identity() + test::random_matrix(rng, 0.1);  // det F < 0
  groups.push_back(inverted);
  std::array<Mat3, 4> stretched = mixed;
  stretched[3] = 2.5 * Mat3::Identity() + test::random_matrix(rng, 0.1);  // J ~ 40: the cube root's start lane by lane
  groups.push_back(stretched);
  return groups;
}

MaterialParams params(MaterialModel model) {
  MaterialParams p;
  p.model = model;
  p.young = 2e5;
  p.poisson = 0.45;
  p.c10 = 0.6, p.c01 = 0.4;
  return p;
}

/// Every lane of energy.scaled_stress(i, count, G, scale) against energy.scaled_stress(i + k, G_k, scale_k).
template <class Energy>
void expect_lanes_equal_points(const Energy& energy, const std::array<Mat3, 4>& group, int count,
                               const std::string& what) {
  const Lanes scale = {1.5e-6, 0.7e-6, 2.1e-6, 1e-6};
  const Matrix3<Lanes> P = energy.scaled_stress(0, count, lanes_of(group), scale);
  for (int k = 0; k < count; ++k) {
    const Mat3 expected = energy.scaled_stress(k, group[k], scale[k]);
    const Mat3 got = lane(P, k);
    EXPECT_LE((got - expected).norm(), 1e-13 * expected.norm() + 1e-300) << what << ", lane " << k << " of " << count;
  }
}

TEST(FourPointStress, EqualsEachPointsOwnForEveryModelAndRegime) {
  for (MaterialModel model_kind :
       {MaterialModel::SVK, MaterialModel::NEO_HOOKEAN, MaterialModel::MOONEY_RIVLIN, MaterialModel::COROTATED}) {
    for (double volume_stiffness : {0.0, 3e5}) {
      Model model;
      model.material = params(model_kind);
      model.material.volume_stiffness = volume_stiffness;
      with_material(model, [&](const auto& energy) {
        int g = 0;
        for (const auto& group : regimes())
          for (int count : {4, 3, 1})
            expect_lanes_equal_points(
                energy, group, count,
                fmt::format("{} (volume {}) group {}", to_string(model_kind), volume_stiffness, g++));
      });
    }
  }
}

TEST(FourPointStress, NotFiniteLanesStayNotFiniteAndLeaveTheOthersAlone) {
  std::mt19937 rng(5);
  std::array<Mat3, 4> group = {test::random_matrix(rng, 0.1), test::random_matrix(rng, 0.1),
                               test::random_matrix(rng, 0.1), test::random_matrix(rng, 0.1)};
  group[2](0, 1) = std::numeric_limits<double>::quiet_NaN();
  for (MaterialModel model_kind :
       {MaterialModel::SVK, MaterialModel::NEO_HOOKEAN, MaterialModel::MOONEY_RIVLIN, MaterialModel::COROTATED}) {
    Model model;
    model.material = params(model_kind);
    with_material(model, [&](const auto& energy) {
      const Matrix3<Lanes> P = energy.scaled_stress(0, 4, lanes_of(group), Lanes{} + 1.0);
      for (int k : {0, 1, 3})
        EXPECT_LE((lane(P, k) - energy.stress(k, group[k])).norm(), 1e-13 * lane(P, k).norm()) << to_string(model_kind);
      EXPECT_FALSE(lane(P, 2).allFinite()) << to_string(model_kind);
    });
  }
}

TEST(FourPointStress, MixedObjectsDispatchEachGroupOrEachPoint) {
  Model model;
  model.material = params(MaterialModel::SVK);
  model.point_materials = {model.material, params(MaterialModel::NEO_HOOKEAN), params(MaterialModel::COROTATED),
                           params(MaterialModel::MOONEY_RIVLIN)};
  for (const std::vector<std::uint8_t>& material_of :
       {std::vector<std::uint8_t>{1, 1, 1, 1}, std::vector<std::uint8_t>{3, 3, 3, 3},
        std::vector<std::uint8_t>{0, 1, 2, 3}, std::vector<std::uint8_t>{2, 2, 0, 2}}) {
    model.material_of = material_of;
    with_material(model, [&](const auto& energy) {
      for (const auto& group : regimes())
        for (int count : {4, 2})
          expect_lanes_equal_points(energy, group, count, fmt::format("materials {}", fmt::join(material_of, ",")));
    });
  }
}

}  // namespace
}  // namespace pointhaptics
