#pragma once
/// @file The viscous overstress of a Prony series within one step, as an energy term beside the material's:
/// its energy density, stress and stress derivative side by side (tests/viscoelasticity_test.cpp checks
/// them against finite differences). mechanics/viscoelasticity.hpp makes it from the state's history.
#include <pointhaptics/mechanics/deformation.hpp>

namespace pointhaptics {

/// A symmetric 3x3 tensor stored as 6 doubles (xx, yy, zz, yz, xz, xy), the layout of the viscous history.
using Voigt6 = Eigen::Matrix<double, 6, 1>;
inline Mat3 from_voigt(const double* v) {
  Mat3 m;
  m << v[0], v[5], v[4], v[5], v[1], v[3], v[4], v[3], v[2];
  return m;
}
inline Voigt6 to_voigt(const Mat3& m) {
  Voigt6 v;
  v << m(0, 0), m(1, 1), m(2, 2), 0.5 * (m(1, 2) + m(2, 1)), 0.5 * (m(0, 2) + m(2, 0)), 0.5 * (m(0, 1) + m(1, 0));
  return v;
}

/// Over one step of a viscoelastic material the second Piola-Kirchhoff stress is
///   S = S_elastic(mu (1 - c)) - H_i
/// (viscoelasticity.hpp): the material with its shear modulus relaxed by the step's share c, less a
/// constant per-point tensor H_i from the history. The material with scaled moduli is still a material;
/// this is the -H_i part, the exact gradient of
///   W_i(F) = -H_i : E,  E = (F^T F - I) / 2,  so  P = -F H_i,  dP = -dF H_i,
/// which makes the step an energy minimisation (Newton's line search and CG need one) for every model.
struct ViscousOverstress {
  const double* overstress = nullptr;  ///< H_i, Pa, 6 per point (Voigt6 layout); nullptr: none

  bool active() const { return overstress != nullptr; }
  Mat3 at(index_t i) const { return from_voigt(overstress + 6 * static_cast<std::ptrdiff_t>(i)); }

  double energy_density(index_t i, const Mat3& G) const { return -(at(i).array() * green_strain(G).array()).sum(); }
  PH_ALWAYS_INLINE Mat3 stress(index_t i, const Mat3& G) const { return -(Mat3::Identity() + G) * at(i); }
  PH_ALWAYS_INLINE Mat3 stress_derivative(index_t i, const Mat3& dG) const { return -dG * at(i); }
};

/// What a viscoelastic material is within one step: its shear modulus scaled by shear_factor (1 - c) and the
/// history's overstress. The default is the elastic material.
struct ViscousStep {
  double shear_factor = 1;
  ViscousOverstress overstress;
};

}  // namespace pointhaptics
