#include <pointhaptics/mechanics/forces.hpp>

#include <pointhaptics/mechanics/deformation.hpp>

namespace pointhaptics {
namespace {

// forces of the stencils i in [first, last), added into the columns of f (seed Eq. 12-13, exact form)
void stencil_forces(const Model& model, const Points& u, index_t first, index_t last, Points& f) {
  const Csr& nbr = model.neighbours;
  const index_t* nbr_index = nbr.index.data();
  const double* X = model.X.data();
  const double* d = model.d.data();
  const double* hg = model.hg_coef.data();
  const double* U = u.data();
  double* out = f.data();
  const double lambda = model.lambda, mu = model.mu, kv = model.material.volume_stiffness;
  const bool hourglass = model.material.hourglass > 0;

  for (index_t i = first; i < last; ++i) {
    const index_t e0 = nbr.begin(i), e1 = nbr.end(i);
    const Vec3 ui(U + 3 * i);
    const Vec3 Xi(X + 3 * i);

    // displacement gradient, seed Eq. 10
    Mat3 G = Mat3::Zero();
    for (index_t e = e0; e < e1; ++e) {
      const Vec3 du = Vec3(U + 3 * nbr_index[e]) - ui;
      G.noalias() += du * Vec3(d + 3 * e).transpose();
    }
    // strain (seed Eq. 2), SVK stress, first Piola-Kirchhoff stress times volume
    const Mat3 F = Mat3::Identity() + G;
    const Mat3 E = 0.5 * (F.transpose() * F - Mat3::Identity());
    const Mat3 S = lambda * E.trace() * Mat3::Identity() + 2.0 * mu * E;
    const double v = model.volume[i];
    Mat3 A = v * (F * S);
    if (kv > 0) A += v * kv * (F.determinant() - 1.0) * cofactor(F);

    // zero-energy-mode penalty: A -= Q_i, self force gets sum_j c_ij r_ij
    Vec3 self = Vec3::Zero();
    if (hourglass) {
      Mat3 Q = Mat3::Zero();
      for (index_t e = e0; e < e1; ++e) {
        const index_t j = nbr_index[e];
        const Vec3 xij = Vec3(X + 3 * j) - Xi;
        const Vec3 cr = hg[e] * (Vec3(U + 3 * j) - ui - G * xij);
        Q.noalias() += cr * xij.transpose();
        self += cr;
      }
      A -= Q;
      for (index_t e = e0; e < e1; ++e) {
        const index_t j = nbr_index[e];
        const Vec3 xij = Vec3(X + 3 * j) - Xi;
        const Vec3 fj = A * Vec3(d + 3 * e) + hg[e] * (Vec3(U + 3 * j) - ui - G * xij);
        Eigen::Map<Vec3>(out + 3 * j) -= fj;
      }
    } else {
      for (index_t e = e0; e < e1; ++e)
        Eigen::Map<Vec3>(out + 3 * nbr_index[e]) -= A * Vec3(d + 3 * e);
    }
    Eigen::Map<Vec3>(out + 3 * i) += self - A * model.d_self.col(i);
  }
}

}  // namespace

void compute_internal_forces(const Model& model, const Points& u, Workspace& ws) {
  const int n_chunks = ws.n_threads();
  if (n_chunks == 1) {
    ws.f_int.setZero();
    stencil_forces(model, u, 0, model.n_points, ws.f_int);
    return;
  }
  // scatter: each chunk into its own buffer, over the columns it touches
  ws.for_each_chunk([&](int c) {
    Points& buffer = ws.chunk_forces[c];
    const index_t lo = ws.scatter_begin(c), hi = ws.scatter_end(c);
    buffer.middleCols(lo, hi - lo).setZero();
    stencil_forces(model, u, ws.chunk_begin(c), ws.chunk_end(c), buffer);
  });
  // gather: each chunk sums its own columns over every buffer that reached them
  ws.for_each_chunk([&](int c) {
    const index_t first = ws.chunk_begin(c), last = ws.chunk_end(c);
    ws.f_int.middleCols(first, last - first).setZero();
    for (int b = 0; b < n_chunks; ++b) {
      const index_t lo = std::max(first, ws.scatter_begin(b)), hi = std::min(last, ws.scatter_end(b));
      if (lo < hi) ws.f_int.middleCols(lo, hi - lo) += ws.chunk_forces[b].middleCols(lo, hi - lo);
    }
  });
}

}  // namespace pointhaptics
