#include <pointhaptics/mechanics/energy.hpp>

#include <pointhaptics/mechanics/deformation.hpp>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/parallel_reduce.h>

#include <vector>

namespace pointhaptics {

EnergyTerms strain_energy(const Model& model, const Points& u, std::vector<Mat3>* scratch) {
  const Csr& nbr = model.neighbours;
  const double kv = model.material.volume_stiffness;
  const bool hourglass = model.material.hourglass > 0;
  // every gradient first: the hourglass term of a pair reads both ends' gradients
  std::vector<Mat3> own;
  std::vector<Mat3>& gradients = scratch ? *scratch : own;
  gradients.resize(static_cast<std::size_t>(model.n_points));
  tbb::parallel_for(tbb::blocked_range<index_t>(0, model.n_points, 512), [&](const tbb::blocked_range<index_t>& range) {
    for (index_t i = range.begin(); i != range.end(); ++i) gradients[i] = displacement_gradient(model, u, i);  // seed Eq. 10
  });
  return tbb::parallel_reduce(
      tbb::blocked_range<index_t>(0, model.n_points, 512), EnergyTerms{},
      [&](const tbb::blocked_range<index_t>& range, EnergyTerms acc) {
        for (index_t i = range.begin(); i != range.end(); ++i) {
          const Mat3& G = gradients[i];
          if (i >= model.stencil_end()) {
            // a passive point (Model::n_passive): no elastic energy of its own, but its hourglass pairs stay,
            // since the force loop charges their derivative through the neighbour's gradient to that neighbour
            for (index_t e = nbr.begin(i); hourglass && e < nbr.end(i); ++e) {
              const index_t j = nbr.index[e];
              const Vec3 r = u.col(j) - u.col(i) - 0.5 * (G + gradients[j]) * (model.X.col(j) - model.X.col(i));
              acc.hourglass += 0.5 * model.hg_coef[e] * r.squaredNorm();
            }
            continue;
          }
          const Mat3 F = Mat3::Identity() + G;
          const Mat3 E = green_strain(G);  // seed Eq. 2
          const Mat3 S = svk_stress(E, model.lambda, model.mu);
          const double v = model.volume[i];
          acc.elastic += v * 0.5 * (S.array() * E.array()).sum();
          const double J = F.determinant();
          acc.volume += 0.5 * kv * v * (J - 1) * (J - 1);
          if (!hourglass) continue;
          for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) {
            const index_t j = nbr.index[e];
            const Vec3 r = u.col(j) - u.col(i) - 0.5 * (G + gradients[j]) * (model.X.col(j) - model.X.col(i));
            acc.hourglass += 0.5 * model.hg_coef[e] * r.squaredNorm();
          }
        }
        return acc;
      },
      [](EnergyTerms a, const EnergyTerms& b) {
        a.elastic += b.elastic;
        a.volume += b.volume;
        a.hourglass += b.hourglass;
        return a;
      });
}

double kinetic_energy(const Model& model, const Points& velocity) {
  return 0.5 * (velocity.colwise().squaredNorm().transpose().array() * model.mass.array()).sum();
}

}  // namespace pointhaptics
