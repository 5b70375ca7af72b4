#pragma once
/// @file The linearisation shared by the hyperelastic models whose stress derivative is not a short formula
/// (neo-Hookean, Mooney-Rivlin, corotated) and by objects that mix models: the 9 x 9 derivative dP/dF
/// per point, built from the material's exact directional derivative, optionally projected onto its
/// positive semi-definite part (per point, as Teran et al. 2005 and IPC do), then applied as a matrix.
#include <pointhaptics/mechanics/deformation.hpp>

#include <Eigen/Eigenvalues>

namespace pointhaptics {

using Mat9 = Eigen::Matrix<double, 9, 9>;
using Vec9 = Eigen::Matrix<double, 9, 1>;

/// dP/dF at F, as a matrix on column-major vec(dF) (entry (a, k) of a 3x3 matrix is vec index a + 3k).
struct HessianLinearisation {
  Mat3 F;  ///< I + G, for the volume term
  Mat9 H;

  PH_ALWAYS_INLINE Mat3 apply(const Mat3& dG) const {
    Mat3 dP;
    Eigen::Map<Vec9>(dP.data()) = H * Eigen::Map<const Vec9>(dG.data());
    return dP;
  }
  /// The block K_ab = e_a . dP(e_b d^T) d = sum_kl d_k d_l H(a + 3k, b + 3l).
  Mat3 block(const Vec3& d) const {
    Mat3 K = Mat3::Zero();
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) K += (d[k] * d[l]) * H.block<3, 3>(3 * k, 3 * l);
    return K;
  }
};

/// H with its negative eigenvalues set to zero (H is symmetric: the Hessian of an energy).
inline Mat9 positive_part(const Mat9& H) {
  Eigen::SelfAdjointEigenSolver<Mat9> eig(0.5 * (H + H.transpose()));
  if (eig.eigenvalues()[0] >= 0) return H;
  return eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() * eig.eigenvectors().transpose();
}

/// The linearisation of `material` at F = I + G from its directional derivative stress_differential(F, dF),
/// projected when asked.
template <class Material>
HessianLinearisation hessian_linearisation(const Material& material, const Mat3& G, bool projected) {
  HessianLinearisation at;
  at.F = Mat3::Identity() + G;
  for (int k = 0; k < 9; ++k) {
    Mat3 dF = Mat3::Zero();
    dF(k % 3, k / 3) = 1;
    const Mat3 dP = material.stress_differential(at.F, dF);
    at.H.col(k) = Eigen::Map<const Vec9>(dP.data());
  }
  if (projected) at.H = positive_part(at.H);
  return at;
}

/// The tangent of a model that gives its exact directional derivative stress_differential(F, dF): the 9 x 9
/// linearisation above (derive from HessianTangent<Model>; the model keeps its constants as members).
template <class Material>
struct HessianTangent {
  using Linearisation = HessianLinearisation;
  Linearisation linearise(const Mat3& G, bool projected) const {
    return hessian_linearisation(static_cast<const Material&>(*this), G, projected);
  }
  PH_ALWAYS_INLINE Mat3 stress_derivative(const Linearisation& at, const Mat3& dG) const { return at.apply(dG); }
  Mat3 stiffness_block(const Linearisation& at, const Vec3& d) const { return at.block(d); }
};

/// J^-p, extended below j_floor by its second-order Taylor expansion there: the deviatoric invariants
/// I1bar = J^-2/3 I1 and I2bar = J^-4/3 I2 stay finite at J <= 0 and keep pushing J up (the value grows,
/// the slope stays negative, as J falls), so an inverted or flattened neighbourhood is restored instead of
/// making infinities. Exact for J >= j_floor: a twentyfold loss of volume, far beyond any tissue's.
struct PowerOfJ {
  static constexpr double j_floor = 0.05;
  double value, first, second;  ///< g(J), g'(J), g''(J)

  PowerOfJ(double J, double p) {
    const double j = std::max(J, j_floor);
    const double g = power(j, p), g1 = -p * g / j, g2 = p * (p + 1) * g / (j * j);
    if (J >= j_floor) {
      value = g, first = g1, second = g2;
    } else {
      const double s = J - j_floor;
      value = g + g1 * s + 0.5 * g2 * s * s, first = g1 + g2 * s, second = g2;
    }
  }
  /// j^-p: the deviatoric invariants' powers (2/3, 4/3, the only ones the materials pass) through one cube
  /// root instead of a std::pow, for the one-point forms (the Hessian's linearisation, lanes below the
  /// floor); the force loop and the stiffening check use lanes.hpp's inverse_cube_root.
  static double power(double j, double p) {
    if (p == 2.0 / 3.0 || p == 4.0 / 3.0) {
      const double r = 1 / std::cbrt(j), r2 = r * r;
      return p == 2.0 / 3.0 ? r2 : r2 * r2;
    }
    return std::pow(j, -p);
  }
};

/// Four points' stresses of a model whose material.regular_stress(G, J - 1, scale) holds for J >= j_floor
/// (neo-Hookean, Mooney-Rivlin); the lanes below the floor (or not finite) are marked in `general`, for the
/// model's one-point form.
template <class Material>
PH_ALWAYS_INLINE inline Matrix3<Lanes> regular_lanes_stress(const Material& material, const Matrix3<Lanes>& G,
                                                            const Lanes& scale, LaneMask& general) {
  const Lanes jm1 = volume_change(G);
  general = !(1 + jm1 >= PowerOfJ::j_floor);
  return material.regular_stress(G, jm1, scale);
}

/// J - 1 = det(I + G) - 1 = tr G + I2(G) + det G, written in G (no cancellation at small strain).
PH_ALWAYS_INLINE inline double volume_change(const Mat3& G) { return volume_change(to_matrix3(G)); }

/// The derivative of cof F along dF: rows of cof F are cross products of rows of F (product rule).
PH_ALWAYS_INLINE inline Mat3 cofactor_differential(const Mat3& F, const Mat3& dF) {
  Mat3 dcof;
  dcof.row(0) = dF.row(1).cross(F.row(2)) + F.row(1).cross(dF.row(2));
  dcof.row(1) = dF.row(2).cross(F.row(0)) + F.row(2).cross(dF.row(0));
  dcof.row(2) = dF.row(0).cross(F.row(1)) + F.row(0).cross(dF.row(1));
  return dcof;
}

/// The deviatoric part of a 3x3 matrix.
PH_ALWAYS_INLINE inline Mat3 deviator(const Mat3& A) { return to_eigen(deviator(to_matrix3(A))); }

/// Upper bounds of the extreme eigenvalues of C = F^T F by Gershgorin's discs: s1 <= lambda_min, s3 >=
/// lambda_max (cheap; the explicit stable step's stiffening estimates use them every step).
inline void stretch_bounds(const Mat3& F, double& s1, double& s3) {
  const Mat3 C = F.transpose() * F;
  s1 = std::numeric_limits<double>::infinity(), s3 = -s1;
  for (int a = 0; a < 3; ++a) {
    const double radius = std::abs(C(a, (a + 1) % 3)) + std::abs(C(a, (a + 2) % 3));
    s1 = std::min(s1, C(a, a) - radius);
    s3 = std::max(s3, C(a, a) + radius);
  }
}

/// The explicit stable step's stiffening of a hyperelastic model with a volume term K (J - 1)^2 / 2: one plus
/// the growth of the bound of |dP / dF| over its rest value (`shear_growth`: the deviatoric terms'; the bulk
/// terms' |cof F|^2 + 2 |J - 1| |F| here, from `cof_squared` = |cof F|^2 and `f` = |F|), over the tangent's
/// rest norm max(3 K, 2 mu). For one point or four (lanes.hpp).
template <class T>
PH_ALWAYS_INLINE inline T hyperelastic_stiffening(const T& cof_squared, const T& f, const T& jm1, const T& shear_growth,
                                                  double bulk, double mu) {
  const T bulk_growth = bulk * (cof_squared + 2 * absolute(jm1) * f - 3);
  const T one = T{} + 1;
  return larger(T(one + (shear_growth + bulk_growth) / std::max(3 * bulk, 2 * mu)), one);
}

}  // namespace pointhaptics
