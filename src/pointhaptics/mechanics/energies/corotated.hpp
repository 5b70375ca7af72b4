#pragma once
/// @file Linear corotated elasticity, the fast model: its energy density, first Piola-Kirchhoff stress and
/// stress derivative side by side (tests/mechanics/energies/materials_test.cpp).
#include <pointhaptics/mechanics/energies/hessian.hpp>

#include <Eigen/SVD>

namespace pointhaptics {

/// Below this det F the corotated rotation comes from the SVD (rotation_of).
inline constexpr double polar_floor = 1e-6;

/// The scaling g = |det X|^-1/3 of the polar iteration while X is far from orthogonal (det outside (0.5, 2)),
/// else 1.
PH_ALWAYS_INLINE inline double polar_scaling(double det) {
  return det > 0.5 && det < 2 ? 1.0 : std::cbrt(1.0 / std::abs(det));
}
PH_ALWAYS_INLINE inline Lanes polar_scaling(const Lanes& det) {
  Lanes g = Lanes{} + 1.0;
  const LaneMask far = !((det > 0.5) & (det < 2.0));
  if (any_lane(far)) [[unlikely]]
    for (int k = 0; k < lane_count; ++k)
      if (far[k]) g[k] = polar_scaling(det[k]);
  return g;
}

/// The polar rotation of F (det F = J > 0) by Newton's iteration X <- (g X + X^-T / g) / 2 (Higham 1986; g:
/// polar_scaling), which from a near-rotation converges in three or four 3x3 inversions, far cheaper than
/// an SVD; for one point or four, each lane stopping when its own step is below 1e-6 (so that four points
/// get what each would alone).
template <class T>
PH_ALWAYS_INLINE inline Matrix3<T> polar_rotation(const Matrix3<T>& F, T det) {
  Matrix3<T> X = F;
  MaskOf<T> active = det == det;  // every lane
  for (int iteration = 0; iteration < 30; ++iteration) {
    const T g = polar_scaling(det);
    const Matrix3<T> next = 0.5 * (g * X + T(1.0 / (g * det)) * cofactor(X));
    const T change = max_abs(next - X);
    X = where(active, next, X);
    // quadratic convergence: the error is now about change^2 / 2, below 1e-12 (a third iteration from
    // the small strains of a haptic step cost a tenth of the force loop)
    active = active & !(change < 1e-6);
    if (none(active)) break;
    det = determinant(X, cofactor(X));
  }
  return X;
}

/// The rotation R of F = R S (S symmetric). For det F > 0 the polar decomposition (polar_rotation). For
/// det F <= 0 (an inverted neighbourhood) the rotation of the SVD with the smallest singular value's sign
/// flipped (Irving, Teran and Fedkiw 2004), so that S has a negative eigenvalue and the energy pushes the
/// point back.
inline Mat3 rotation_of(const Mat3& F) {
  const double J = F.determinant();
  if (J > polar_floor) return to_eigen(polar_rotation(to_matrix3(F), J));
  Eigen::JacobiSVD<Mat3> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 U = svd.matrixU();
  const Mat3& V = svd.matrixV();
  if ((U * V.transpose()).determinant() < 0) U.col(2) = -U.col(2);  // singular values descend: flip the smallest
  return U * V.transpose();
}

/// W(F) = mu |F - R|^2 + lambda / 2 tr(R^T F - I)^2 with R the rotation of F (rotation_of): linear
/// elasticity in the rotated frame, so rotations cost nothing and small strains match St. Venant-Kirchhoff's
/// and neo-Hookean's moduli (lambda, mu from young and poisson), without their softening or stiffening at
/// large strain. The fast option (PhysX, Drake, iMSTK offer it): no invariant powers, no volume barrier.
struct Corotated : HessianTangent<Corotated> {
  double lambda = 0, mu = 0;  ///< Lame's parameters, Pa
  Corotated() = default;
  Corotated(double lambda_, double mu_) : lambda(lambda_), mu(mu_) {}

  double energy_density(const Mat3& G) const {
    const Mat3 F = Mat3::Identity() + G;
    const Mat3 R = rotation_of(F);
    const double t = (R.transpose() * F).trace() - 3;
    return mu * (F - R).squaredNorm() + 0.5 * lambda * t * t;
  }

  /// P = 2 mu (F - R) + lambda tr(R^T F - I) R, Pa (the derivative of R drops out: R^T dR is skew, S symmetric),
  /// times `scale`.
  PH_ALWAYS_INLINE Mat3 scaled_stress(const Mat3& G, double scale) const {
    const Mat3 F = Mat3::Identity() + G;
    return to_eigen(stress_with_rotation(to_matrix3(F), to_matrix3(rotation_of(F)), scale));
  }
  /// Four points' stresses; the lanes with det F <= the polar floor (or not finite) are marked in `general`,
  /// for the one-point form above.
  PH_ALWAYS_INLINE Matrix3<Lanes> scaled_stress(const Matrix3<Lanes>& G, const Lanes& scale, LaneMask& general) const {
    const Matrix3<Lanes> F = plus_identity(G, 1.0);
    const Lanes J = determinant(F, cofactor(F));
    general = !(J > polar_floor);
    if (none(general)) return stress_with_rotation(F, polar_rotation(F, J), scale);
    // the general lanes iterate from the identity, which stops at once
    const Matrix3<Lanes> start = where(general, plus_identity(Matrix3<Lanes>{}, 1.0), F);
    return stress_with_rotation(F, polar_rotation(start, where(general, Lanes{} + 1.0, J)), scale);
  }
  template <class T>
  PH_ALWAYS_INLINE Matrix3<T> stress_with_rotation(const Matrix3<T>& F, const Matrix3<T>& R, const T& scale) const {
    const T t = inner(R, F) - 3;
    return T((2 * mu) * scale) * (F - R) + T(lambda * t * scale) * R;
  }
  PH_ALWAYS_INLINE Mat3 stress(const Mat3& G) const { return scaled_stress(G, 1.0); }

  /// dR = R [w]x with (tr S I - S) w = axial(R^T dF - dF^T R), S = R^T F (from dF = dR S + R dS: the skew
  /// part of R^T dF is W S + S W = [(tr S I - S) w]x); then
  ///   dP = 2 mu (dF - dR) + lambda tr(R^T dF) R + lambda tr(S - I) dR.
  Mat3 stress_differential(const Mat3& F, const Mat3& dF) const {
    const Mat3 R = rotation_of(F);
    const Mat3 S = R.transpose() * F;
    const Mat3 A = R.transpose() * dF - dF.transpose() * R;
    const Vec3 a(A(2, 1), A(0, 2), A(1, 0));
    Mat3 M = S.trace() * Mat3::Identity() - 0.5 * (S + S.transpose());
    // two singular values summing to zero (a neighbourhood folded flat): R is not differentiable there
    if (std::abs(M.determinant()) < 1e-12) M += 1e-6 * Mat3::Identity();
    const Vec3 w = M.inverse() * a;
    Mat3 W;
    W << 0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0;
    const Mat3 dR = R * W;
    const double t = S.trace() - 3;
    return 2 * mu * (dF - dR) + lambda * (R.transpose() * dF).trace() * R + lambda * t * dR;
  }

  /// How much stiffer than at rest (explicit stable step): dP = 2 mu dF + lambda tr(R^T dF) R + (lambda tr(S - I)
  /// - 2 mu) dR with |dR| <= 2 |dF| / (the smallest sum of two singular values), bounded from the stretches
  /// (sigma_min >= J / s3 for J > 0; a floor of 0.1 for inverted neighbourhoods).
  double stiffening(const Mat3& G) const {
    const Mat3 F = Mat3::Identity() + G;
    double s1, s3;
    stretch_bounds(F, s1, s3);
    s3 = std::max(s3, 1e-12);
    const double J = F.determinant();
    const double sigma_min = std::max(std::sqrt(std::max(s1, 0.0)), J / s3);
    const double pair_min = std::max(0.1, 2 * sigma_min);
    // |tr S - 3|: the singular values lie in [sqrt(s1), sqrt(s3)] when F is not inverted
    const double trace_bound =
        J > 0 ? std::max(3 * std::sqrt(s3) - 3, 3 - 3 * std::sqrt(std::max(s1, 0.0))) : 3 * std::sqrt(s3) + 3;
    const double now = 2 * mu + 3 * lambda + (lambda * trace_bound + 2 * mu) * 2 / pair_min;
    const double rest = 2 * mu + 3 * lambda + 2 * mu;
    return std::max(1.0, now / rest);
  }
};

}  // namespace pointhaptics
