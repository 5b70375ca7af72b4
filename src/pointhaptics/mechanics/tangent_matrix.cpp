#include <pointhaptics/mechanics/tangent_matrix.hpp>

#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>

namespace pointhaptics {
namespace {

/// The stencils that contain point j: j's own (when it has one) and its neighbours' (neighbourhoods are
/// symmetric); fn(i, d_ij) with d_ij the weight of j in stencil i.
template <class Fn>
void for_each_stencil_containing(const Model& model, index_t j, Fn&& fn) {
  const Csr& nbr = model.neighbours;
  if (j < model.stencil_end()) fn(j, Vec3(model.d_self.col(j)));
  for (index_t e = nbr.begin(j); e < nbr.end(j); ++e) {
    const index_t i = nbr.index[e];
    if (i < model.stencil_end()) fn(i, Vec3(model.d.col(model.reverse_pair[e])));
  }
}

/// fn(k, d_ik) for the points k of stencil i.
template <class Fn>
void for_each_stencil_point(const Model& model, index_t i, Fn&& fn) {
  const Csr& nbr = model.neighbours;
  fn(i, Vec3(model.d_self.col(i)));
  for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) fn(nbr.index[e], Vec3(model.d.col(e)));
}

/// fn(c, first, last) over `chunks` even row ranges: on ws's threads, else TBB's.
template <class Fn>
void for_each_row_range(index_t n, int chunks, Workspace* ws, Fn&& fn) {
  const auto range = [&](int c) {
    fn(c, static_cast<index_t>(std::int64_t{n} * c / chunks), static_cast<index_t>(std::int64_t{n} * (c + 1) / chunks));
  };
  if (ws) ws->for_each_chunk([&](int c) { range(c); });
  else tbb::parallel_for(0, chunks, range);
}

/// Row j of the hourglass bound H_a = sum_i sum_{k in N(i)} k_ik w w^T (x) I, w_m = [m = k] - [m = i] - d_im . X_ik
/// over stencil i's points: the Hessian of the pair residuals a_ik = u_k - u_i - G_i X_ik, which uses stencil i's
/// gradient alone. The penalty's r_ik = (a_ik - a_ki) / 2, so (k/2)|r_ik|^2 <= (k/4)(|a_ik|^2 + |a_ki|^2): H_a bounds
/// the exact Hessian from above and, unlike it, stays inside the pattern of points sharing a stencil.
void add_hourglass_bound(const Model& model, index_t j, const std::vector<index_t>& slot, double* row) {
  const Csr& nbr = model.neighbours;
  auto add = [&](index_t m, double value) {
    double* block = row + 9 * static_cast<std::size_t>(slot[m]);
    block[0] += value, block[4] += value, block[8] += value;
  };
  for_each_stencil_containing(model, j, [&](index_t i, const Vec3& d_ij) {
    for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) {
      const index_t k = nbr.index[e];
      const Vec3 x = model.X.col(k) - model.X.col(i);
      const double w_j = (j == k) - (j == i) - d_ij.dot(x);
      if (w_j == 0) continue;
      const double c = model.hg_coef[e] * w_j;
      add(i, c * (-1.0 - model.d_self.col(i).dot(x)));
      for (index_t f = nbr.begin(i); f < nbr.end(i); ++f) add(nbr.index[f], c * ((f == e) - model.d.col(f).dot(x)));
    }
  });
}

}  // namespace

void build_tangent_pattern(const Model& model, TangentMatrix& K) {
  const index_t n = model.n_points;
  Csr& pattern = K.pattern;
  pattern.offset.assign(1, 0);
  pattern.index.clear();
  K.diagonal.resize(n);
  std::vector<unsigned char> seen(n, 0);
  std::vector<index_t> row;
  for (index_t j = 0; j < n; ++j) {
    row.clear();
    auto add = [&](index_t k) {
      if (!seen[k]) seen[k] = 1, row.push_back(k);
    };
    add(j);  // a held point's row keeps its diagonal block (it has no stencil of its own when passive)
    for_each_stencil_containing(model, j, [&](index_t i, const Vec3&) {
      for_each_stencil_point(model, i, [&](index_t k, const Vec3&) { add(k); });
    });
    std::sort(row.begin(), row.end());
    for (index_t k : row) seen[k] = 0;
    K.diagonal[j] =
        pattern.n_entries() + static_cast<index_t>(std::lower_bound(row.begin(), row.end(), j) - row.begin());
    pattern.index.insert(pattern.index.end(), row.begin(), row.end());
    pattern.offset.push_back(pattern.n_entries());
  }
  K.values.assign(9 * static_cast<std::size_t>(pattern.n_entries()), 0.0);
  K.model_pairs = model.n_pairs();
}

void assemble_tangent(const Model& model, const Tangent& tangent, TangentMatrix& K, Workspace* ws) {
  const index_t n = model.n_points;
  if (K.pattern.n_rows() != n || K.model_pairs != model.n_pairs()) build_tangent_pattern(model, K);
  tangent.moduli(model, K.moduli, ws);
  const std::vector<double>& moduli = K.moduli;
  const Csr& pattern = K.pattern;
  K.values.resize(9 * static_cast<std::size_t>(pattern.n_entries()));
  const bool hourglass = model.material.hourglass > 0;
  // a row's slot per column point, per chunk of rows: each row is written by one thread only (no atomics)
  const int chunks = ws ? ws->n_threads() : static_cast<int>(tbb::this_task_arena::max_concurrency());
  K.slots.resize(chunks);
  for (std::vector<index_t>& slot : K.slots) slot.resize(n, -1);
  for_each_row_range(n, chunks, ws, [&](int c, index_t first, index_t last) {
    std::vector<index_t>& slot = K.slots[c];
    for (index_t j = first; j < last; ++j) {
      double* row = K.values.data() + 9 * static_cast<std::size_t>(pattern.begin(j));
      std::fill(row, row + 9 * static_cast<std::size_t>(pattern.row_size(j)), 0.0);
      for (index_t e = pattern.begin(j); e < pattern.end(j); ++e) slot[pattern.index[e]] = e - pattern.begin(j);
      for_each_stencil_containing(model, j, [&](index_t i, const Vec3& d_ij) {
        const Eigen::Map<const Eigen::Matrix<double, 9, 9>> C(moduli.data() + 81 * static_cast<std::size_t>(i));
        // A(a, b + 3e) = sum_c d_ij(c) C(a + 3c, b + 3e): j's force row of the stencil's stress derivative
        const Eigen::Matrix<double, 3, 9> A =
            d_ij[0] * C.topRows<3>() + d_ij[1] * C.middleRows<3>(3) + d_ij[2] * C.bottomRows<3>();
        for_each_stencil_point(model, i, [&](index_t k, const Vec3& d_ik) {
          Eigen::Map<Mat3> block(row + 9 * static_cast<std::size_t>(slot[k]));
          block += d_ik[0] * A.leftCols<3>() + d_ik[1] * A.middleCols<3>(3) + d_ik[2] * A.rightCols<3>();
        });
      });
      if (hourglass) add_hourglass_bound(model, j, slot, row);
      for (index_t e = pattern.begin(j); e < pattern.end(j); ++e) slot[pattern.index[e]] = -1;
    }
  });
}

namespace {
// the entry of block (j, k) in row j, -1 when the pattern has none (rows are sorted)
index_t find_block(const TangentMatrix& K, index_t j, index_t k) {
  const auto first = K.pattern.index.begin() + K.pattern.begin(j), last = K.pattern.index.begin() + K.pattern.end(j);
  const auto it = std::lower_bound(first, last, k);
  return it != last && *it == k ? static_cast<index_t>(it - K.pattern.index.begin()) : -1;
}
Eigen::Map<Mat3> block(TangentMatrix& K, index_t e) {
  return Eigen::Map<Mat3>(K.values.data() + 9 * static_cast<std::size_t>(e));
}
}  // namespace

void add_coupling(TangentMatrix& K, index_t j, index_t k, double a, const Mat3& S) {
  if (j == k) {
    block(K, K.diagonal[j]) += a * S;
    return;
  }
  const index_t jk = find_block(K, j, k), kj = find_block(K, k, j);
  if (jk >= 0 && kj >= 0) {
    block(K, jk) += a * S;
    block(K, kj) += a * S;
    return;
  }
  block(K, K.diagonal[j]) += std::abs(a) * S;
  block(K, K.diagonal[k]) += std::abs(a) * S;
}

void multiply(const TangentMatrix& K, const Points& x, Points& y) {
  y.setZero(3, x.cols());
  for (index_t j = 0; j < K.pattern.n_rows(); ++j)
    for (index_t e = K.pattern.begin(j); e < K.pattern.end(j); ++e)
      y.col(j) += Eigen::Map<const Mat3>(K.values.data() + 9 * static_cast<std::size_t>(e)) * x.col(K.pattern.index[e]);
}

}  // namespace pointhaptics
