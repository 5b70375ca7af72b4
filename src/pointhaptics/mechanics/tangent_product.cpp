#include <pointhaptics/mechanics/tangent.hpp>

#include <pointhaptics/mechanics/detail/linearisation_store.hpp>
#include <pointhaptics/mechanics/detail/stencil_loop.hpp>
#include <pointhaptics/mechanics/energies/material.hpp>
#include <pointhaptics/mechanics/viscoelasticity.hpp>

// The tangent's product K du (Newton-CG's inner loop), in a file apart from the linearisation and the
// preconditioners' blocks: the stencil loop instantiated for every material took most of tangent.cpp's 29 s
// at -O3.
namespace pointhaptics {

using detail::load_linearisation;

void Tangent::apply(const Model& model, const Points& du, Workspace& ws, Points& out) const {
  const bool projected = mode_ == TangentMode::PROJECTED;
  const double* volume = model.stiffness_volume.data();  // v_i, times E_i / E with a stiffness map
  const double* base = linearisation_.data();
  with_material(model, viscous_step(ws), [&](const auto& energy) {
    using L = typename std::decay_t<decltype(energy)>::Linearisation;
    // the force loop with the stress map linearised gives -K du; the hourglass part is linear already
    detail::stencil_sum(model, du, ws, out, -1.0,
                        [energy, volume, base, projected](index_t i, const Mat3& dG) PH_ALWAYS_INLINE -> Mat3 {
                          return volume[i] * energy.stress_derivative(i, load_linearisation<L>(base, i), dG, projected);
                        });
  });
}

}  // namespace pointhaptics
