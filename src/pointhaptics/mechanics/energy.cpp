#include <pointhaptics/mechanics/energy.hpp>

#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/energies/hourglass.hpp>
#include <pointhaptics/mechanics/energies/material.hpp>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/parallel_reduce.h>  // parallel_deterministic_reduce

#include <vector>

namespace pointhaptics {

namespace {

/// Point i's stencil energy (when it has one) and its hourglass pairs with j where `pair_counts(j)`, into acc.
template <class Energy, class PairCounts>
void add_point_energy(const Model& model, const Points& u, const std::vector<Mat3>& gradients, const Energy& energy,
                      index_t i, bool stencil, const PairCounts& pair_counts, EnergyTerms& acc) {
  const Csr& nbr = model.neighbours;
  const Mat3& G = gradients[i];
  // the pairs' hourglass energy; a passive point (Model::n_passive) has no elastic energy of its own, but its pairs
  // stay, since the force loop charges their derivative through the neighbour's gradient
  if (model.material.hourglass > 0)
    for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) {
      const index_t j = nbr.index[e];
      if (!pair_counts(j)) continue;
      acc.hourglass += hourglass_pair_energy(model.hg_coef[e], u.col(j) - u.col(i), G + gradients[j],
                                             model.X.col(j) - model.X.col(i));
    }
  if (!stencil || i >= model.stencil_end()) return;
  const double v = model.stiffness_volume[i];  // v_i, times E_i / E with a stiffness map
  acc.elastic += v * energy.material_energy_density(i, G);
  acc.volume += v * energy.volume.energy_density(G);
  acc.viscous += v * energy.viscous_energy_density(i, G);
}

EnergyTerms sum(EnergyTerms a, const EnergyTerms& b) {
  a.elastic += b.elastic;
  a.volume += b.volume;
  a.hourglass += b.hourglass;
  a.viscous += b.viscous;
  return a;
}

}  // namespace

EnergyTerms strain_energy(const Model& model, const Points& u, std::vector<Mat3>* scratch, const ViscousStep& step) {
  return with_material(model, step, [&](const auto& energy) {
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
          for (index_t i = range.begin(); i != range.end(); ++i)
            add_point_energy(
                model, u, gradients, energy, i, true, [](index_t) { return true; }, acc);
          return acc;
        },
        sum);
  });
}

EnergyTerms strain_energy_near(const Model& model, const Points& u, index_t ring_end, index_t gradients_end,
                               std::vector<Mat3>& gradients) {
  return with_material(model, {}, [&](const auto& energy) {
    gradients.resize(static_cast<std::size_t>(model.n_points));
    for (index_t i = 0; i < gradients_end; ++i) gradients[i] = displacement_gradient(model, u, i);
    EnergyTerms acc;
    for (index_t i = 0; i < ring_end; ++i)
      add_point_energy(
          model, u, gradients, energy, i, true, [](index_t) { return true; }, acc);
    // the second ring's pairs with the first ring
    for (index_t i = ring_end; i < gradients_end; ++i)
      add_point_energy(
          model, u, gradients, energy, i, false, [&](index_t j) { return j < ring_end; }, acc);
    return acc;
  });
}

double kinetic_energy(const Model& model, const Points& velocity) {
  return 0.5 * (velocity.colwise().squaredNorm().transpose().array() * model.mass.array()).sum();
}

}  // namespace pointhaptics
