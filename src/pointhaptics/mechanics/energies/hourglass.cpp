#include <pointhaptics/mechanics/energies/hourglass.hpp>

#include <pointhaptics/mechanics/kernels.hpp>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/enumerable_thread_specific.h>
#include <oneapi/tbb/parallel_for.h>

#include <cmath>

namespace pointhaptics {

void build_hourglass(Model& model, const Eigen::VectorXd& w, const std::vector<double>& weight_sum) {
  const Csr& nbr = model.neighbours;
  const index_t n = model.n_points;
  // each end's share carries its own Young's modulus (per-point materials): a stiff inclusion's pairs are stiff
  const double scale = 0.5 * model.material.hourglass;
  auto share = [&](index_t i) { return weight_sum[i] > 0 ? model.young_at(i) * model.volume[i] / weight_sum[i] : 0.0; };
  const bool per_point = model.support.size() == n;
  for (index_t i = 0; i < n; ++i)
    for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) {
      const index_t j = nbr.index[e];
      const double r2 = (model.X.col(j) - model.X.col(i)).squaredNorm();
      // w_ji from j's own support (equal to w_ij with one support for all), so that k_ij = k_ji
      const double w_ji = per_point ? kernel_value(model.kernel.type, std::sqrt(r2), model.support[j]) : w[e];
      model.hg_coef[e] = scale * (w[e] * share(i) + w_ji * share(j)) / r2;
    }
  model.hg_diagonal = Eigen::VectorXd::Zero(n);
  if (!(model.material.hourglass > 0)) return;
  // in parallel over stencils (it took a sixth of a 10^6-point set-up serially): each thread accumulates its
  // own diagonal, summed at the end (no atomics)
  struct Scratch {
    std::vector<double> weight, diagonal;
    std::vector<index_t> touched;
  };
  tbb::enumerable_thread_specific<Scratch> scratch([n] { return Scratch{std::vector<double>(n, 0.0), std::vector<double>(n, 0.0), {}}; });
  tbb::parallel_for(tbb::blocked_range<index_t>(0, n, 2048), [&](const tbb::blocked_range<index_t>& range) {
    Scratch& local = scratch.local();
    std::vector<double>& weight = local.weight;
    std::vector<index_t>& touched = local.touched;
    for (index_t i = range.begin(); i != range.end(); ++i)
      for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) {
        const index_t j = nbr.index[e];
        const Vec3 xij = model.X.col(j) - model.X.col(i);
        auto add = [&](index_t m, double value) {
          if (weight[m] == 0.0) touched.push_back(m);
          weight[m] += value;
        };
        add(j, 1.0);
        add(i, -1.0);
        for (index_t s : {i, j}) {  // the two gradients G_i and G_j
          add(s, -0.5 * model.d_self.col(s).dot(xij));
          for (index_t f = nbr.begin(s); f < nbr.end(s); ++f) add(nbr.index[f], -0.5 * model.d.col(f).dot(xij));
        }
        for (index_t m : touched) {
          local.diagonal[m] += model.hg_coef[e] * weight[m] * weight[m];
          weight[m] = 0.0;
        }
        touched.clear();
      }
  });
  for (const Scratch& local : scratch)
    model.hg_diagonal += Eigen::Map<const Eigen::VectorXd>(local.diagonal.data(), n);
}


}  // namespace pointhaptics
