#include <pointhaptics/mechanics/forces.hpp>

#include <pointhaptics/mechanics/detail/stencil_loop.hpp>
#include <pointhaptics/mechanics/energies/material.hpp>

namespace pointhaptics {

void compute_internal_forces(const Model& model, const Points& u, Workspace& ws) {
  const double* volume = model.volume.data();
  // seed Eq. 12-13 in exact form: the stencil's stress A_i = v_i P_i(G_i), F = I + G (Eq. 2)
  // the stress map captures by value: the material's constants stay in registers while the loop writes forces
  with_material(model, [&](const auto& energy) {
    detail::stencil_sum(model, u, ws, ws.f_int, 1.0,
                        [energy, volume](index_t i, const Mat3& G) PH_ALWAYS_INLINE -> Mat3 { return energy.scaled_stress(G, volume[i]); });
  });
}

}  // namespace pointhaptics
