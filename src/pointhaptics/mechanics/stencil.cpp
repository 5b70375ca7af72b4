#include <pointhaptics/mechanics/stencil.hpp>

#include <pointhaptics/mechanics/kernels.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <limits>

namespace pointhaptics {

double pair_weight(const Model& model, index_t i, index_t e) {
  if (!model.severed.empty() && model.severed[e]) return 0.0;
  const double r = (model.X.col(model.neighbours.index[e]) - model.X.col(i)).norm();
  return kernel_value(model.kernel.type, r, model.support.size() ? model.support[i] : model.h);
}

StencilFit assess_stencil(const Model& model, index_t i, const double* w_row, Mat3* moment) {
  const Csr& nbr = model.neighbours;
  StencilFit fit;
  Mat3 M = Mat3::Zero();
  for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) {
    const double w = w_row[e - nbr.begin(i)];
    const Vec3 xij = model.X.col(nbr.index[e]) - model.X.col(i);
    M.noalias() += w * xij * xij.transpose();
    fit.weight_sum += w;
  }
  if (M.trace() > 0) {
    Eigen::SelfAdjointEigenSolver<Mat3> eig;
    eig.computeDirect(M, Eigen::EigenvaluesOnly);
    const double lo = std::max(eig.eigenvalues()[0], 0.0), hi = eig.eigenvalues()[2];
    fit.condition = lo > 0 ? hi / lo : std::numeric_limits<double>::infinity();
    // too few or coplanar neighbours (or a stencil a cut made one-sided)
    fit.regularised = fit.condition > max_moment_condition;
  } else {
    fit.regularised = true;  // isolated: G_i = 0, the point feels no elastic force
    fit.condition = std::numeric_limits<double>::infinity();
  }
  if (moment) *moment = M;
  return fit;
}

StencilFit fit_stencil(Model& model, index_t i, const double* w_row) {
  const Csr& nbr = model.neighbours;
  Mat3 M;
  const StencilFit fit = assess_stencil(model, i, w_row, &M);
  const double trace = M.trace();
  Mat3 M_inv = Mat3::Zero();
  if (trace > 0) {
    if (fit.regularised) M += 1e-3 * trace * Mat3::Identity();  // so that cond(M) stays near 1e3
    M_inv = M.inverse();
  }
  Vec3 d_sum = Vec3::Zero();
  for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) {
    const Vec3 xij = model.X.col(nbr.index[e]) - model.X.col(i);
    const Vec3 dij = M_inv * xij * w_row[e - nbr.begin(i)];
    model.d.col(e) = dij;
    d_sum += dij;
  }
  model.d_self.col(i) = -d_sum;
  return fit;
}

}  // namespace pointhaptics
