#pragma once
/// @file Viscoelasticity: a Prony series on the shear (deviatoric) part of any material, integrated over a
/// step of any length, explicit or implicit (Simo 1987; Holzapfel 2000, section 6.10).
///
/// With the material's shear stress S_s(t) (its second Piola-Kirchhoff stress with the bulk modulus set to
/// zero; material.hpp's material_constants), each term k of the series carries an overstress Q_k with
///   dQ_k/dt = (g_k S_s - Q_k) / tau_k,    S = S_elastic - sum_k Q_k.
/// Held at a constant strain from t = 0 the shear stress relaxes as g(t) = 1 - sum_k g_k (1 - e^(-t/tau_k)),
/// the bulk response not at all; young and poisson are the instantaneous moduli, mu (1 - sum_k g_k) the
/// long-term shear modulus. Over a step of length dt, with S_s linear between its ends (exact for the
/// relaxation and creep tests), the solution is
///   Q_k' = a_k Q_k + b_k S_s + c_k S_s',  a_k = e^(-x), b_k = g_k ((1 - a_k) / x - a_k),
///   c_k = g_k (1 - (1 - a_k) / x),  x = dt / tau_k,
/// unconditionally stable (a_k < 1) for any dt. The stress at the step's end is then
///   S' = S_elastic(mu (1 - c)) - H,  c = sum_k c_k,  H = sum_k (a_k Q_k + b_k S_s):
/// the material with a relaxed shear modulus plus a constant overstress H per point, whose term
/// (energies/viscous_overstress.hpp) keeps the step an energy minimisation for Newton. An explicit step takes
/// its whole dt as one viscous step: its sub-steps see the stress the step would end with at their u.
#include <pointhaptics/core/state.hpp>
#include <pointhaptics/core/workspace.hpp>
#include <pointhaptics/mechanics/energies/viscous_overstress.hpp>

#include <array>

namespace pointhaptics {

/// The coefficients of one step of length dt, per term.
struct PronyStep {
  std::size_t terms = 0;
  std::array<double, max_prony_terms> a{}, b{}, c{};
  double c_sum = 0;  ///< c = sum_k c_k: the share of the shear modulus the step relaxes at once
};
PronyStep prony_step(const std::vector<PronyTerm>& series, double dt);

/// The shear part of a point's second Piola-Kirchhoff stress at G, unscaled by the stiffness map, Pa.
/// (Exposed for the tests.)
Mat3 shear_stress(const Model& model, index_t i, const Mat3& G);

/// The step's material (relaxed shear modulus) and overstress H_i, from the state's history, into ws: what
/// compute_internal_forces(), strain_energy() and the tangent then use. No-op for an elastic model.
void begin_viscous_step(const Model& model, const State& state, double dt, Workspace& ws);
/// The history at the end of the step: each point's shear stress at the state's displacement, and the Q_k.
/// Where a neighbourhood is degenerate (det F < 0.05) the shear stress is kept from the step before.
void end_viscous_step(const Model& model, double dt, State& state, Workspace& ws);
/// The material at the state itself, between steps, into ws (reactions and forces reported after a step):
/// the elastic stress less the history's overstress sum_k Q_k, or after a static solve (`relaxed`) the
/// long-term material. No-op for an elastic model.
void viscous_stress_at_state(const Model& model, const State& state, Workspace& ws, bool relaxed);
/// A static solve of a viscoelastic model: the equilibrium after all relaxation, with the long-term shear
/// modulus mu (1 - sum_k g_k) and no history.
void relaxed_material(const Model& model, Workspace& ws);

/// What ws says the material is within the current step (elastic unless a viscous step began).
inline ViscousStep viscous_step(const Workspace& ws) {
  ViscousStep step;
  step.shear_factor = ws.viscous_shear_factor;
  if (ws.overstress_active) step.overstress.overstress = ws.overstress.data();
  return step;
}

}  // namespace pointhaptics
