#include <pointhaptics/mechanics/forces.hpp>

#include <pointhaptics/mechanics/detail/stencil_loop.hpp>
#include <pointhaptics/mechanics/energies/material.hpp>
#include <pointhaptics/mechanics/viscoelasticity.hpp>

namespace pointhaptics {
namespace {

// seed Eq. 12-13 in exact form: the stencil's stress A_i = v_i P_i(G_i), F = I + G (Eq. 2). A function
// template per energy rather than a generic lambda: GCC inlined the loop less well inside the latter.
template <class Energy>
void internal_forces_of(const Energy energy, const Model& model, const Points& u, Workspace& ws) {
  const double* volume = model.stiffness_volume.data();  // v_i, times E_i / E with a stiffness map
  // the stress map captures by value: the material's constants stay in registers while the loop writes forces
  detail::stencil_sum(model, u, ws, ws.f_int, 1.0,
                      [energy, volume](index_t i, const Mat3& G) PH_ALWAYS_INLINE -> Mat3 { return energy.scaled_stress(i, G, volume[i]); });
}

}  // namespace

void compute_internal_forces(const Model& model, const Points& u, Workspace& ws) {
  with_material(model, viscous_step(ws), [&](const auto& energy) { internal_forces_of(energy, model, u, ws); });
}

}  // namespace pointhaptics
