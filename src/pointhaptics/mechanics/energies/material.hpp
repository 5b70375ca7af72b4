#pragma once
/// @file The registry of materials, and a point's elastic energy: its material plus the volume term.
/// Adding a material is one file beside svk.hpp (energy_density, scaled_stress and stress, a Linearisation
/// with F, linearise, stress_derivative, stiffness_block, stiffening; or stress_differential and the shared
/// HessianLinearisation of hessian.hpp), a value of MaterialModel with its name (core/parameters.hpp), an
/// alternative of AnyMaterial and a case in material_constants() below; the force loop, the energy, the
/// tangent, the stable step and the point fields then use it, each compiled for it.
#include <pointhaptics/core/model.hpp>
#include <pointhaptics/mechanics/energies/corotated.hpp>
#include <pointhaptics/mechanics/energies/mooney_rivlin.hpp>
#include <pointhaptics/mechanics/energies/neo_hookean.hpp>
#include <pointhaptics/mechanics/energies/svk.hpp>
#include <pointhaptics/mechanics/energies/viscous_overstress.hpp>
#include <pointhaptics/mechanics/energies/volume_penalty.hpp>

#include <algorithm>
#include <array>
#include <concepts>
#include <type_traits>
#include <variant>

namespace pointhaptics {

/// One material's constants, of any model.
using AnyMaterial = std::variant<StVenantKirchhoff, NeoHookean, MooneyRivlin, Corotated>;

/// The constants of `params`' model. young and poisson are the small-strain moduli of every model:
/// lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)), K = E / (3 (1 - 2 nu)); Mooney-Rivlin
/// splits mu = 2 (C10 + C01) as params.c10 : params.c01 when they are given, else equally.
/// `shear_factor` and `bulk_factor` scale mu and K apart (lambda = K - 2 mu / 3 follows): every model's
/// stress is linear in (mu, K), so bulk_factor = 0 leaves its shear part, which a Prony series relaxes,
/// and shear_factor = 1 - c the material within a viscoelastic step (viscoelasticity.hpp). For St.
/// Venant-Kirchhoff the split is exact (W = K tr(E)^2 / 2 + mu |dev E|^2); for neo-Hookean and
/// Mooney-Rivlin it is the isochoric/volumetric one; for corotated the shear part mu |F - R|^2 - (mu / 3)
/// tr(R^T F - I)^2 is mu |dev(S - I)|^2 of the stretch S = R^T F.
inline AnyMaterial material_constants(const MaterialParams& params, double shear_factor = 1, double bulk_factor = 1) {
  const double mu = shear_factor * params.mu(), bulk = bulk_factor * params.bulk_modulus();
  const double lambda = shear_factor == 1 && bulk_factor == 1 ? params.lambda() : bulk - 2.0 / 3.0 * mu;
  switch (params.model) {
    case MaterialModel::NEO_HOOKEAN: return NeoHookean{mu, bulk};
    case MaterialModel::MOONEY_RIVLIN: {
      const double sum = params.c10 + params.c01;
      const double share = sum > 0 ? params.c10 / sum : 0.5;
      return MooneyRivlin{0.5 * mu * share, 0.5 * mu * (1 - share), bulk};
    }
    case MaterialModel::COROTATED: return Corotated{lambda, mu};
    case MaterialModel::SVK: break;
  }
  return StVenantKirchhoff{lambda, mu};
}

/// The linearisation of any material as its 9 x 9 dP/dF (for objects that mix models).
template <class Material>
HessianLinearisation as_hessian(const Material& material, const Mat3& G, bool projected) {
  if constexpr (std::is_same_v<typename Material::Linearisation, HessianLinearisation>) {
    return material.linearise(G, projected);
  } else {
    const auto own = material.linearise(G, projected);  // St. Venant-Kirchhoff's projection is its own
    HessianLinearisation at;
    at.F = Mat3::Identity() + G;
    for (int k = 0; k < 9; ++k) {
      Mat3 dG = Mat3::Zero();
      dG(k % 3, k / 3) = 1;
      const Mat3 dP = material.stress_derivative(own, dG);
      at.H.col(k) = Eigen::Map<const Vec9>(dP.data());
    }
    return at;
  }
}

/// What every energy adds to its material's: the volume penalty and, within a viscoelastic step, the viscous
/// overstress; each only when active.
struct AddedTerms {
  VolumePenalty volume;
  ViscousOverstress viscous;  ///< within a viscoelastic step (viscous_overstress.hpp); else none

  bool active() const { return volume.active() || viscous.active(); }
  /// The viscous overstress's term of a step's energy, J/m^3 (0 outside a viscoelastic step).
  double viscous_energy_density(index_t i, const Mat3& G) const {
    return viscous.active() ? viscous.energy_density(i, G) : 0.0;
  }
  double energy_density(index_t i, const Mat3& G) const {
    return (volume.active() ? volume.energy_density(G) : 0.0) + viscous_energy_density(i, G);
  }
  PH_ALWAYS_INLINE void add_scaled_stress(index_t i, const Mat3& G, double scale, Mat3& P) const {
    if (volume.active()) P += scale * volume.stress(G);
    if (viscous.active()) P += scale * viscous.stress(i, G);
  }
  /// `projected` keeps the volume's Gauss-Newton part and drops the viscous overstress's term (its sign
  /// follows the history's).
  PH_ALWAYS_INLINE void add_stress_derivative(index_t i, const Mat3& F, const Mat3& dG, bool projected,
                                              Mat3& dP) const {
    if (volume.active()) dP += volume.stress_derivative(F, dG, !projected);
    if (viscous.active() && !projected) dP += viscous.stress_derivative(i, dG);
  }
  void add_stiffness_block(const Mat3& F, const Vec3& d, Mat3& K) const {
    if (volume.active()) K += volume.stiffness_block(F, d);
  }
};

/// Four consecutive points' stresses P (points i .. i + count - 1, count <= 4) completed lane by lane: the
/// lanes the material's four-point form leaves (`general`: inverted or degenerate neighbourhoods) by the
/// one-point form, and the added terms when active.
template <class Energy>
void complete_lanes(const Energy& energy, index_t i, int count, const Matrix3<Lanes>& G, const Lanes& scale,
                    const LaneMask& general, Matrix3<Lanes>& P) {
  for (int k = 0; k < count; ++k) {
    Mat3 Gk, Pk;
    for (int e = 0; e < 9; ++e) Gk.data()[e] = G.m[e][k], Pk.data()[e] = P.m[e][k];
    if (general[k]) Pk = energy.material_scaled_stress(i + k, Gk, scale[k]);
    energy.add_scaled_stress(i + k, Gk, scale[k], Pk);
    for (int e = 0; e < 9; ++e) P.m[e][k] = Pk.data()[e];
  }
}

/// A material with a four-point stiffening(G, general) (lanes.hpp), as NeoHookean.
template <class Material>
concept FourPointStiffening = requires(const Material& m, const Matrix3<Lanes>& G, LaneMask& general) {
  { m.stiffening(G, general) } -> std::same_as<Lanes>;
};

/// energy.stiffening(i + k, G_k) in the lanes k < count where `general` is set; the others keep `s`.
template <class Energy>
Lanes complete_stiffening(const Energy& energy, index_t i, int count, const Matrix3<Lanes>& G, const LaneMask& general,
                          Lanes s) {
  for (int k = 0; k < count; ++k) {
    if (!general[k]) continue;
    Mat3 Gk;
    for (int e = 0; e < 9; ++e) Gk.data()[e] = G.m[e][k];
    s[k] = energy.stiffening(i + k, Gk);
  }
  return s;
}

/// A stencil's energy per unit volume when every point has the same material: the material's, plus the
/// added terms. Every function takes the point i (ignored by the material here; see MixedEnergy).
template <class Material>
struct PointEnergy : AddedTerms {
  Material material;

  /// The material's energy per unit volume, without the added terms, J/m^3.
  double material_energy_density(index_t, const Mat3& G) const { return material.energy_density(G); }
  double energy_density(index_t i, const Mat3& G) const {
    return material_energy_density(i, G) + AddedTerms::energy_density(i, G);
  }
  /// The material's own first Piola-Kirchhoff stress, without the added terms, Pa, times `scale`.
  PH_ALWAYS_INLINE Mat3 material_scaled_stress(index_t, const Mat3& G, double scale) const {
    return material.scaled_stress(G, scale);
  }
  Mat3 material_stress(index_t i, const Mat3& G) const { return material_scaled_stress(i, G, 1.0); }
  /// First Piola-Kirchhoff stress P = dW/dF, Pa, times `scale` (the force loop's v_i).
  PH_ALWAYS_INLINE Mat3 scaled_stress(index_t i, const Mat3& G, double scale) const {
    Mat3 P = material.scaled_stress(G, scale);
    add_scaled_stress(i, G, scale, P);
    return P;
  }
  /// The same for the points i .. i + count - 1 (count <= 4) at once (lanes.hpp).
  PH_ALWAYS_INLINE Matrix3<Lanes> scaled_stress(index_t i, int count, const Matrix3<Lanes>& G,
                                                const Lanes& scale) const {
    LaneMask general;
    Matrix3<Lanes> P = material.scaled_stress(G, scale, general);
    if (AddedTerms::active() || any_lane(general)) [[unlikely]]
      complete_lanes(*this, i, count, G, scale, general, P);
    return P;
  }
  PH_ALWAYS_INLINE Mat3 stress(index_t i, const Mat3& G) const { return scaled_stress(i, G, 1.0); }
  using Linearisation = typename Material::Linearisation;
  /// `projected`: the positive semi-definite part (the material's projection, the volume's Gauss-Newton part).
  Linearisation linearise(index_t, const Mat3& G, bool projected) const { return material.linearise(G, projected); }
  PH_ALWAYS_INLINE Mat3 stress_derivative(index_t i, const Linearisation& at, const Mat3& dG, bool projected) const {
    Mat3 dP = material.stress_derivative(at, dG);
    add_stress_derivative(i, at.F, dG, projected, dP);
    return dP;
  }
  Mat3 stiffness_block(index_t, const Linearisation& at, const Vec3& d) const {
    Mat3 K = material.stiffness_block(at, d);
    add_stiffness_block(at.F, d, K);
    return K;
  }
  /// How much stiffer than at rest the material is at G (the explicit stable step).
  double stiffening(index_t, const Mat3& G) const { return material.stiffening(G); }
  /// The same for the points i .. i + count - 1 (count <= 4) at once; lanes past `count` are 1.
  Lanes stiffening(index_t i, int count, const Matrix3<Lanes>& G) const {
    LaneMask general = LaneMask{} - 1;  // every lane
    Lanes s = Lanes{} + 1;
    if constexpr (FourPointStiffening<Material>) s = material.stiffening(G, general);
    if (any_lane(general)) [[unlikely]]
      s = complete_stiffening(*this, i, count, G, general, s);
    return s;
  }
};

/// The most materials one object can mix (the object's own and its regions'; model_builder.hpp's limit).
inline constexpr std::size_t max_materials = 32;

/// A stencil's energy when points have their own materials (Model::material_of): each call dispatches on
/// the point's material, whose constants sit in a small table. Regions are contiguous in space, so the
/// branch is predicted, and four consecutive points mostly share a material; the linearisation is the
/// 9 x 9 dP/dF of any model.
struct MixedEnergy : AddedTerms {
  std::array<AnyMaterial, max_materials> materials;
  const std::uint8_t* material_of = nullptr;

  template <class Fn>
  PH_ALWAYS_INLINE decltype(auto) visit(index_t i, Fn&& fn) const {
    return std::visit(std::forward<Fn>(fn), materials[material_of[i]]);
  }
  double material_energy_density(index_t i, const Mat3& G) const {
    return visit(i, [&](const auto& m) { return m.energy_density(G); });
  }
  double energy_density(index_t i, const Mat3& G) const {
    return material_energy_density(i, G) + AddedTerms::energy_density(i, G);
  }
  PH_ALWAYS_INLINE Mat3 material_scaled_stress(index_t i, const Mat3& G, double scale) const {
    return visit(i, [&](const auto& m) -> Mat3 { return m.scaled_stress(G, scale); });
  }
  Mat3 material_stress(index_t i, const Mat3& G) const { return material_scaled_stress(i, G, 1.0); }
  PH_ALWAYS_INLINE Mat3 scaled_stress(index_t i, const Mat3& G, double scale) const {
    Mat3 P = material_scaled_stress(i, G, scale);
    add_scaled_stress(i, G, scale, P);
    return P;
  }
  /// Four points at once when they share a material, else lane by lane.
  PH_ALWAYS_INLINE Matrix3<Lanes> scaled_stress(index_t i, int count, const Matrix3<Lanes>& G,
                                                const Lanes& scale) const {
    LaneMask general = LaneMask{} - 1;  // every lane
    Matrix3<Lanes> P{};
    if (std::all_of(material_of + i + 1, material_of + i + count, [&](std::uint8_t m) { return m == material_of[i]; }))
      P = visit(i, [&](const auto& m) { return m.scaled_stress(G, scale, general); });
    if (AddedTerms::active() || any_lane(general)) [[unlikely]]
      complete_lanes(*this, i, count, G, scale, general, P);
    return P;
  }
  PH_ALWAYS_INLINE Mat3 stress(index_t i, const Mat3& G) const { return scaled_stress(i, G, 1.0); }
  using Linearisation = HessianLinearisation;
  Linearisation linearise(index_t i, const Mat3& G, bool projected) const {
    return visit(i, [&](const auto& m) { return as_hessian(m, G, projected); });
  }
  PH_ALWAYS_INLINE Mat3 stress_derivative(index_t i, const Linearisation& at, const Mat3& dG, bool projected) const {
    Mat3 dP = at.apply(dG);
    add_stress_derivative(i, at.F, dG, projected, dP);
    return dP;
  }
  Mat3 stiffness_block(index_t, const Linearisation& at, const Vec3& d) const {
    Mat3 K = at.block(d);
    add_stiffness_block(at.F, d, K);
    return K;
  }
  double stiffening(index_t i, const Mat3& G) const {
    return visit(i, [&](const auto& m) { return m.stiffening(G); });
  }
  /// Point by point (the explicit step's check; mixed objects are rare enough not to pay for lanes here).
  Lanes stiffening(index_t i, int count, const Matrix3<Lanes>& G) const {
    return complete_stiffening(*this, i, count, G, LaneMask{} - 1, Lanes{} + 1);
  }
};

/// fn(energy) with the model's energy: PointEnergy<M> of its one material's model M, or MixedEnergy when its
/// points have their own materials; within a viscoelastic step (`step`), with the step's relaxed shear
/// moduli and overstress. The one switch over materials. The preconditioner's stiffness_block() leaves the
/// overstress out (it only needs to be close).
template <class Fn>
decltype(auto) with_material(const Model& model, const ViscousStep& step, Fn&& fn, double bulk_factor = 1) {
  const VolumePenalty volume{bulk_factor == 1 ? model.material.volume_stiffness : 0.0};
  if (!model.material_of.empty()) {
    MixedEnergy mixed;
    for (std::size_t k = 0; k < model.point_materials.size() && k < max_materials; ++k)
      mixed.materials[k] = material_constants(model.point_materials[k], step.shear_factor, bulk_factor);
    mixed.material_of = model.material_of.data();
    mixed.volume = volume;
    mixed.viscous = step.overstress;
    return fn(static_cast<const MixedEnergy&>(mixed));
  }
  return std::visit(
      [&](const auto& material) -> decltype(auto) {
        return fn(PointEnergy<std::decay_t<decltype(material)>>{{volume, step.overstress}, material});
      },
      material_constants(model.material, step.shear_factor, bulk_factor));
}

/// fn(energy) with the model's elastic energy (no viscous step).
template <class Fn>
decltype(auto) with_material(const Model& model, Fn&& fn) {
  return with_material(model, ViscousStep{}, std::forward<Fn>(fn));
}

}  // namespace pointhaptics
