#include <pointhaptics/mechanics/tangent.hpp>

#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/detail/linearisation_store.hpp>
#include <pointhaptics/mechanics/energies/material.hpp>
#include <pointhaptics/mechanics/viscoelasticity.hpp>

namespace pointhaptics {

using detail::doubles_of;
using detail::for_each_point;

void Tangent::linearise(const Model& model, const Points& u, TangentMode mode, Workspace* ws) {
  mode_ = mode;
  with_material(model, ws ? viscous_step(*ws) : ViscousStep{}, [&](const auto& energy) {
    using L = typename std::decay_t<decltype(energy)>::Linearisation;
    linearisation_.resize(doubles_of<L> * static_cast<std::size_t>(model.n_points));
    double* base = linearisation_.data();
    for_each_point(model.n_points, ws, [&](index_t i) {
      const L at =
          energy.linearise(i, displacement_gradient(model, u, i), mode == TangentMode::PROJECTED);  // seed Eq. 10
      detail::store_linearisation(base, i, at);
    });
  });
}

}  // namespace pointhaptics
