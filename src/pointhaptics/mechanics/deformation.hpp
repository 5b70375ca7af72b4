#pragma once
/// @file Per-point kinematics: G_i (seed Eq. 10), F_i, the Green strain (Eq. 2), cof F; the materials build on them
/// (mechanics/energies/).
#include <pointhaptics/core/model.hpp>
#include <pointhaptics/mechanics/energies/lanes.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pointhaptics {

/// Displacement gradient G_i = sum_j (u_j - u_i) d_ij^T (seed Eq. 10); row a is the gradient of u_a.
inline Mat3 displacement_gradient(const Model& model, const Points& u, index_t i) {
  Mat3 G = Mat3::Zero();
  const Vec3 ui = u.col(i);
  for (index_t e = model.neighbours.begin(i); e < model.neighbours.end(i); ++e)
    G.noalias() += (u.col(model.neighbours.index[e]) - ui) * model.d.col(e).transpose();
  return G;
}

/// Green strain E = 0.5 (F^T F - I) = 0.5 (G + G^T + G^T G) from the displacement gradient G (seed Eq. 2).
/// Written in G: forming F^T F - I cancels catastrophically at small strain (at |G| ~ 1e-9 only 7 digits
/// survive, which puts a floor under Newton's residual).
PH_ALWAYS_INLINE inline Mat3 green_strain(const Mat3& G) { return to_eigen(green_strain(to_matrix3(G))); }

/// Cofactor matrix cof F = det(F) F^-T; its rows are (r1 x r2, r2 x r0, r0 x r1) for rows r_a of F.
inline Mat3 cofactor(const Mat3& F) { return to_eigen(cofactor(to_matrix3(F))); }

/// A symmetric matrix with its negative eigenvalues set to zero.
inline Mat3 positive_part(const Mat3& S) {
  Eigen::SelfAdjointEigenSolver<Mat3> eig(S);
  const Vec3 lam = eig.eigenvalues().cwiseMax(0.0);
  return eig.eigenvectors() * lam.asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace pointhaptics
