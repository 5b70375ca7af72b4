#include <pointhaptics/mechanics/energy.hpp>

#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/energies/hourglass.hpp>
#include <pointhaptics/mechanics/energies/material.hpp>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/parallel_reduce.h>  // parallel_deterministic_reduce

#include <vector>

namespace pointhaptics {

EnergyTerms strain_energy(const Model& model, const Points& u, std::vector<Mat3>* scratch, const ViscousStep& step) {
  return with_material(model, step, [&](const auto& energy) {
    const Csr& nbr = model.neighbours;
    const bool hourglass = model.material.hourglass > 0;
    // every gradient first: the hourglass term of a pair reads both ends' gradients
    std::vector<Mat3> own;
    std::vector<Mat3>& gradients = scratch ? *scratch : own;
    gradients.resize(static_cast<std::size_t>(model.n_points));
    tbb::parallel_for(tbb::blocked_range<index_t>(0, model.n_points, 512),
                      [&](const tbb::blocked_range<index_t>& range) {
                        for (index_t i = range.begin(); i != range.end(); ++i)
                          gradients[i] = displacement_gradient(model, u, i);  // seed Eq. 10
                      });
    // deterministic: the same split at every run, so the same sum (line searches compare energies)
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<index_t>(0, model.n_points, 512), EnergyTerms{},
        [&](const tbb::blocked_range<index_t>& range, EnergyTerms acc) {
          for (index_t i = range.begin(); i != range.end(); ++i) {
            const Mat3& G = gradients[i];
            // the pairs' hourglass energy; a passive point (Model::n_passive) has no elastic energy of its own,
            // but its pairs stay, since the force loop charges their derivative through the neighbour's gradient
            for (index_t e = nbr.begin(i); hourglass && e < nbr.end(i); ++e) {
              const index_t j = nbr.index[e];
              acc.hourglass += hourglass_pair_energy(model.hg_coef[e], u.col(j) - u.col(i), G + gradients[j],
                                                     model.X.col(j) - model.X.col(i));
            }
            if (i >= model.stencil_end()) continue;
            const double v = model.stiffness_volume[i];  // v_i, times E_i / E with a stiffness map
            acc.elastic += v * energy.material_energy_density(i, G);
            acc.volume += v * energy.volume.energy_density(G);
            acc.viscous += v * energy.viscous_energy_density(i, G);
          }
          return acc;
        },
        [](EnergyTerms a, const EnergyTerms& b) {
          a.elastic += b.elastic;
          a.volume += b.volume;
          a.hourglass += b.hourglass;
          a.viscous += b.viscous;
          return a;
        });
  });
}

double kinetic_energy(const Model& model, const Points& velocity) {
  return 0.5 * (velocity.colwise().squaredNorm().transpose().array() * model.mass.array()).sum();
}

}  // namespace pointhaptics
