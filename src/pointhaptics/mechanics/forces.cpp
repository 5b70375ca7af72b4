#include <pointhaptics/mechanics/forces.hpp>

#include <pointhaptics/mechanics/detail/stencil_loop.hpp>
#include <pointhaptics/mechanics/energies/material.hpp>
#include <pointhaptics/mechanics/viscoelasticity.hpp>

namespace pointhaptics {
namespace {

// seed Eq. 12-13 in exact form: the stencil's stress A_i = v_i P_i(G_i), F = I + G (Eq. 2), for one point or
// four at once (lanes.hpp). Held by value: the material's constants stay in registers while the loop
// writes forces.
template <class Energy>
struct ScaledStress {
  Energy energy;
  const double* volume;  ///< v_i, times E_i / E with a stiffness map

  PH_ALWAYS_INLINE Mat3 operator()(index_t i, const Mat3& G) const { return energy.scaled_stress(i, G, volume[i]); }
  PH_ALWAYS_INLINE Matrix3<Lanes> operator()(index_t i, int count, const Matrix3<Lanes>& G) const {
    Lanes scale = {};
    for (int p = 0; p < count; ++p) scale[p] = volume[i + p];
    return energy.scaled_stress(i, count, G, scale);
  }
};

template <class Energy>
void internal_forces_of(const Energy& energy, const Model& model, const Points& u, Workspace& ws) {
  detail::stencil_sum(model, u, ws, ws.f_int, 1.0, ScaledStress<Energy>{energy, model.stiffness_volume.data()});
}

}  // namespace

void compute_internal_forces(const Model& model, const Points& u, Workspace& ws) {
  with_material(model, viscous_step(ws), [&](const auto& energy) { internal_forces_of(energy, model, u, ws); });
}

}  // namespace pointhaptics
