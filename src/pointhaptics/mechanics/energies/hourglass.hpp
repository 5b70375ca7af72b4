#pragma once
/// @file The hourglass penalty against zero-energy modes (physics.md, averaged-gradient form): its energy,
/// its gradient (one pair's force, used by the stencil loop) and its constant Hessian's diagonal, side by
/// side (tests/mechanics/energies/hourglass_test.cpp).
///
/// W = sum_i sum_{j in N(i)} (k_ij / 2) |r_ij|^2,  r_ij = u_j - u_i - (G_i + G_j) X_ij / 2,
/// k_ij = (alpha / 2) (E_i v_i w^_ij + E_j v_j w^_ji) / |X_ij|^2,  w^_ij = w_ij / sum_k w_ik  (symmetric; E_i the
/// point's Young's modulus).
/// r vanishes for any field whose gradient the stencils reproduce at both ends, so quadratic (bending) fields
/// cost nothing inside the body, while checkerboard modes, whose interior gradients vanish, are fully
/// penalised. Its exact gradient, per pair: y_j -= k r, y_i += k r, and the stress of stencil i gains
/// -Q_i = -sum_j k_ij r_ij X_ij^T (then scattered through d_ij like the material's stress).
#include <pointhaptics/core/model.hpp>

#include <utility>
#include <vector>

namespace pointhaptics {

/// r_ij of one pair: du = u_j - u_i, G_sum = G_i + G_j, x = X_j - X_i.
inline Vec3 hourglass_residual(const Vec3& du, const Mat3& G_sum, const Vec3& x) { return du - 0.5 * G_sum * x; }

/// (k_ij / 2) |r_ij|^2, J.
inline double hourglass_pair_energy(double k, const Vec3& du, const Mat3& G_sum, const Vec3& x) {
  return 0.5 * k * hourglass_residual(du, G_sum, x).squaredNorm();
}

/// k r_ij, the pair's force on u_i (and minus it on u_j), generic over the vector type: Vec3, or the stencil
/// loop's padded 4-lane vectors. g0..g2 are the columns of G_i + G_j, x = X_j - X_i. (GCC builds without AVX
/// note that returning a 4-lane vector changes the ABI: stencil_loop.hpp silences that for its translation
/// units; the function is always inlined.)
template <class V>
PH_ALWAYS_INLINE inline V hourglass_pair_force(double k, const V& du, const V& g0, const V& g1, const V& g2, double x0,
                                               double x1, double x2) {
  const double kh = 0.5 * k;
  return k * du - (g0 * (kh * x0) + g1 * (kh * x1) + g2 * (kh * x2));
}

/// k_ij of pair e = (i, j) (the formula above) from the kernel weights' sums of stencils i and j; zero for a
/// severed pair.
double hourglass_coefficient(const Model& model, index_t i, index_t e, double weight_sum_i, double weight_sum_j);

/// The pair coefficients k_ij (model.hg_coef) from the sums of the stencils' kernel weights, and the exact
/// diagonal of the constant Hessian (model.hg_diagonal). The weight of u_m in r_ij is
///   [m = j] - [m = i] - (a_im + a_jm) / 2,  a_im = d_im . X_ij (m in N(i)), a_ii = d_ii . X_ij,
/// so diag_m = sum over pairs of k_ij (weight)^2, over the two stencils of each pair (O(pairs x stencil), in
/// parallel on TBB's threads). Needs model.d, d_self, volume, X, reverse_pair, kernel and material.
void build_hourglass(Model& model, const std::vector<double>& weight_sum);

/// Adds `sign` times the diagonal's terms of the given pairs (each (i, e), e = (i, j) in i's row) to `diagonal`,
/// from the model's current d and k: a cut takes its changed pairs' terms out before it refits them and puts
/// them back after.
void add_hourglass_diagonal(const Model& model, const std::vector<std::pair<index_t, index_t>>& pairs, double sign,
                            Eigen::VectorXd& diagonal);

}  // namespace pointhaptics
