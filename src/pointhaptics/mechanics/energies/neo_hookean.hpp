#pragma once
/// @file Compressible neo-Hookean elasticity, CalculiX's NEO HOOKE: its energy density, first Piola-Kirchhoff
/// stress and stress derivative side by side (tests/mechanics/energies/materials_test.cpp checks each against
/// finite differences of the one before).
#include <pointhaptics/mechanics/energies/hessian.hpp>

namespace pointhaptics {

/// W(F) = C10 (I1bar - 3) + (J - 1)^2 / D1, I1bar = J^-2/3 tr(F^T F), with C10 = mu / 2 and D1 = 2 / K:
/// exactly CalculiX's *HYPERELASTIC, NEO HOOKE for J >= PowerOfJ::j_floor, and finite and restoring below
/// (J^-2/3 continued by its Taylor expansion; hessian.hpp). mu and K are the small-strain shear and bulk
/// moduli: mu = E / (2 (1 + nu)), K = E / (3 (1 - 2 nu)), so young and poisson keep their meaning. Unlike
/// St. Venant-Kirchhoff it stiffens under compression: the volume term's (J - 1)^2 and I1bar's J^-2/3 grow
/// without bound as a neighbourhood flattens.
struct NeoHookean : HessianTangent<NeoHookean> {
  double mu = 0, bulk = 0;  ///< small-strain shear and bulk moduli, Pa (C10 = mu / 2, D1 = 2 / bulk)
  NeoHookean() = default;
  NeoHookean(double mu_, double bulk_) : mu(mu_), bulk(bulk_) {}

  double c10() const { return 0.5 * mu; }

  /// Energy per unit reference volume, J/m^3. I1bar - 3 = g (I1 - 3) + 3 (g - 1) with g = J^-2/3, both terms
  /// formed from the strain (no cancellation at small strain).
  double energy_density(const Mat3& G) const {
    const double jm1 = volume_change(G);
    const PowerOfJ g(1 + jm1, 2.0 / 3.0);
    const double gm1 = 1 + jm1 >= PowerOfJ::j_floor ? std::expm1(-2.0 / 3.0 * std::log1p(jm1)) : g.value - 1;
    const double i1m3 = 2 * green_strain(G).trace();
    return c10() * (g.value * i1m3 + 3 * gm1) + 0.5 * bulk * jm1 * jm1;
  }

  /// P = C10 (g' I1 cof F + 2 g F) + K (J - 1) cof F, Pa, times `scale`.
  PH_ALWAYS_INLINE Mat3 scaled_stress(const Mat3& G, double scale) const {
    const double jm1 = volume_change(G), J = 1 + jm1;
    if (J >= PowerOfJ::j_floor) return to_eigen(regular_stress(to_matrix3(G), jm1, scale));
    const Mat3 F = Mat3::Identity() + G;
    const Mat3 cof = cofactor(F);
    const PowerOfJ g(J, 2.0 / 3.0);
    const double i1 = (F.array() * F.array()).sum();
    return scale * (c10() * (g.first * i1 * cof + 2 * g.value * F) + bulk * jm1 * cof);
  }
  /// Four points' stresses (hessian.hpp's regular_lanes_stress; the other lanes by the form above).
  PH_ALWAYS_INLINE Matrix3<Lanes> scaled_stress(const Matrix3<Lanes>& G, const Lanes& scale, LaneMask& general) const {
    return regular_lanes_stress(*this, G, scale, general);
  }
  /// The stress for J >= j_floor, where g' = -2/3 g / J: the deviatoric part is 4 C10 J^-5/3 cof F dev(E)
  /// (no cancellation at small strain), for one point or four (lanes.hpp).
  template <class T>
  PH_ALWAYS_INLINE Matrix3<T> regular_stress(const Matrix3<T>& G, const T& jm1, const T& scale) const {
    const Matrix3<T> cof = cofactor(plus_identity(G, 1.0));
    const T y = inverse_cube_root(T(1 + jm1)), y2 = y * y;  // J^-1/3 (std::pow cost a third of the force loop)
    return T(scale * (4 * c10()) * (y2 * y2 * y)) * (cof * deviator(green_strain(G))) + T(scale * bulk * jm1) * cof;
  }
  PH_ALWAYS_INLINE Mat3 stress(const Mat3& G) const { return scaled_stress(G, 1.0); }

  /// dP along dF at F: with dJ = cof F : dF, dI1 = 2 F : dF and d(cof F),
  ///   dP = C10 [(g'' dJ I1 + g' dI1) cof + g' I1 dcof + 2 g' dJ F + 2 g dF] + K [dJ cof + (J - 1) dcof].
  Mat3 stress_differential(const Mat3& F, const Mat3& dF) const {
    const Mat3 cof = cofactor(F), dcof = cofactor_differential(F, dF);
    const double jm1 = volume_change(F - Mat3::Identity()), J = 1 + jm1;
    const PowerOfJ g(J, 2.0 / 3.0);
    const double i1 = (F.array() * F.array()).sum();
    const double dJ = (cof.array() * dF.array()).sum(), di1 = 2 * (F.array() * dF.array()).sum();
    return c10() * ((g.second * dJ * i1 + g.first * di1) * cof + g.first * i1 * dcof + 2 * g.first * dJ * F +
                    2 * g.value * dF) +
           bulk * (dJ * cof + jm1 * dcof);
  }

  /// How much stiffer than at rest (for the explicit stable step): each term of dP bounded in Frobenius
  /// norms (|F|^2 = I1, |cof F|, |d cof| <= 2 |F| |dF|); the bound's growth over its rest value, over the
  /// tangent's rest norm 3 K (the volumetric mode; 2 mu for negative Poisson's ratios).
  double stiffening(const Mat3& G) const {
    const double jm1 = volume_change(G);
    const PowerOfJ g(1 + jm1, 2.0 / 3.0);
    return stiffening_at(to_matrix3(G), jm1, g.value, std::abs(g.first), std::abs(g.second));
  }
  /// The same for four points (lanes.hpp), the explicit step's check over every point of every step. The
  /// lanes whose J is below PowerOfJ's floor (or not finite) are marked in `general`, for the form above.
  Lanes stiffening(const Matrix3<Lanes>& G, LaneMask& general) const {
    const Lanes jm1 = volume_change(G), J = 1 + jm1;
    general = !(J >= PowerOfJ::j_floor);
    const Lanes j = where(general, Lanes{} + 1, J);
    const Lanes y = inverse_cube_root(j), g = y * y;  // J^-2/3 and its derivatives' magnitudes
    return stiffening_at(G, jm1, g, (2.0 / 3.0) * g / j, (10.0 / 9.0) * g / (j * j));
  }
  /// The stiffening at G from g = J^-2/3, |g'| and |g''|.
  template <class T>
  PH_ALWAYS_INLINE T stiffening_at(const Matrix3<T>& G, const T& jm1, const T& g, const T& g1, const T& g2) const {
    const Matrix3<T> F = plus_identity(G, 1.0), cof = cofactor(F);
    const T i1 = inner(F, F), f = square_root(i1), c2 = inner(cof, cof);
    const T shear_growth = c10() * (shear_bound(i1, f, square_root(c2), g, g1, g2) - rest_shear_bound);
    return hyperelastic_stiffening(c2, f, jm1, shear_growth, bulk, mu);
  }
  /// The C10 (I1bar - 3) terms of |dP| / |dF|, over C10, from I1 = |F|^2, f = |F|, c = |cof F| and g = J^-2/3,
  /// |g'|, |g''|.
  template <class T>
  PH_ALWAYS_INLINE static T shear_bound(const T& i1, const T& f, const T& c, const T& g, const T& g1, const T& g2) {
    return 2 * g + g2 * i1 * c * c + g1 * (2 * f * c + 2 * i1 * f + 2 * c * f);
  }
  /// shear_bound() at rest (F = I: I1 = 3, |F| = |cof F| = sqrt 3, g = 1, |g'| = 2/3, |g''| = 10/9): 20 + 4 sqrt 3.
  static constexpr double rest_shear_bound = 20 + 4 * 1.7320508075688772;
};

}  // namespace pointhaptics
