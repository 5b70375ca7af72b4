#pragma once
/// @file Material constants and deformation gradients for the tests of mechanics/energies/ (materials_test,
/// neo_hookean_test, mooney_rivlin_test, corotated_test).
#include <pointhaptics/mechanics/energies/material.hpp>

#include "support/finite_differences.hpp"

#include <Eigen/SVD>

#include <random>
#include <vector>

namespace pointhaptics::test {

inline MaterialParams params(MaterialModel model, double young = 1e5, double poisson = 0.4) {
  MaterialParams p;
  p.model = model;
  p.young = young;
  p.poisson = poisson;
  return p;
}

template <class M>
M make(double young = 1e5, double poisson = 0.4);
template <>
inline NeoHookean make<NeoHookean>(double young, double poisson) {
  return std::get<NeoHookean>(material_constants(params(MaterialModel::NEO_HOOKEAN, young, poisson)));
}
template <>
inline MooneyRivlin make<MooneyRivlin>(double young, double poisson) {
  MaterialParams p = params(MaterialModel::MOONEY_RIVLIN, young, poisson);
  p.c10 = 0.7, p.c01 = 0.3;  // a 70 : 30 split of the shear modulus
  return std::get<MooneyRivlin>(material_constants(p));
}
template <>
inline Corotated make<Corotated>(double young, double poisson) {
  return std::get<Corotated>(material_constants(params(MaterialModel::COROTATED, young, poisson)));
}

inline double contract(const Mat3& a, const Mat3& b) { return (a.array() * b.array()).sum(); }

/// Deformation gradients over the regimes the tests cover: near rest, large stretch and shear, deep
/// compression (J down to ~0.1), and below PowerOfJ::j_floor.
inline std::vector<Mat3> sample_gradients(std::mt19937& rng) {
  std::vector<Mat3> out;
  for (int k = 0; k < 20; ++k) out.push_back(test::random_matrix(rng, 0.4));
  for (int k = 0; k < 10; ++k) out.push_back(-0.45 * Mat3::Identity() + test::random_matrix(rng, 0.1));
  for (int k = 0; k < 5; ++k) {
    Mat3 G = test::random_matrix(rng, 0.02);
    G(1, 1) -= 0.97;  // J ~ 0.03, below the floor
    out.push_back(G);
  }
  return out;
}

// dP/dF spectral norm at G, over the rest value
template <class M>
double tangent_ratio(const M& m, const Mat3& G) {
  auto norm = [&](const Mat3& g) { return Eigen::JacobiSVD<Mat9>(m.linearise(g, false).H).singularValues()[0]; };
  return norm(G) / norm(Mat3::Zero());
}

}  // namespace pointhaptics::test
