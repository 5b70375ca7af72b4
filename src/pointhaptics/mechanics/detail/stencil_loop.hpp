#pragma once
/// @file The loop over stencils shared by the internal forces and the tangent (an internal header).
/// Both are "gather the gradients, map each to a stress, scatter the stresses back": the forces map G_i to
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

/// Pass 1: the gradients G_i = sum_j (u_j - u_i) d_ij^T (seed Eq. 10) of the points i in [first, last),
/// row-major into the columns of `gradients` (9 x n).
inline void gradient_pass(const Model& model, const Points& u, index_t first, index_t last,
                          Eigen::Matrix<double, 9, Eigen::Dynamic>& gradients) {
  const Csr& nbr = model.neighbours;
  const index_t* nbr_index = nbr.index.data();
  const double* d = model.d.data();
  const double* U = u.data();
  for (index_t i = first; i < last; ++i) {
    const double ui0 = U[3 * i], ui1 = U[3 * i + 1], ui2 = U[3 * i + 2];
    double G00 = 0, G01 = 0, G02 = 0, G10 = 0, G11 = 0, G12 = 0, G20 = 0, G21 = 0, G22 = 0;
    for (index_t e = nbr.begin(i), e1 = nbr.end(i); e < e1; ++e) {
      const index_t j = nbr_index[e];
      const double du0 = U[3 * j] - ui0, du1 = U[3 * j + 1] - ui1, du2 = U[3 * j + 2] - ui2;
      const double d0 = d[3 * e], d1 = d[3 * e + 1], d2 = d[3 * e + 2];
      G00 += du0 * d0; G01 += du0 * d1; G02 += du0 * d2;
      G10 += du1 * d0; G11 += du1 * d1; G12 += du1 * d2;
      G20 += du2 * d0; G21 += du2 * d1; G22 += du2 * d2;
    }
    double* g = gradients.data() + 9 * static_cast<Eigen::Index>(i);
    g[0] = G00; g[1] = G01; g[2] = G02; g[3] = G10; g[4] = G11; g[5] = G12; g[6] = G20; g[7] = G21; g[8] = G22;
  }
}

/// Pass 2: adds, for the stencils i in [first, last), the terms of y = -dW/du into the columns of y, with
/// the stress map A_i = stress(i, G_i) and the gradients of pass 1. The hourglass energy (physics.md, in
/// its averaged-gradient form) is W = sum_i sum_j (k_ij / 2) |r_ij|^2 with r_ij = u_j - u_i - (G_i + G_j) X_ij / 2
/// and k_ij symmetric; its exact gradient is
///   y_j -= k_ij r_ij,  y_i += k_ij r_ij  (per pair),   and A_i -= Q_i = sum_j k_ij r_ij X_ij^T,
/// then y_j -= A_i d_ij, y_i -= A_i d_ii. r vanishes for any field whose gradient the stencils reproduce
/// at both ends, so quadratic (bending) fields cost nothing inside the body, while checkerboard
/// (zero-energy) modes, whose interior gradients vanish, are fully penalised.
template <bool hourglass, class StressMap>
void stencil_loop(const Model& model, const Points& u, const Eigen::Matrix<double, 9, Eigen::Dynamic>& gradients,
                  index_t first, index_t last, Points& y, StressMap&& stress) {
  const Csr& nbr = model.neighbours;
  const index_t* nbr_index = nbr.index.data();
  const double* d = model.d.data();
  const double* k = model.hg_coef.data();
  const double* X = model.X.data();
  const double* U = u.data();
  const double* Gall = gradients.data();
  double* out = y.data();

  for (index_t i = first; i < last; ++i) {
    const index_t e0 = nbr.begin(i), e1 = nbr.end(i);
    const double* gi = Gall + 9 * static_cast<Eigen::Index>(i);
    Mat3 G;
    G << gi[0], gi[1], gi[2], gi[3], gi[4], gi[5], gi[6], gi[7], gi[8];
    Mat3 A = stress(i, G);
    Vec3 self = Vec3::Zero();
    if constexpr (hourglass) {
      const double ui0 = U[3 * i], ui1 = U[3 * i + 1], ui2 = U[3 * i + 2];
      const double Xi0 = X[3 * i], Xi1 = X[3 * i + 1], Xi2 = X[3 * i + 2];
      double Q00 = 0, Q01 = 0, Q02 = 0, Q10 = 0, Q11 = 0, Q12 = 0, Q20 = 0, Q21 = 0, Q22 = 0;
      double s0 = 0, s1 = 0, s2 = 0;
      for (index_t e = e0; e < e1; ++e) {
        const index_t j = nbr_index[e];
        const double* gj = Gall + 9 * static_cast<Eigen::Index>(j);
        const double x0 = X[3 * j] - Xi0, x1 = X[3 * j + 1] - Xi1, x2 = X[3 * j + 2] - Xi2;
        const double kh = 0.5 * k[e];
        // k r = k (u_j - u_i) - (k/2) (G_i + G_j) X_ij
        const double r0 = k[e] * (U[3 * j] - ui0) - kh * ((gi[0] + gj[0]) * x0 + (gi[1] + gj[1]) * x1 + (gi[2] + gj[2]) * x2);
        const double r1 = k[e] * (U[3 * j + 1] - ui1) - kh * ((gi[3] + gj[3]) * x0 + (gi[4] + gj[4]) * x1 + (gi[5] + gj[5]) * x2);
        const double r2 = k[e] * (U[3 * j + 2] - ui2) - kh * ((gi[6] + gj[6]) * x0 + (gi[7] + gj[7]) * x1 + (gi[8] + gj[8]) * x2);
        Q00 += r0 * x0; Q01 += r0 * x1; Q02 += r0 * x2;
        Q10 += r1 * x0; Q11 += r1 * x1; Q12 += r1 * x2;
        Q20 += r2 * x0; Q21 += r2 * x1; Q22 += r2 * x2;
        s0 += r0; s1 += r1; s2 += r2;
        out[3 * j] -= r0;
        out[3 * j + 1] -= r1;
        out[3 * j + 2] -= r2;
      }
      Mat3 Q;
      Q << Q00, Q01, Q02, Q10, Q11, Q12, Q20, Q21, Q22;
      A -= Q;
      self = Vec3(s0, s1, s2);
    }
    // the point itself: y_i = sum_j k_ij r_ij - A_i d_ii
    Eigen::Map<Vec3>(out + 3 * i) += self - A * model.d_self.col(i);

    // scatter to the neighbours (no two pairs of a stencil share j)
    const double A00 = A(0, 0), A01 = A(0, 1), A02 = A(0, 2), A10 = A(1, 0), A11 = A(1, 1), A12 = A(1, 2),
                 A20 = A(2, 0), A21 = A(2, 1), A22 = A(2, 2);
    for (index_t e = e0; e < e1; ++e) {
      const index_t j = nbr_index[e];
      const double d0 = d[3 * e], d1 = d[3 * e + 1], d2 = d[3 * e + 2];
      out[3 * j] -= A00 * d0 + A01 * d1 + A02 * d2;
      out[3 * j + 1] -= A10 * d0 + A11 * d1 + A12 * d2;
      out[3 * j + 2] -= A20 * d0 + A21 * d1 + A22 * d2;
    }
  }
}

/// y = sign * (sum over all stencils of stencil_loop), on ws's threads: the gradient pass into
/// ws.gradients, then each chunk of stencils scatters into its own buffer over the columns it touches,
/// then each chunk sums its own columns. No allocation.
template <class StressMap>
void stencil_sum(const Model& model, const Points& u, Workspace& ws, Points& y, double sign, StressMap&& stress) {
  const bool hourglass = model.material.hourglass > 0;
  auto run = [&](index_t first, index_t last, Points& target) {
    if (hourglass) stencil_loop<true>(model, u, ws.gradients, first, last, target, stress);
    else stencil_loop<false>(model, u, ws.gradients, first, last, target, stress);
  };
  const int n_chunks = ws.n_threads();
  const index_t stencil_end = model.stencil_end();  // passive points: gradients (their neighbours read them), no stencil
  if (n_chunks == 1) {
    gradient_pass(model, u, 0, model.n_points, ws.gradients);
    y.setZero();
    run(0, stencil_end, y);
    if (sign != 1.0) y *= sign;
    return;
  }
  // every gradient is needed before any stencil's hourglass term (it reads its neighbours' G_j)
  ws.for_each_chunk([&](int c) { gradient_pass(model, u, ws.chunk_begin(c), ws.chunk_end(c), ws.gradients); });
  ws.for_each_chunk([&](int c) {
    Points& buffer = ws.chunk_forces[c];
    const index_t lo = ws.scatter_begin(c), hi = ws.scatter_end(c);
    buffer.middleCols(lo, hi - lo).setZero();
    run(ws.chunk_begin(c), std::min(ws.chunk_end(c), stencil_end), buffer);
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
