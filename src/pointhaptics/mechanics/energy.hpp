#pragma once
/// @file The total elastic energy of a displacement field, term by term (independent of the force code).
#include <pointhaptics/core/model.hpp>
#include <pointhaptics/mechanics/energies/viscous_overstress.hpp>

#include <vector>

namespace pointhaptics {

struct EnergyTerms {
  double elastic = 0;    ///< sum_i v_i 0.5 S_i : E_i (St. Venant-Kirchhoff), J
  double volume = 0;     ///< sum_i 0.5 k_v v_i (det F_i - 1)^2, J
  double hourglass = 0;  ///< zero-energy-mode penalty (physics.md), J
  double viscous =
      0;  ///< within a viscoelastic step: the overstress's term -sum_i v_i H_i : E_i, J (not stored energy)
  double total() const { return elastic + volume + hourglass + viscous; }
};

/// The strain energy W(u) whose exact negative gradient compute_internal_forces() returns. `gradients`:
/// scratch for every point's G_i (resized to n, so a caller that keeps it allocates once); without it the
/// call allocates its own. `step`: within a viscoelastic step, the energy that step minimises (relaxed shear
/// modulus and overstress; viscoelasticity.hpp); by default the elastic one.
EnergyTerms strain_energy(const Model& model, const Points& u, std::vector<Mat3>* gradients = nullptr,
                          const ViscousStep& step = {});

/// The part of strain_energy() that moves with a model's free points, for a model ordered by neighbour rings around
/// them (model_patch.hpp: the free points, then each held ring): the stencils in [0, ring_end) (the free points and
/// their first ring), and the hourglass pairs with an end there, whose other end's gradient reaches to
/// gradients_end (the second ring's end). The rest of the energy does not change as the free points move, so this
/// part changes as the whole does (ContactPatch's energy, at a fraction of the cost: a patch's outer rings hold
/// half its points and most of its pairs). On the calling thread (a patch of a few thousand points: handing chunks
/// between threads cost more than it saved); `gradients`: scratch, as above (its entries beyond gradients_end are
/// left as they were).
EnergyTerms strain_energy_near(const Model& model, const Points& u, index_t ring_end, index_t gradients_end,
                               std::vector<Mat3>& gradients);

/// Kinetic energy 0.5 sum_i m_i |v_i|^2, J.
double kinetic_energy(const Model& model, const Points& velocity);

}  // namespace pointhaptics
