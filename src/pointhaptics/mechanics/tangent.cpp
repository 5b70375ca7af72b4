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

}  // namespace

void Tangent::linearise(const Model& model, const Points& u, TangentMode mode) {
  mode_ = mode;
  F_.resize(9, model.n_points);
  S_.resize(9, model.n_points);
  tbb::parallel_for(tbb::blocked_range<index_t>(0, model.n_points, 256), [&](const tbb::blocked_range<index_t>& r) {
    for (index_t i = r.begin(); i != r.end(); ++i) {
      const Mat3 G = displacement_gradient(model, u, i);                   // seed Eq. 10
      const Mat3 F = Mat3::Identity() + G;
      const Mat3 S = svk_stress(green_strain(G), model.lambda, model.mu);  // seed Eq. 2
      F_.col(i) = F.reshaped();
      S_.col(i) = (mode == TangentMode::PROJECTED ? positive_part(S) : S).reshaped();
    }
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

void Tangent::diagonal_blocks(const Model& model, Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks) const {
  const double lambda = model.lambda, mu = model.mu, kv = model.material.volume_stiffness;
  const bool exact = mode_ == TangentMode::EXACT;
  const Csr& nbr = model.neighbours;
  blocks.setZero(9, model.n_points);
  using Mat9 = Eigen::Matrix<double, 9, 9>;
  // block of the pair (i, j) with weight vector d: sum_{k,l} C[a + 3k][b + 3l] d_k d_l, C = d(v P)/dG
  auto add_block = [&blocks](index_t j, const Mat9& C, const Vec3& d, double hourglass_diagonal) {
    Mat3 K = Mat3::Zero();
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) K += d[k] * d[l] * C.block<3, 3>(3 * k, 3 * l);
    K.diagonal().array() += hourglass_diagonal;
    blocks.col(j) += K.reshaped();
  };
  // serial: stencils scatter into shared points; about two force evaluations in cost
  for (index_t i = 0; i < model.stencil_end(); ++i) {
    const Mat3 F = Eigen::Map<const Mat3>(F_.data() + 9 * i), S = Eigen::Map<const Mat3>(S_.data() + 9 * i);
    Mat9 C;
    for (int col = 0; col < 9; ++col) {
      Mat3 unit = Mat3::Zero();
      unit.data()[col] = 1.0;
      C.col(col) = stress_increment(F, S, unit, model.volume[i], lambda, mu, kv, exact).reshaped();
    }
    // the hourglass part is constant and precomputed in the model (model_builder.cpp)
    for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) add_block(nbr.index[e], C, model.d.col(e), 0.0);
    add_block(i, C, model.d_self.col(i), model.hg_diagonal.size() ? model.hg_diagonal[i] : 0.0);
  }
}

}  // namespace pointhaptics
