#pragma once
/// @file Per-point kinematics and constitutive law: G_i (seed Eq. 10), F_i, Green strain (Eq. 2), SVK stress.
#include <pointhaptics/core/model.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pointhaptics {

/// Displacement gradient G_i = sum_j (u_j - u_i) d_ij^T (seed Eq. 10); row a is the gradient of u_a.
inline Mat3 displacement_gradient(const Model& model, const Points& u, index_t i) {
  Mat3 G = Mat3::Zero();
  const Vec3 ui = u.col(i);
  for (index_t e = model.neighbours.begin(i); e < model.neighbours.end(i); ++e)
    G.noalias() += (u.col(model.neighbours.index[e]) - ui) * model.d.col(e).transpose();
  return G;
}

/// Green strain E = 0.5 (F^T F - I) = 0.5 (G + G^T + G^T G) from the displacement gradient G (seed Eq. 2).
/// Written in G: forming F^T F - I cancels catastrophically at small strain (at |G| ~ 1e-9 only 7 digits
/// survive, which puts a floor under Newton's residual).
inline Mat3 green_strain(const Mat3& G) { return 0.5 * (G + G.transpose() + G.transpose() * G); }

/// St. Venant-Kirchhoff second Piola-Kirchhoff stress S = lambda tr(E) I + 2 mu E.
inline Mat3 svk_stress(const Mat3& E, double lambda, double mu) {
  return lambda * E.trace() * Mat3::Identity() + 2.0 * mu * E;
}

/// How much stiffer St. Venant-Kirchhoff is at F = I + G than at rest: a bound on |dP/dF| over its rest
/// value. dP = dF S + F C : sym(F^T dF), so |dP| <= (|S| + s3 |C|) |dF| with s1 <= s3 the extreme
/// eigenvalues of F^T F; |S| <= |C| |E|, and the principal Green strains lie in [(s1 - 1) / 2, (s3 - 1) / 2].
/// The ratio is at most s3 + max(s3 - 1, 1 - s1) / 2: (3 s^2 - 1) / 2 in a pure stretch s (the uniaxial
/// tangent), 1 at rest. s1 and s3 are bounded by Gershgorin's discs of F^T F (exact for a diagonal F^T F,
/// and an eigen-solver per point cost as much as the force evaluation). The explicit stable step follows it
/// (issue 21: a probe pressed deep into soft tissue stretched the points under it to |G| ~ 2, and the
/// rest-state step diverged).
inline double svk_stiffening(const Mat3& G) {
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

/// Cofactor matrix cof F = det(F) F^-T; its rows are (r1 x r2, r2 x r0, r0 x r1) for rows r_a of F.
inline Mat3 cofactor(const Mat3& F) {
  Mat3 C;
  C.row(0) = F.row(1).cross(F.row(2));
  C.row(1) = F.row(2).cross(F.row(0));
  C.row(2) = F.row(0).cross(F.row(1));
  return C;
}

}  // namespace pointhaptics
