#pragma once
/// @file Compressible Mooney-Rivlin elasticity, CalculiX's MOONEY-RIVLIN: its energy density, first
/// Piola-Kirchhoff stress and stress derivative side by side (tests/mechanics/energies/materials_test.cpp).
#include <pointhaptics/mechanics/energies/neo_hookean.hpp>

namespace pointhaptics {

/// W(F) = C10 (I1bar - 3) + C01 (I2bar - 3) + (J - 1)^2 / D1 with I1bar = J^-2/3 I1, I2bar = J^-4/3 I2,
/// I2 = (I1^2 - tr(C^2)) / 2, D1 = 2 / K: CalculiX's *HYPERELASTIC, MOONEY-RIVLIN for J >= PowerOfJ::j_floor,
/// finite and restoring below (hessian.hpp). Small-strain shear modulus mu = 2 (C10 + C01); C01 = 0 is
/// neo-Hookean. C01 stiffens shear at large stretch, as measured for many soft tissues.
struct MooneyRivlin : HessianTangent<MooneyRivlin> {
  double c10 = 0, c01 = 0, bulk = 0;  ///< Pa
  MooneyRivlin() = default;
  MooneyRivlin(double c10_, double c01_, double bulk_) : c10(c10_), c01(c01_), bulk(bulk_) {}

  double mu() const { return 2 * (c10 + c01); }

  /// J/m^3; each Ibar - 3 = g (I - 3) + 3 (g - 1), formed from the strain (no cancellation at small strain):
  /// I1 - 3 = 2 t, I2 - 3 = 4 t + 2 t^2 - 2 tr(E^2) with t = tr E.
  double energy_density(const Mat3& G) const {
    const double jm1 = volume_change(G), J = 1 + jm1;
    const PowerOfJ g1(J, 2.0 / 3.0), g2(J, 4.0 / 3.0);
    const bool exact = J >= PowerOfJ::j_floor;
    const double g1m1 = exact ? std::expm1(-2.0 / 3.0 * std::log1p(jm1)) : g1.value - 1;
    const double g2m1 = exact ? std::expm1(-4.0 / 3.0 * std::log1p(jm1)) : g2.value - 1;
    const Mat3 E = green_strain(G);
    const double t = E.trace();
    const double i1m3 = 2 * t, i2m3 = 4 * t + 2 * t * t - 2 * (E * E).trace();
    return c10 * (g1.value * i1m3 + 3 * g1m1) + c01 * (g2.value * i2m3 + 3 * g2m1) + 0.5 * bulk * jm1 * jm1;
  }

  /// P = C10 (g1' I1 cof + 2 g1 F) + C01 (g2' I2 cof + 2 g2 (I1 F - F C)) + K (J - 1) cof, Pa, times `scale`.
  PH_ALWAYS_INLINE Mat3 scaled_stress(const Mat3& G, double scale) const {
    const double jm1 = volume_change(G), J = 1 + jm1;
    if (J >= PowerOfJ::j_floor) return to_eigen(regular_stress(to_matrix3(G), jm1, scale));
    const Mat3 F = Mat3::Identity() + G;
    const Mat3 cof = cofactor(F);
    const PowerOfJ g1(J, 2.0 / 3.0), g2(J, 4.0 / 3.0);
    const Mat3 C = F.transpose() * F;
    const double i1 = C.trace(), i2 = 0.5 * (i1 * i1 - (C * C).trace());
    return scale * (c10 * (g1.first * i1 * cof + 2 * g1.value * F) +
                    c01 * (g2.first * i2 * cof + 2 * g2.value * (i1 * F - F * C)) + bulk * jm1 * cof);
  }
  /// Four points' stresses (hessian.hpp's regular_lanes_stress; the other lanes by the form above).
  PH_ALWAYS_INLINE Matrix3<Lanes> scaled_stress(const Matrix3<Lanes>& G, const Lanes& scale, LaneMask& general) const {
    return regular_lanes_stress(*this, G, scale, general);
  }
  /// The stress for J >= j_floor: the deviatoric parts are 4 (cof / J) [C10 g1 dev E + C01 g2 ((1 + 2 t) dev E
  /// - 2 dev(E^2))] with g1 = J^-2/3, g2 = J^-4/3 (no cancellation at small strain), for one point or four.
  template <class T>
  PH_ALWAYS_INLINE Matrix3<T> regular_stress(const Matrix3<T>& G, const T& jm1, const T& scale) const {
    const Matrix3<T> cof = cofactor(plus_identity(G, 1.0));
    const T y = inverse_cube_root(T(1 + jm1)), g1 = y * y, g2 = g1 * g1;  // std::pow cost a third of the force loop
    const Matrix3<T> E = green_strain(G);
    const Matrix3<T> inner =
        T(c10 * g1 + c01 * g2 * (1 + 2 * trace(E))) * deviator(E) - T((2 * c01) * g2) * deviator(symmetric_square(E));
    return T(scale * 4 * (g1 * y)) * (cof * inner) + T(scale * bulk * jm1) * cof;
  }
  PH_ALWAYS_INLINE Mat3 stress(const Mat3& G) const { return scaled_stress(G, 1.0); }

  /// dP along dF at F, the product rule on the general form of the stress (dC = dF^T F + F^T dF,
  /// dI2 = 2 (I1 F - F C) : dF).
  Mat3 stress_differential(const Mat3& F, const Mat3& dF) const {
    const Mat3 cof = cofactor(F), dcof = cofactor_differential(F, dF);
    const double jm1 = volume_change(F - Mat3::Identity()), J = 1 + jm1;
    const PowerOfJ g1(J, 2.0 / 3.0), g2(J, 4.0 / 3.0);
    const Mat3 C = F.transpose() * F, dC = dF.transpose() * F + F.transpose() * dF;
    const double i1 = C.trace(), i2 = 0.5 * (i1 * i1 - (C * C).trace());
    const Mat3 B = i1 * F - F * C;  // dI2/dF / 2
    const double dJ = (cof.array() * dF.array()).sum(), di1 = 2 * (F.array() * dF.array()).sum();
    const double di2 = 2 * (B.array() * dF.array()).sum();
    const Mat3 dB = di1 * F + i1 * dF - dF * C - F * dC;
    return c10 * ((g1.second * dJ * i1 + g1.first * di1) * cof + g1.first * i1 * dcof + 2 * g1.first * dJ * F +
                  2 * g1.value * dF) +
           c01 * ((g2.second * dJ * i2 + g2.first * di2) * cof + g2.first * i2 * dcof + 2 * g2.first * dJ * B +
                  2 * g2.value * dB) +
           bulk * (dJ * cof + jm1 * dcof);
  }

  /// How much stiffer than at rest (explicit stable step): as NeoHookean::stiffening, with the C01 terms'
  /// bounds (|B| <= 2 I1 |F|, |dB| <= 6 I1 |dF|, I2 <= I1^2 / 3).
  double stiffening(const Mat3& G) const {
    const Mat3 F = Mat3::Identity() + G;
    const double jm1 = volume_change(G);
    const PowerOfJ g1(1 + jm1, 2.0 / 3.0), g2(1 + jm1, 4.0 / 3.0);
    static const double second_rest = second_bound(Mat3::Identity(), PowerOfJ(1, 4.0 / 3.0));  // a constant: once
    const double i1 = F.squaredNorm(), f = std::sqrt(i1), c = cofactor(F).norm();
    const double first = NeoHookean::shear_bound(i1, f, c, g1.value, std::abs(g1.first), std::abs(g1.second));
    const double growth = c10 * (first - NeoHookean::rest_shear_bound) + c01 * (second_bound(F, g2) - second_rest);
    return hyperelastic_stiffening(c * c, f, jm1, growth, bulk, mu());
  }
  /// The C01 (I2bar - 3) terms of |dP| / |dF|, over C01.
  static double second_bound(const Mat3& F, const PowerOfJ& g) {
    const double i1 = F.squaredNorm(), f = std::sqrt(i1), c = cofactor(F).norm(), i2 = i1 * i1 / 3, b = 2 * i1 * f;
    return 12 * i1 * g.value + std::abs(g.second) * i2 * c * c +
           std::abs(g.first) * (2 * b * c + 2 * i2 * f + 2 * c * b);
  }
};

}  // namespace pointhaptics
