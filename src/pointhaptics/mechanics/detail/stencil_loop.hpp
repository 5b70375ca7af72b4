#pragma once
/// @file The loop over stencils shared by the internal forces and the tangent (an internal header).
/// Both are "gather a gradient, map it to a stress, scatter the stress back": the forces map G_i to
/// v_i P_i(G_i), the tangent maps dG_i to v_i dP_i(dG_i). The hourglass energy is quadratic in u, so the
/// same code gives its force (from u) and its tangent product (from du).
#include <pointhaptics/core/workspace.hpp>

#include <algorithm>

// Stress maps are small lambdas called once per stencil; GCC otherwise keeps them out of line and the
// force loop loses ~20% returning the 3x3 through memory.
#if defined(__GNUC__)
#define PH_ALWAYS_INLINE __attribute__((always_inline))
#else
#define PH_ALWAYS_INLINE
#endif

namespace pointhaptics::detail {

/// Adds, for the stencils i in [first, last), the terms of y = -dW/du evaluated by the stress map
/// A_i = stress(i, G_i) (G_i gathered from the columns of `u`, seed Eq. 10), into the columns of y.
/// The hourglass sums are expanded so that one gather pass suffices: with du_j = u_j - u_i, g_j = c_j X_ij,
///   Q_i = sum_j c_j r_j X_ij^T = sum_j du_j g_j^T - G_i H_i,   sum_j c_j r_j = sum_j c_j du_j - G_i t_i,
/// and the scatter y_j -= (A_i - Q_i) d_ij + c_j du_j - G_i g_j (H_i, t_i precomputed in the model;
/// g_j is recomputed from the positions, cheaper than streaming it from memory).
template <bool hourglass, class StressMap>
void stencil_loop(const Model& model, const Points& u, index_t first, index_t last, Points& y, StressMap&& stress) {
  const Csr& nbr = model.neighbours;
  const index_t* nbr_index = nbr.index.data();
  const double* d = model.d.data();
  const double* c = model.hg_coef.data();
  const double* X = model.X.data();
  const double* U = u.data();
  double* out = y.data();

  for (index_t i = first; i < last; ++i) {
    const index_t e0 = nbr.begin(i), e1 = nbr.end(i);
    const double ui0 = U[3 * i], ui1 = U[3 * i + 1], ui2 = U[3 * i + 2];
    const double Xi0 = X[3 * i], Xi1 = X[3 * i + 1], Xi2 = X[3 * i + 2];

    // gather: gradient (seed Eq. 10) and the hourglass sums, in scalars (row-major G[a][k] = du_a d_k);
    // explicit SIMD across one stencil did not pay here (rows of ~24 pairs)
    double G00 = 0, G01 = 0, G02 = 0, G10 = 0, G11 = 0, G12 = 0, G20 = 0, G21 = 0, G22 = 0;
    double B00 = 0, B01 = 0, B02 = 0, B10 = 0, B11 = 0, B12 = 0, B20 = 0, B21 = 0, B22 = 0;
    double s0 = 0, s1 = 0, s2 = 0;
    for (index_t e = e0; e < e1; ++e) {
      const index_t j = nbr_index[e];
      const double du0 = U[3 * j] - ui0, du1 = U[3 * j + 1] - ui1, du2 = U[3 * j + 2] - ui2;
      const double d0 = d[3 * e], d1 = d[3 * e + 1], d2 = d[3 * e + 2];
      G00 += du0 * d0; G01 += du0 * d1; G02 += du0 * d2;
      G10 += du1 * d0; G11 += du1 * d1; G12 += du1 * d2;
      G20 += du2 * d0; G21 += du2 * d1; G22 += du2 * d2;
      if constexpr (hourglass) {
        const double g0 = c[e] * (X[3 * j] - Xi0), g1 = c[e] * (X[3 * j + 1] - Xi1), g2 = c[e] * (X[3 * j + 2] - Xi2);
        B00 += du0 * g0; B01 += du0 * g1; B02 += du0 * g2;
        B10 += du1 * g0; B11 += du1 * g1; B12 += du1 * g2;
        B20 += du2 * g0; B21 += du2 * g1; B22 += du2 * g2;
        s0 += c[e] * du0; s1 += c[e] * du1; s2 += c[e] * du2;
      }
    }
    Mat3 G;
    G << G00, G01, G02, G10, G11, G12, G20, G21, G22;
    Mat3 A = stress(i, G);
    Vec3 self(s0, s1, s2);
    if constexpr (hourglass) {
      Mat3 B;
      B << B00, B01, B02, B10, B11, B12, B20, B21, B22;
      A -= B - G * Eigen::Map<const Mat3>(model.hg_H.data() + 9 * i);
      self -= G * model.hg_t.col(i);
    }
    // the point itself: y_i = sum_j c_j r_j - A_i d_ii
    Eigen::Map<Vec3>(out + 3 * i) += self - A * model.d_self.col(i);

    // scatter to the neighbours (no two pairs of a stencil share j)
    const double A00 = A(0, 0), A01 = A(0, 1), A02 = A(0, 2), A10 = A(1, 0), A11 = A(1, 1), A12 = A(1, 2),
                 A20 = A(2, 0), A21 = A(2, 1), A22 = A(2, 2);
    for (index_t e = e0; e < e1; ++e) {
      const index_t j = nbr_index[e];
      const double d0 = d[3 * e], d1 = d[3 * e + 1], d2 = d[3 * e + 2];
      double f0 = A00 * d0 + A01 * d1 + A02 * d2;
      double f1 = A10 * d0 + A11 * d1 + A12 * d2;
      double f2 = A20 * d0 + A21 * d1 + A22 * d2;
      if constexpr (hourglass) {
        const double g0 = c[e] * (X[3 * j] - Xi0), g1 = c[e] * (X[3 * j + 1] - Xi1), g2 = c[e] * (X[3 * j + 2] - Xi2);
        f0 += c[e] * (U[3 * j] - ui0) - (G00 * g0 + G01 * g1 + G02 * g2);
        f1 += c[e] * (U[3 * j + 1] - ui1) - (G10 * g0 + G11 * g1 + G12 * g2);
        f2 += c[e] * (U[3 * j + 2] - ui2) - (G20 * g0 + G21 * g1 + G22 * g2);
      }
      out[3 * j] -= f0;
      out[3 * j + 1] -= f1;
      out[3 * j + 2] -= f2;
    }
  }
}

/// y = sign * (sum over all stencils of stencil_loop), on ws's threads: each chunk of stencils scatters
/// into its own buffer over the columns it touches, then each chunk sums its own columns. No allocation.
template <class StressMap>
void stencil_sum(const Model& model, const Points& u, Workspace& ws, Points& y, double sign, StressMap&& stress) {
  const bool hourglass = model.material.hourglass > 0;
  auto run = [&](index_t first, index_t last, Points& target) {
    if (hourglass) stencil_loop<true>(model, u, first, last, target, stress);
    else stencil_loop<false>(model, u, first, last, target, stress);
  };
  const int n_chunks = ws.n_threads();
  if (n_chunks == 1) {
    y.setZero();
    run(0, model.n_points, y);
    if (sign != 1.0) y *= sign;
    return;
  }
  ws.for_each_chunk([&](int c) {
    Points& buffer = ws.chunk_forces[c];
    const index_t lo = ws.scatter_begin(c), hi = ws.scatter_end(c);
    buffer.middleCols(lo, hi - lo).setZero();
    run(ws.chunk_begin(c), ws.chunk_end(c), buffer);
  });
  ws.for_each_chunk([&](int c) {
    const index_t first = ws.chunk_begin(c), last = ws.chunk_end(c);
    auto cols = y.middleCols(first, last - first);
    cols.setZero();
    for (int b = 0; b < n_chunks; ++b) {
      const index_t lo = std::max(first, ws.scatter_begin(b)), hi = std::min(last, ws.scatter_end(b));
      if (lo < hi) y.middleCols(lo, hi - lo) += ws.chunk_forces[b].middleCols(lo, hi - lo);
    }
    if (sign != 1.0) cols *= sign;
  });
}

}  // namespace pointhaptics::detail
