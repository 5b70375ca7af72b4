#pragma once
/// @file St. Venant-Kirchhoff, the seed's material: its energy density, first Piola-Kirchhoff stress and
/// stress derivative side by side (tests/mechanics/energies/svk_test.cpp checks each against finite
/// differences of the one before).
#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/energies/lanes.hpp>

namespace pointhaptics {

/// W(F) = 0.5 S : E with the Green strain E = 0.5 (F^T F - I) (seed Eq. 2) and S = lambda tr(E) I + 2 mu E.
/// Every function takes the displacement gradient G = F - I, from which E is formed without cancellation.
struct StVenantKirchhoff {
  double lambda = 0, mu = 0;  ///< Lame's parameters, Pa

  /// Second Piola-Kirchhoff stress S(E), Pa.
  PH_ALWAYS_INLINE Mat3 second_piola(const Mat3& E) const {
    return lambda * E.trace() * Mat3::Identity() + 2.0 * mu * E;
  }

  /// Energy per unit reference volume, J/m^3.
  double energy_density(const Mat3& G) const {
    const Mat3 E = green_strain(G);
    return 0.5 * (second_piola(E).array() * E.array()).sum();
  }

  /// First Piola-Kirchhoff stress P = dW/dF = F S, Pa (seed Eq. 12-13 in exact form), times `scale` (the
  /// force loop's volume v_i), for one point (T = double) or four (T = Lanes, lanes.hpp).
  template <class T>
  PH_ALWAYS_INLINE Matrix3<T> scaled_stress(const Matrix3<T>& G, const T& scale) const {
    const Matrix3<T> E = green_strain(G);
    const Matrix3<T> S = plus_identity((2.0 * mu) * E, T(lambda * trace(E)));
    return scale * (plus_identity(G, 1.0) * S);
  }
  PH_ALWAYS_INLINE Mat3 scaled_stress(const Mat3& G, double scale) const {
    return to_eigen(scaled_stress(to_matrix3(G), scale));
  }
  /// Four points' stresses (every lane is handled: `general` is left clear).
  PH_ALWAYS_INLINE Matrix3<Lanes> scaled_stress(const Matrix3<Lanes>& G, const Lanes& scale, LaneMask& general) const {
    general = LaneMask{};
    return scaled_stress<Lanes>(G, scale);
  }
  PH_ALWAYS_INLINE Mat3 stress(const Mat3& G) const { return scaled_stress(G, 1.0); }

  /// What the tangent keeps per point between linearising and applying: F and S, or with `projected` the
  /// positive part of S, which makes the geometric term dG S, and with it the whole tangent, positive
  /// semi-definite (Newton's fallback under compression).
  struct Linearisation {
    Mat3 F, S;
  };
  Linearisation linearise(const Mat3& G, bool projected) const {
    const Mat3 S = second_piola(green_strain(G));
    return {Mat3::Identity() + G, projected ? positive_part(S) : S};
  }

  /// The stress increment dP = dG S + F (lambda tr(dE) I + 2 mu dE), dE = sym(F^T dG), Pa.
  PH_ALWAYS_INLINE Mat3 stress_derivative(const Linearisation& at, const Mat3& dG) const {
    const Mat3 FtdG = at.F.transpose() * dG;
    const Mat3 dE = 0.5 * (FtdG + FtdG.transpose());
    return dG * at.S + at.F * (lambda * dE.trace() * Mat3::Identity() + 2.0 * mu * dE);
  }

  /// The 3x3 block of dP for dG = e_b d^T, applied to d: K_ab = e_a . dP(e_b d^T) d. With g = F d,
  ///   dG S d = (d^T S d) e_b,  F (lambda tr(dE) I + 2 mu dE) d = (lambda + mu) g_b g + mu |d|^2 F F^T e_b,
  /// so K = (lambda + mu) g g^T + mu |d|^2 F F^T + (d^T S d) I (the diagonal blocks of block-Jacobi).
  Mat3 stiffness_block(const Linearisation& at, const Vec3& d) const {
    const Vec3 g = at.F * d;
    Mat3 K = (lambda + mu) * g * g.transpose() + (mu * d.squaredNorm()) * (at.F * at.F.transpose());
    K.diagonal().array() += d.dot(at.S * d);
    return K;
  }

  /// How much stiffer the material is at F = I + G than at rest: a bound on |dP/dF| over its rest value.
  /// dP = dF S + F C : sym(F^T dF), so |dP| <= (|S| + s3 |C|) |dF| with s1 <= s3 the extreme eigenvalues
  /// of F^T F; |S| <= |C| |E|, and the principal Green strains lie in [(s1 - 1) / 2, (s3 - 1) / 2]. The
  /// ratio is at most s3 + max(s3 - 1, 1 - s1) / 2: (3 s^2 - 1) / 2 in a pure stretch s (the uniaxial
  /// tangent), 1 at rest. s1 and s3 are bounded by Gershgorin's discs of F^T F (exact for a diagonal
  /// F^T F; an eigen-solver per point cost as much as the force evaluation). The explicit stable step
  /// follows it (issue 21: a probe pressed deep into soft tissue stretched the points under it to |G| ~ 2,
  /// and the rest-state step diverged).
  static double stiffening(const Mat3& G) {
    const Mat3 F = Mat3::Identity() + G;
    const Mat3 C = F.transpose() * F;
    double s1 = std::numeric_limits<double>::infinity(), s3 = -s1;
    for (int a = 0; a < 3; ++a) {
      const double radius = std::abs(C(a, (a + 1) % 3)) + std::abs(C(a, (a + 2) % 3));
      s1 = std::min(s1, C(a, a) - radius);
      s3 = std::max(s3, C(a, a) + radius);
    }
    return std::max(1.0, s3 + 0.5 * std::max(s3 - 1.0, 1.0 - std::max(0.0, s1)));
  }
};

}  // namespace pointhaptics
