#include <pointhaptics/mechanics/tangent.hpp>

#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/detail/stencil_loop.hpp>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>

namespace pointhaptics {
namespace {

/// v dP for a gradient increment dG at (F, S) (physics.md, "Tangent"):
///   dP = dG S + F (lambda tr(dE) I + 2 mu dE) + k_v [(cof F : dG) cof F + (J - 1) d(cof F)],
///   dE = sym(F^T dG). PROJECTED passes S's positive part and drops the (J - 1) term.
PH_ALWAYS_INLINE inline Mat3 stress_increment(const Mat3& F, const Mat3& S, const Mat3& dG, double v, double lambda, double mu,
                             double kv, bool exact) {
  const Mat3 FtdG = F.transpose() * dG;
  const Mat3 dE = 0.5 * (FtdG + FtdG.transpose());
  Mat3 dP = dG * S + F * (lambda * dE.trace() * Mat3::Identity() + 2.0 * mu * dE);
  if (kv > 0) {
    const Mat3 cof = cofactor(F);
    dP += kv * (cof.array() * dG.array()).sum() * cof;
    if (exact) {
      const double J = F.determinant();
      Mat3 dcof;
      dcof.row(0) = dG.row(1).cross(F.row(2)) + F.row(1).cross(dG.row(2));
      dcof.row(1) = dG.row(2).cross(F.row(0)) + F.row(2).cross(dG.row(0));
      dcof.row(2) = dG.row(0).cross(F.row(1)) + F.row(0).cross(dG.row(1));
      dP += kv * (J - 1.0) * dcof;
    }
  }
  return v * dP;
}

/// S with its negative eigenvalues set to zero.
inline Mat3 positive_part(const Mat3& S) {
  Eigen::SelfAdjointEigenSolver<Mat3> eig(S);
  const Vec3 lam = eig.eigenvalues().cwiseMax(0.0);
  return eig.eigenvectors() * lam.asDiagonal() * eig.eigenvectors().transpose();
}

/// fn(i) for i in [0, n): on ws's threads (even contiguous ranges) when given, else on TBB's.
template <class Fn>
void for_each_point(index_t n, Workspace* ws, Fn&& fn) {
  if (ws) {
    const int chunks = ws->n_threads();
    ws->for_each_chunk([&](int c) {
      const index_t first = static_cast<index_t>(std::int64_t{n} * c / chunks);
      const index_t last = static_cast<index_t>(std::int64_t{n} * (c + 1) / chunks);
      for (index_t i = first; i < last; ++i) fn(i);
    });
    return;
  }
  tbb::parallel_for(tbb::blocked_range<index_t>(0, n, 256), [&](const tbb::blocked_range<index_t>& r) {
    for (index_t i = r.begin(); i != r.end(); ++i) fn(i);
  });
}

}  // namespace

void Tangent::linearise(const Model& model, const Points& u, TangentMode mode, Workspace* ws) {
  mode_ = mode;
  F_.resize(9, model.n_points);
  S_.resize(9, model.n_points);
  for_each_point(model.n_points, ws, [&](index_t i) {
    const Mat3 G = displacement_gradient(model, u, i);                   // seed Eq. 10
    const Mat3 F = Mat3::Identity() + G;
    const Mat3 S = svk_stress(green_strain(G), model.lambda, model.mu);  // seed Eq. 2
    F_.col(i) = F.reshaped();
    S_.col(i) = (mode == TangentMode::PROJECTED ? positive_part(S) : S).reshaped();
  });
}

void Tangent::apply(const Model& model, const Points& du, Workspace& ws, Points& out) const {
  const double lambda = model.lambda, mu = model.mu, kv = model.material.volume_stiffness;
  const bool exact = mode_ == TangentMode::EXACT;
  const double* volume = model.volume.data();
  const double* F = F_.data();
  const double* S = S_.data();
  // the force loop with the stress map linearised gives -K du; the hourglass part is linear already
  detail::stencil_sum(model, du, ws, out, -1.0, [=](index_t i, const Mat3& dG) PH_ALWAYS_INLINE -> Mat3 {
    return stress_increment(Eigen::Map<const Mat3>(F + 9 * i), Eigen::Map<const Mat3>(S + 9 * i), dG, volume[i],
                            lambda, mu, kv, exact);
  });
}

void Tangent::diagonal_blocks(const Model& model, Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks, Workspace* ws) const {
  const double lambda = model.lambda, mu = model.mu, kv = model.material.volume_stiffness;
  const bool exact = mode_ == TangentMode::EXACT;
  const Csr& nbr = model.neighbours;
  const index_t n = model.n_points, stencil_end = model.stencil_end();
  blocks.setZero(9, n);
  // C_i = d(v_i P_i)/dG_i (9 x 9) of every stencil, from the stress increments of the 9 unit gradients
  stencil_moduli_.resize(81, stencil_end);
  for_each_point(stencil_end, ws, [&](index_t i) {
    const Mat3 F = Eigen::Map<const Mat3>(F_.data() + 9 * i), S = Eigen::Map<const Mat3>(S_.data() + 9 * i);
    for (int col = 0; col < 9; ++col) {
      Mat3 unit = Mat3::Zero();
      unit.data()[col] = 1.0;
      stencil_moduli_.col(i).segment<9>(9 * col) =
          stress_increment(F, S, unit, model.volume[i], lambda, mu, kv, exact).reshaped();
    }
  });
  // stencil i adds to the block of each j it reaches (j = i with d_ii) sum_{k,l} d_k d_l C_i[a + 3k][b + 3l];
  // gathered per j over the stencils that reach it (neighbourhoods are symmetric), so no two threads write
  // one block. The hourglass part is constant and precomputed in the model (model_builder.cpp).
  auto contribution = [&](index_t i, const double* d) {
    const Eigen::Map<const Eigen::Matrix<double, 9, 9>> C(stencil_moduli_.col(i).data());
    Mat3 K = Mat3::Zero();
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) K += d[k] * d[l] * C.block<3, 3>(3 * k, 3 * l);
    return K;
  };
  for_each_point(n, ws, [&](index_t j) {
    Mat3 K = Mat3::Zero();
    if (j < stencil_end) {
      K = contribution(j, model.d_self.col(j).data());
      if (model.hg_diagonal.size()) K.diagonal().array() += model.hg_diagonal[j];
    }
    for (index_t e = nbr.begin(j); e < nbr.end(j); ++e) {
      const index_t i = nbr.index[e];
      if (i >= stencil_end) continue;
      // the pair (i, j) in i's row (rows are sorted)
      const index_t* row = nbr.index.data();
      const index_t ij = static_cast<index_t>(std::lower_bound(row + nbr.begin(i), row + nbr.end(i), j) - row);
      K += contribution(i, model.d.col(ij).data());
    }
    blocks.col(j) = K.reshaped();
  });
}

}  // namespace pointhaptics
