#include <pointhaptics/reduction/svk_polynomial.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/core/run_control.hpp>
#include <pointhaptics/mechanics/tangent.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

namespace pointhaptics {
namespace {

/// Index of the pair (k, l), k <= l, in the packed upper triangle (row by row).
struct Pairs {
  int r;
  int operator()(int k, int l) const {
    if (k > l) std::swap(k, l);
    return k * r - k * (k - 1) / 2 + (l - k);
  }
  int count() const { return r * (r + 1) / 2; }
};

/// The symmetric 3x3 X as a 6-vector x^ with x^ . y^ = <X, Y> = 2 mu X:Y + lambda tr X tr Y: Voigt's
/// (X00, X11, X22, X01, X12, X20) times L^T, L the Cholesky factor of the metric.
class Metric {
 public:
  Metric(double lambda, double mu) {
    Eigen::Matrix<double, 6, 6> D = Eigen::Matrix<double, 6, 6>::Zero();
    D.topLeftCorner<3, 3>().setConstant(lambda);
    for (int a = 0; a < 3; ++a) D(a, a) += 2 * mu;
    for (int a = 3; a < 6; ++a) D(a, a) = 4 * mu;  // off-diagonal entries count twice in X:Y
    upper_ = Eigen::LLT<Eigen::Matrix<double, 6, 6>>(D).matrixU();
  }
  /// Voigt entries of the symmetric matrix, then the factor
  template <class V>
  Eigen::Matrix<double, 6, 1> operator()(const V& voigt) const {
    return upper_ * voigt;
  }

 private:
  Eigen::Matrix<double, 6, 6> upper_;
};

}  // namespace

SvkPolynomial::SvkPolynomial(const Model& model, const Eigen::MatrixXd& U, Workspace& ws) {
  const auto start = std::chrono::steady_clock::now();
  if (model.material.model != MaterialModel::SVK)
    throw Error(
        "reduction.forces = \"polynomial\": the material must be St. Venant-Kirchhoff (model = \"svk\"), whose "
        "energy is a polynomial in the displacement");
  if (!model.material_of.empty())
    throw Error("reduction.forces = \"polynomial\": not with points of several materials ([[region]] tables)");
  if (model.material.volume_stiffness > 0)
    throw Error(
        "reduction.forces = \"polynomial\": not with material.volume_stiffness > 0 (its (det F - 1)^2 is not "
        "a quartic)");
  if (!model.material.prony.empty())
    throw Error("reduction.forces = \"polynomial\": not with a viscoelastic material (material.prony)");
  if (U.rows() != 3 * model.n_points || U.cols() < 1)
    throw Error(fmt::format("reduction: a basis of {} rows for {} points", U.rows(), model.n_points));
  r_ = static_cast<int>(U.cols());
  const Pairs pair{r_};
  pairs_ = pair.count();
  const Metric metric(model.lambda, model.mu);

  // A = U^T K U at rest, through the exact matrix-free tangent (the hourglass penalty included)
  {
    Tangent rest;
    rest.linearise(model, Points::Zero(3, model.n_points), TangentMode::EXACT, &ws);
    Points column(3, model.n_points), image(3, model.n_points);
    A_.resize(r_, r_);
    for (int k = 0; k < r_; ++k) {
      column = Eigen::Map<const Points>(U.col(k).data(), 3, model.n_points);
      rest.apply(model, column, ws, image);
      A_.col(k) = U.transpose() * Eigen::Map<const Eigen::VectorXd>(image.data(), image.size());
    }
    A_ = 0.5 * (A_ + A_.transpose()).eval();
  }

  // the Gram tables of e and h over the points, in blocks of points, per chunk of the workspace's (fixed point
  // ranges, summed in their order: the tables are the same to the bit whatever the threads did)
  struct Sums {
    Eigen::MatrixXd hh, eh;
    double largest_gradients = 0;  ///< max_p sum_k |G_pk|_F^2 (gradient_bound())
  };
  std::vector<Sums> sums(static_cast<std::size_t>(ws.n_threads()),
                         Sums{Eigen::MatrixXd::Zero(pairs_, pairs_), Eigen::MatrixXd::Zero(r_, pairs_), 0.0});
  constexpr index_t block = 64;
  const index_t n_stencils = model.stencil_end();
  ws.for_each_chunk([&](int chunk) {
    Sums& s = sums[static_cast<std::size_t>(chunk)];
    const index_t chunk_end = std::min(ws.chunk_end(chunk), n_stencils);
    for (index_t first = ws.chunk_begin(chunk); first < chunk_end; first += block) {
      throw_if_stop_requested("reduction (the polynomial's tables)");
      const index_t last = std::min(first + block, chunk_end);
      const index_t n = last - first;
      Eigen::MatrixXd e_hat(6 * n, r_), h_hat(6 * n, pairs_);
      Eigen::Matrix<double, 9, Eigen::Dynamic> G(9, r_);  // vec(G_k) per column (column-major 3x3)
      for (index_t i = first; i < last; ++i) {
        G.setZero();
        for (index_t e = model.neighbours.begin(i); e < model.neighbours.end(i); ++e) {
          const index_t j = model.neighbours.index[e];
          const auto du = (U.middleRows<3>(3 * j) - U.middleRows<3>(3 * i)).eval();  // 3 x r
          for (int c = 0; c < 3; ++c) G.middleRows<3>(3 * c) += model.d(c, e) * du;
        }
        s.largest_gradients = std::max(s.largest_gradients, G.squaredNorm());
        const double scale = std::sqrt(model.stiffness_volume[i]);
        const index_t row = 6 * (i - first);
        for (int k = 0; k < r_; ++k) {
          const auto g = [&](int a, int b) { return G(3 * b + a, k); };  // (G_k)_ab
          Eigen::Matrix<double, 6, 1> voigt;
          voigt << g(0, 0), g(1, 1), g(2, 2), 0.5 * (g(0, 1) + g(1, 0)), 0.5 * (g(1, 2) + g(2, 1)),
              0.5 * (g(2, 0) + g(0, 2));
          e_hat.block<6, 1>(row, k) = scale * metric(voigt);
        }
        // h_kl = sym(G_k^T G_l): (G_k^T G_l)_ab = column a of G_k . column b of G_l
        for (int k = 0; k < r_; ++k)
          for (int l = k; l < r_; ++l) {
            const auto dot = [&](int a, int b) { return G.block<3, 1>(3 * a, k).dot(G.block<3, 1>(3 * b, l)); };
            Eigen::Matrix<double, 6, 1> voigt;
            voigt << dot(0, 0), dot(1, 1), dot(2, 2), 0.5 * (dot(0, 1) + dot(1, 0)), 0.5 * (dot(1, 2) + dot(2, 1)),
                0.5 * (dot(2, 0) + dot(0, 2));
            h_hat.block<6, 1>(row, pair(k, l)) = scale * metric(voigt);
          }
      }
      s.hh.selfadjointView<Eigen::Lower>().rankUpdate(h_hat.transpose());
      s.eh.noalias() += e_hat.transpose() * h_hat;
    }
  });
  Eigen::MatrixXd hh = Eigen::MatrixXd::Zero(pairs_, pairs_), eh = Eigen::MatrixXd::Zero(r_, pairs_);
  for (const Sums& s : sums) {
    hh += s.hh;
    eh += s.eh;
    gradient_bound_ = std::max(gradient_bound_, std::sqrt(s.largest_gradients));
  }
  hh = hh.selfadjointView<Eigen::Lower>();

  b_.resize(pairs_, r_);
  c_.resize(pairs_, pairs_);
  for (int k = 0; k < r_; ++k)
    for (int l = k; l < r_; ++l) {
      const int kl = pair(k, l);
      for (int m = 0; m < r_; ++m) b_(kl, m) = eh(k, pair(l, m)) + eh(l, pair(k, m)) + eh(m, kl);
      for (int m = 0; m < r_; ++m)
        for (int n = m; n < r_; ++n)
          c_(kl, pair(m, n)) = hh(kl, pair(m, n)) + hh(pair(k, m), pair(l, n)) + hh(pair(k, n), pair(l, m));
    }
  w_.resize(pairs_);
  bq_.resize(pairs_);
  cq_.resize(pairs_);
  B_.resize(r_, r_);
  C_.resize(r_, r_);
  build_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void SvkPolynomial::contract(const Eigen::VectorXd& q) const {
  // w_mn = q_m q_n, counted twice off the diagonal (the table holds m <= n only)
  int p = 0;
  for (int m = 0; m < r_; ++m) {
    w_[p++] = q[m] * q[m];
    for (int n = m + 1; n < r_; ++n) w_[p++] = 2 * q[m] * q[n];
  }
  bq_.noalias() = b_ * q;
  // c is symmetric (c_klmn = c_mnkl): half of it is read, which halves the memory traffic of the largest table
  cq_.noalias() = c_.selfadjointView<Eigen::Lower>() * w_;
  p = 0;
  for (int k = 0; k < r_; ++k)
    for (int l = k; l < r_; ++l, ++p) {
      B_(k, l) = B_(l, k) = bq_[p];
      C_(k, l) = C_(l, k) = cq_[p];
    }
}

double SvkPolynomial::energy(const Eigen::VectorXd& q) const {
  contract(q);
  // through kept scratch: a product inside a dot would allocate its temporary
  bq_.head(r_).noalias() = A_ * q;
  bq_.head(r_).noalias() += (1.0 / 3.0) * (B_ * q);
  bq_.head(r_).noalias() += (1.0 / 12.0) * (C_ * q);
  return 0.5 * q.dot(bq_.head(r_));
}

void SvkPolynomial::evaluate(const Eigen::VectorXd& q, Eigen::VectorXd& gradient, Eigen::MatrixXd* hessian,
                             double* energy) const {
  contract(q);
  // the three orders' terms apart first (kept scratch): the energy weighs them 1/2, 1/6, 1/24, the gradient 1,
  // 1/2, 1/6
  auto aq = bq_.head(r_), bq = cq_.head(r_), cq = w_.head(r_);
  aq.noalias() = A_ * q;
  bq.noalias() = B_ * q;
  cq.noalias() = C_ * q;
  if (energy) *energy = q.dot(0.5 * aq + (1.0 / 6.0) * bq + (1.0 / 24.0) * cq);
  gradient = aq + 0.5 * bq + (1.0 / 6.0) * cq;
  if (hessian) {
    *hessian = A_;
    *hessian += B_;
    *hessian += 0.5 * C_;
  }
}

double SvkPolynomial::bytes() const {
  return 8.0 * static_cast<double>(A_.size() + b_.size() + c_.size() + B_.size() + C_.size() + w_.size() + bq_.size() +
                                   cq_.size());
}

}  // namespace pointhaptics
