#pragma once
/// @file The registry of materials, and a point's elastic energy: its material plus the volume term.
/// Adding a material is one file beside svk.hpp (energy_density, scaled_stress and stress, Linearisation
/// with F, linearise, stress_derivative, stiffness_block, stiffening), a value of MaterialModel with its name
/// (core/parameters.hpp), and a case in with_material() below; the force loop, the energy, the tangent, the
/// stable step and the point fields then use it, each compiled for it.
#include <pointhaptics/mechanics/energies/svk.hpp>
#include <pointhaptics/mechanics/energies/volume_penalty.hpp>

namespace pointhaptics {

/// A stencil's energy per unit volume: the material's, plus the volume penalty's.
template <class Material>
struct PointEnergy {
  Material material;
  VolumePenalty volume;

  double energy_density(const Mat3& G) const {
    return material.energy_density(G) + (volume.active() ? volume.energy_density(G) : 0.0);
  }
  /// First Piola-Kirchhoff stress P = dW/dF, Pa, times `scale` (the force loop's v_i).
  PH_ALWAYS_INLINE Mat3 scaled_stress(const Mat3& G, double scale) const {
    Mat3 P = material.scaled_stress(G, scale);
    if (volume.active()) P += scale * volume.stress(G);
    return P;
  }
  PH_ALWAYS_INLINE Mat3 stress(const Mat3& G) const { return scaled_stress(G, 1.0); }
  using Linearisation = typename Material::Linearisation;
  /// `projected`: the positive semi-definite part (the material's projection, the volume's Gauss-Newton part).
  Linearisation linearise(const Mat3& G, bool projected) const { return material.linearise(G, projected); }
  PH_ALWAYS_INLINE Mat3 stress_derivative(const Linearisation& at, const Mat3& dG, bool projected) const {
    Mat3 dP = material.stress_derivative(at, dG);
    if (volume.active()) dP += volume.stress_derivative(at.F, dG, !projected);
    return dP;
  }
  Mat3 stiffness_block(const Linearisation& at, const Vec3& d) const {
    Mat3 K = material.stiffness_block(at, d);
    if (volume.active()) K += volume.stiffness_block(at.F, d);
    return K;
  }
};

/// fn(PointEnergy<M>) with the model's material M: the one switch over materials.
template <class Fn>
decltype(auto) with_material(const Model& model, Fn&& fn) {
  const VolumePenalty volume{model.material.volume_stiffness};
  switch (model.material.model) {
    case MaterialModel::SVK: break;
  }
  return fn(PointEnergy<StVenantKirchhoff>{{model.lambda, model.mu}, volume});
}

}  // namespace pointhaptics
