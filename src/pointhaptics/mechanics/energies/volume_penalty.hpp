#pragma once
/// @file The volume term: a penalty on the change of volume added to the material, with its energy
/// density, stress and stress derivative side by side (tests/mechanics/energies/volume_penalty_test.cpp).
#include <pointhaptics/mechanics/deformation.hpp>

namespace pointhaptics {

/// W(F) = 0.5 k_v (J - 1)^2 with J = det F (k_v = 0: off). It stiffens St. Venant-Kirchhoff against the
/// collapse it allows under compression.
struct VolumePenalty {
  double stiffness = 0;  ///< k_v, Pa

  bool active() const { return stiffness > 0; }

  double energy_density(const Mat3& G) const {
    const double J = (Mat3::Identity() + G).determinant();
    return 0.5 * stiffness * (J - 1) * (J - 1);
  }

  /// P = dW/dF = k_v (J - 1) cof F (dJ/dF = cof F), Pa.
  PH_ALWAYS_INLINE Mat3 stress(const Mat3& G) const {
    const Mat3 F = Mat3::Identity() + G;
    return stiffness * (F.determinant() - 1.0) * cofactor(F);
  }

  /// dP = k_v [(cof F : dG) cof F + (J - 1) d(cof F)[dG]]; `exact` = false drops the second term, which is
  /// indefinite, and keeps a positive semi-definite Gauss-Newton part. Rows of cof F are cross products of
  /// rows of F, so d(cof F) is their product rule.
  PH_ALWAYS_INLINE Mat3 stress_derivative(const Mat3& F, const Mat3& dG, bool exact) const {
    const Mat3 cof = cofactor(F);
    Mat3 dP = stiffness * (cof.array() * dG.array()).sum() * cof;
    if (exact) {
      Mat3 dcof;
      dcof.row(0) = dG.row(1).cross(F.row(2)) + F.row(1).cross(dG.row(2));
      dcof.row(1) = dG.row(2).cross(F.row(0)) + F.row(2).cross(dG.row(0));
      dcof.row(2) = dG.row(0).cross(F.row(1)) + F.row(0).cross(dG.row(1));
      dP += stiffness * (F.determinant() - 1.0) * dcof;
    }
    return dP;
  }

  /// The 3x3 block of dP for dG = e_b d^T applied to d: k_v h h^T with h = cof F d (d(cof F)[e_b d^T] d
  /// vanishes: each of its rows is a cross product with d).
  Mat3 stiffness_block(const Mat3& F, const Vec3& d) const {
    const Vec3 h = cofactor(F) * d;
    return stiffness * h * h.transpose();
  }
};

}  // namespace pointhaptics
