#include <pointhaptics/mechanics/tangent.hpp>

#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/detail/stencil_loop.hpp>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

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
  const Csr& nbr = model.neighbours;
  const index_t n = model.n_points, stencil_end = model.stencil_end();
  blocks.resize(9, n);
  // A unit displacement of point j along e_b changes stencil i's gradient by dG = e_b d^T (d = d_ij, or d_ii
  // for j = i), and j's force by -v_i dP(dG) d. With dE = sym(F^T dG) and g = F d, h = cof(F) d:
  //   dG S d = (d^T S d) e_b,  F (lambda tr(dE) I + 2 mu dE) d = (lambda + mu) g_b g + mu |d|^2 F F^T e_b,
  //   (cof F : dG) cof F d = h_b h,  and d(cof F)[e_b d^T] d = 0 (each row is a cross product with d),
  // so the block is v_i ((lambda + mu) g g^T + mu |d|^2 F F^T + (d^T S d) I + k_v h h^T), in either mode
  // (S_ holds the positive part of S when PROJECTED). Per stencil: F F^T and cof F.
  stencil_factors_.resize(18, stencil_end);
  for_each_point(stencil_end, ws, [&](index_t i) {
    const Eigen::Map<const Mat3> F(F_.data() + 9 * i);
    stencil_factors_.col(i).head<9>() = (F * F.transpose()).reshaped();
    stencil_factors_.col(i).tail<9>() = cofactor(F).reshaped();
  });
  auto contribution = [&](index_t i, const Vec3& d) {
    const Eigen::Map<const Mat3> F(F_.data() + 9 * i), S(S_.data() + 9 * i);
    const Eigen::Map<const Mat3> FFt(stencil_factors_.col(i).data()), cof(stencil_factors_.col(i).data() + 9);
    const Vec3 g = F * d;
    Mat3 K = (lambda + mu) * g * g.transpose() + (mu * d.squaredNorm()) * FFt;
    K.diagonal().array() += d.dot(S * d);
    if (kv > 0) {
      const Vec3 h = cof * d;
      K += kv * h * h.transpose();
    }
    return Mat3(model.volume[i] * K);
  };
  // gathered per j over the stencils that reach it (neighbourhoods are symmetric), so no two threads write
  // one block. The hourglass part is constant and precomputed in the model (model_builder.cpp).
  for_each_point(n, ws, [&](index_t j) {
    Mat3 K = Mat3::Zero();
    if (j < stencil_end) {
      K = contribution(j, model.d_self.col(j));
      if (model.hg_diagonal.size()) K.diagonal().array() += model.hg_diagonal[j];
    }
    for (index_t e = nbr.begin(j); e < nbr.end(j); ++e) {
      const index_t i = nbr.index[e];
      if (i >= stencil_end) continue;
      K += contribution(i, model.d.col(model.reverse_pair[e]));  // d_ij of the pair (i, j) in i's row
    }
    blocks.col(j) = K.reshaped();
  });
}

}  // namespace pointhaptics
