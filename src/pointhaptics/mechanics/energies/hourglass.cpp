#include <pointhaptics/mechanics/energies/hourglass.hpp>

#include <pointhaptics/core/polled_loop.hpp>
#include <pointhaptics/mechanics/stencil.hpp>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include <cmath>

namespace pointhaptics {

namespace {

/// Scratch for one pair's weights over the points of its two stencils.
struct PairWeights {
  std::vector<double> weight;
  std::vector<index_t> touched;
};

/// Adds sign x k_e (weight of u_m in r_e)^2 to diagonal[m] for every m pair e = (i, j) reaches (hourglass.hpp).
void add_pair_diagonal(const Model& model, index_t i, index_t e, double sign, PairWeights& scratch, double* diagonal) {
  const Csr& nbr = model.neighbours;
  const index_t j = nbr.index[e];
  const Vec3 xij = model.X.col(j) - model.X.col(i);
  auto add = [&](index_t m, double value) {
    if (scratch.weight[m] == 0.0) scratch.touched.push_back(m);
    scratch.weight[m] += value;
  };
  add(j, 1.0);
  add(i, -1.0);
  for (index_t s : {i, j}) {  // the two gradients G_i and G_j
    add(s, -0.5 * model.d_self.col(s).dot(xij));
    for (index_t f = nbr.begin(s); f < nbr.end(s); ++f) add(nbr.index[f], -0.5 * model.d.col(f).dot(xij));
  }
  for (index_t m : scratch.touched) {
    diagonal[m] += sign * model.hg_coef[e] * scratch.weight[m] * scratch.weight[m];
    scratch.weight[m] = 0.0;
  }
  scratch.touched.clear();
}

}  // namespace

double hourglass_coefficient(const Model& model, index_t i, index_t e, double weight_sum_i, double weight_sum_j) {
  const index_t j = model.neighbours.index[e];
  // each end's share carries its own Young's modulus (per-point materials): a stiff inclusion's pairs are stiff
  auto share = [&](index_t p, double weight_sum) {
    return weight_sum > 0 ? model.young_at(p) * model.volume[p] / weight_sum : 0.0;
  };
  const double r2 = (model.X.col(j) - model.X.col(i)).squaredNorm();
  // w_ji from j's own support (equal to w_ij with one support for all), so that k_ij = k_ji
  return 0.5 * model.material.hourglass *
         (pair_weight(model, i, e) * share(i, weight_sum_i) +
          pair_weight(model, j, model.reverse_pair[e]) * share(j, weight_sum_j)) /
         r2;
}

void build_hourglass(Model& model, const std::vector<double>& weight_sum) {
  const Csr& nbr = model.neighbours;
  const index_t n = model.n_points;
  // k_ji = k_ij to the bit (the formula is symmetric term by term), so each pair is computed once, from its
  // lower end, and copied to its reverse: no two iterations write one slot
  parallel_for_polled("the hourglass coefficients", n, [&](index_t i) {
    for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) {
      const index_t j = nbr.index[e];
      if (j < i) continue;
      model.hg_coef[e] = hourglass_coefficient(model, i, e, weight_sum[i], weight_sum[j]);
      model.hg_coef[model.reverse_pair[e]] = model.hg_coef[e];
    }
  });
  model.hg_diagonal = Eigen::VectorXd::Zero(n);
  if (!(model.material.hourglass > 0)) return;
  // in parallel over stencils (it took a sixth of a 10^6-point set-up serially): each of a fixed number of
  // blocks of points accumulates its own diagonal, summed in block order at the end (no atomics; per thread,
  // the sum's order followed the scheduler, and a run differed from the last in the last digit, which a
  // chaotic contact then grew to millimetres)
  constexpr index_t blocks = 8;
  std::vector<Eigen::VectorXd> diagonals(static_cast<std::size_t>(blocks));
  Progress progress("the hourglass diagonal", n);
  tbb::parallel_for(index_t{0}, blocks, [&](index_t b) {
    Eigen::VectorXd& diagonal = diagonals[static_cast<std::size_t>(b)];
    diagonal = Eigen::VectorXd::Zero(n);
    PairWeights pair{std::vector<double>(n, 0.0), {}};
    for (index_t i = b * n / blocks; i < (b + 1) * n / blocks; ++i) {
      progress.advance();
      // r_ji = -r_ij and k_ji = k_ij, so a pair's reverse adds the same squares: each pair once, twice over
      for (index_t e = nbr.begin(i); e < nbr.end(i); ++e)
        if (nbr.index[e] > i) add_pair_diagonal(model, i, e, 2.0, pair, diagonal.data());
    }
  });
  for (const Eigen::VectorXd& diagonal : diagonals) model.hg_diagonal += diagonal;
}

void add_hourglass_diagonal(const Model& model, const std::vector<std::pair<index_t, index_t>>& pairs, double sign,
                            Eigen::VectorXd& diagonal) {
  if (!(model.material.hourglass > 0)) return;
  PairWeights scratch{std::vector<double>(model.n_points, 0.0), {}};
  for (const auto& [i, e] : pairs) add_pair_diagonal(model, i, e, sign, scratch, diagonal.data());
}

}  // namespace pointhaptics
