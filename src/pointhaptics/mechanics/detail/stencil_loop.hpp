#pragma once
/// @file The loop over stencils shared by the internal forces and the tangent (an internal header).
/// Both are "gather the gradients, map each to a stress, scatter the stresses back": the forces map G_i to
/// v_i P_i(G_i), the tangent maps dG_i to v_i dP_i(dG_i). The hourglass energy is quadratic in u, so the
/// same code gives its force (from u) and its tangent product (from du).
///
/// Every 3-vector of the loop (a displacement, a column of G_i or A_i, a force) is held as 4 doubles,
/// x y z and a zero, so that one SIMD instruction does a point's three components: a neighbour's
/// displacement, gradient column or force is one aligned load, with no gather (vectorising across the pairs
/// of a stencil or across points needs 20+ gathered doubles per pair, which cost what they save;
/// docs/performance.md). The pad lane stays zero throughout: it starts zero in u and every operation
/// maps zero lanes to zero.
// GCC builds without AVX (the sanitizer presets) warn that passing or returning a Lane4 has another ABI
// than with AVX; everything here is inline in one internal header and never crosses a library boundary.
// Before the includes: hourglass_pair_force<Lane4> is defined in one of them.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
#include <pointhaptics/core/workspace.hpp>
#include <pointhaptics/mechanics/energies/hourglass.hpp>
#include <pointhaptics/mechanics/energies/lanes.hpp>

#include <algorithm>
#include <concepts>
#include <cstring>
#include <type_traits>

namespace pointhaptics::detail {

/// x, y, z and a zero pad; arithmetic with a double broadcasts it.
using Lane4 = Lanes;

inline Lane4 load4(const double* p) {
  Lane4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store4(double* p, Lane4 v) { std::memcpy(p, &v, sizeof v); }

/// u (3 x n) into the padded layout (4 x n, pad zero) for points [first, last).
inline void pad_points(const Points& u, index_t first, index_t last, PaddedPoints& padded) {
  const double* src = u.data();
  double* dst = padded.data();
  for (index_t i = first; i < last; ++i) {
    dst[4 * i] = src[3 * i];
    dst[4 * i + 1] = src[3 * i + 1];
    dst[4 * i + 2] = src[3 * i + 2];
    dst[4 * i + 3] = 0.0;
  }
}

/// Pass 1: the gradients G_i = sum_j (u_j - u_i) d_ij^T (seed Eq. 10) of the points i in [first, last),
/// column by column (column c = sum_j (u_j - u_i) d_ij,c) into `gradients` (12 doubles per point).
inline void gradient_pass(const Model& model, const PaddedPoints& u, index_t first, index_t last,
                          PaddedGradients& gradients) {
  const Csr& nbr = model.neighbours;
  const index_t* nbr_index = nbr.index.data();
  const double* d = model.d.data();
  const double* U = u.data();
  double* Gall = gradients.data();
  for (index_t i = first; i < last; ++i) {
    const Lane4 ui = load4(U + 4 * i);
    Lane4 G0 = {}, G1 = {}, G2 = {};
    for (index_t e = nbr.begin(i), e1 = nbr.end(i); e < e1; ++e) {
      const Lane4 du = load4(U + 4 * nbr_index[e]) - ui;
      G0 += du * d[3 * e];
      G1 += du * d[3 * e + 1];
      G2 += du * d[3 * e + 2];
    }
    double* g = Gall + 12 * static_cast<std::ptrdiff_t>(i);
    store4(g, G0);
    store4(g + 4, G1);
    store4(g + 8, G2);
  }
}

/// A stress map that also takes four consecutive points at once: stress(i, count, G) for the points
/// i .. i + count - 1 (lanes.hpp).
template <class StressMap>
concept FourPointStressMap = requires(const StressMap& stress, const Matrix3<Lanes>& G) {
  { stress(index_t{}, int{}, G) } -> std::same_as<Matrix3<Lanes>>;
};

/// Pass 2: adds, for the stencils i in [first, last), the terms of y = -dW/du into `out` (padded), with
/// the stress map A_i = stress(i, G_i) and the gradients of pass 1. With the hourglass penalty
/// (energies/hourglass.hpp) its exact gradient is added per pair:
///   y_j -= k_ij r_ij,  y_i += k_ij r_ij,   and A_i -= Q_i = sum_j k_ij r_ij X_ij^T,
/// then y_j -= A_i d_ij, y_i -= A_i d_ii. A FourPointStressMap is asked for four stencils' A_i at once.
template <bool hourglass, class StressMap>
void stencil_loop(const Model& model, const PaddedPoints& u, const PaddedGradients& gradients, index_t first,
                  index_t last, PaddedPoints& y, StressMap&& stress) {
  const Csr& nbr = model.neighbours;
  const index_t* nbr_index = nbr.index.data();
  const double* d = model.d.data();
  const double* d_self = model.d_self.data();
  const double* k = model.hg_coef.data();
  const double* X = model.X.data();
  const double* U = u.data();
  const double* Gall = gradients.data();
  double* out = y.data();
  // a local copy of the stress map: its constants (a material's moduli, pointers) cannot alias the forces
  // written below, so they stay in registers instead of being reloaded for every stencil (5% of the loop)
  const std::decay_t<StressMap> stress_map = stress;

  // the stencil of i with its stress map A_i = (A0 A1 A2)
  auto stencil_of = [&](index_t i, Lane4 A0, Lane4 A1, Lane4 A2) PH_ALWAYS_INLINE {
    const index_t e0 = nbr.begin(i), e1 = nbr.end(i);
    Lane4 self = {};
    if constexpr (hourglass) {
      const double* gi = Gall + 12 * static_cast<std::ptrdiff_t>(i);
      const Lane4 Gi0 = load4(gi), Gi1 = load4(gi + 4), Gi2 = load4(gi + 8);
      const Lane4 ui = load4(U + 4 * i);
      const double Xi0 = X[3 * i], Xi1 = X[3 * i + 1], Xi2 = X[3 * i + 2];
      Lane4 Q0 = {}, Q1 = {}, Q2 = {};
      for (index_t e = e0; e < e1; ++e) {
        const index_t j = nbr_index[e];
        const double* gj = Gall + 12 * static_cast<std::ptrdiff_t>(j);
        const double x0 = X[3 * j] - Xi0, x1 = X[3 * j + 1] - Xi1, x2 = X[3 * j + 2] - Xi2;
        // k r = k (u_j - u_i) - (k/2) (G_i + G_j) X_ij  (energies/hourglass.hpp)
        const Lane4 r = hourglass_pair_force(k[e], Lane4(load4(U + 4 * j) - ui), Lane4(Gi0 + load4(gj)),
                                             Lane4(Gi1 + load4(gj + 4)), Lane4(Gi2 + load4(gj + 8)), x0, x1, x2);
        Q0 += r * x0;
        Q1 += r * x1;
        Q2 += r * x2;
        self += r;
        store4(out + 4 * j, load4(out + 4 * j) - r);
      }
      A0 -= Q0;
      A1 -= Q1;
      A2 -= Q2;
    }
    // the point itself: y_i = sum_j k_ij r_ij - A_i d_ii
    const double* di = d_self + 3 * i;
    store4(out + 4 * i, load4(out + 4 * i) + self - (A0 * di[0] + A1 * di[1] + A2 * di[2]));
    // scatter to the neighbours (no two pairs of a stencil share j)
    for (index_t e = e0; e < e1; ++e) {
      double* oj = out + 4 * nbr_index[e];
      store4(oj, load4(oj) - (A0 * d[3 * e] + A1 * d[3 * e + 1] + A2 * d[3 * e + 2]));
    }
  };

  if constexpr (FourPointStressMap<StressMap>) {
    for (index_t i = first; i < last; i += lane_count) {
      const int count = static_cast<int>(std::min<index_t>(lane_count, last - i));
      const Matrix3<Lanes> G = four_gradients(Gall, i, count);  // lanes past `count`: never read back
      const Matrix3<Lanes> A = stress_map(i, count, G);
      for (int p = 0; p < count; ++p)
        stencil_of(i + p, Lane4{A.m[0][p], A.m[1][p], A.m[2][p], 0.0}, Lane4{A.m[3][p], A.m[4][p], A.m[5][p], 0.0},
                   Lane4{A.m[6][p], A.m[7][p], A.m[8][p], 0.0});
    }
  } else {
    for (index_t i = first; i < last; ++i) {
      const double* gi = Gall + 12 * static_cast<std::ptrdiff_t>(i);
      Mat3 G;
      G << gi[0], gi[4], gi[8], gi[1], gi[5], gi[9], gi[2], gi[6], gi[10];
      const Mat3 A = stress_map(i, G);
      stencil_of(i, Lane4{A(0, 0), A(1, 0), A(2, 0), 0.0}, Lane4{A(0, 1), A(1, 1), A(2, 1), 0.0},
                 Lane4{A(0, 2), A(1, 2), A(2, 2), 0.0});
    }
  }
}

/// y = sign * (sum over all stencils of stencil_loop), on ws's threads: u into the padded layout, the
/// gradient pass into ws.gradients, then each chunk of stencils scatters into its own buffer over the
/// columns it touches, then each chunk sums its own columns into y. No allocation.
template <class StressMap>
void stencil_sum(const Model& model, const Points& u, Workspace& ws, Points& y, double sign, StressMap&& stress) {
  const bool hourglass = model.material.hourglass > 0;
  auto run = [&](index_t first, index_t last, PaddedPoints& target) {
    if (hourglass) stencil_loop<true>(model, ws.padded_u, ws.gradients, first, last, target, stress);
    else stencil_loop<false>(model, ws.padded_u, ws.gradients, first, last, target, stress);
  };
  const int n_chunks = ws.n_threads();
  const index_t stencil_end =
      model.stencil_end();  // passive points: gradients (their neighbours read them), no stencil
  // every gradient is needed before any stencil's hourglass term (it reads its neighbours' G_j), and
  // every padded u before any gradient
  // (the points that sleep, ws.asleep: neither their gradients nor their stencils, only ws.awake's; their sum is
  // 0. No neighbour list leaves a body, and a body sleeps whole)
  const auto over_awake = [&](index_t first, index_t last, auto&& pass) {
    if (ws.asleep.empty()) return pass(first, last);
    for (const std::array<index_t, 2>& range : ws.awake)
      if (std::max(first, range[0]) < std::min(last, range[1]))
        pass(std::max(first, range[0]), std::min(last, range[1]));
  };
  ws.for_each_chunk([&](int c) { pad_points(u, ws.chunk_begin(c), ws.chunk_end(c), ws.padded_u); });
  ws.for_each_chunk([&](int c) {
    over_awake(ws.chunk_begin(c), ws.chunk_end(c),
               [&](index_t first, index_t last) { gradient_pass(model, ws.padded_u, first, last, ws.gradients); });
  });
  ws.for_each_chunk([&](int c) {
    PaddedPoints& buffer = ws.chunk_forces[c];
    const index_t lo = ws.scatter_begin(c), hi = ws.scatter_end(c);
    buffer.middleCols(lo, hi - lo).setZero();
    over_awake(ws.chunk_begin(c), std::min(ws.chunk_end(c), stencil_end),
               [&](index_t first, index_t last) { run(first, last, buffer); });
  });
  ws.for_each_chunk([&](int c) {
    const index_t first = ws.chunk_begin(c), last = ws.chunk_end(c);
    for (index_t i = first; i < last; ++i) {
      Lane4 sum = {};
      for (int b = 0; b < n_chunks; ++b)
        if (i >= ws.scatter_begin(b) && i < ws.scatter_end(b)) sum += load4(ws.chunk_forces[b].data() + 4 * i);
      sum *= sign;
      y(0, i) = sum[0];
      y(1, i) = sum[1];
      y(2, i) = sum[2];
    }
  });
}

}  // namespace pointhaptics::detail

// No pop: GCC emits the -Wpsabi warning for the always-inlined hourglass_pair_force<Lane4> at the end of the
// translation unit, where a popped state would warn again; the ignore lasts to the end of forces.cpp and
// tangent.cpp, the only files that include this internal header.
