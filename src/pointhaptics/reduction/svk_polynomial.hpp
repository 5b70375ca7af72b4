#pragma once
/// @file The reduced St. Venant-Kirchhoff energy as an exact quartic polynomial in the reduced coordinates q
/// (issue 49, `[reduction] forces = "polynomial"`; Barbic & James 2005): with u = U q every point's displacement
/// gradient is linear in q, G_p = sum_k q_k G_pk, so its Green strain is E_p = sum_k q_k e_pk + 1/2 sum_kl q_k q_l
/// h_pkl (e = sym G_k, h = sym G_k^T G_l), and the energy sum_p v_p 1/2 <E_p, E_p> (<X, Y> = 2 mu X:Y + lambda tr X
/// tr Y) is
///   W(q) = 1/2 q^T A q + 1/6 b_klm q_k q_l q_m + 1/24 c_klmn q_k q_l q_m q_n,
///   b_klm = <e_k, h_lm> + <e_l, h_km> + <e_m, h_kl>,  c_klmn = <h_kl, h_mn> + <h_km, h_ln> + <h_kn, h_lm>
/// (sums over points weighted by v_p understood; A is U^T K U at rest, hourglass penalty included, which is
/// quadratic). With B(q)_kl = b_klm q_m and C(q)_kl = c_klmn q_m q_n, the gradient is A q + 1/2 B q + 1/6 C q and
/// the Hessian A + B + 1/2 C: one product with a precomputed (r(r+1)/2)^2 table gives both, whatever the number of
/// points. Energy, gradient and Hessian live side by side here (tests/reduction/svk_polynomial_test.cpp checks
/// them against the full model's energy, forces and tangent).
#include <pointhaptics/core/workspace.hpp>

namespace pointhaptics {

class SvkPolynomial {
 public:
  /// The tables for basis U (3n x r) of `model`, on TBB's threads. Throws Error when the model's energy is not a
  /// polynomial: a material other than St. Venant-Kirchhoff, points of several materials, a volume term
  /// (volume_stiffness > 0) or viscoelasticity. Interrupted on a stop request.
  SvkPolynomial(const Model& model, const Eigen::MatrixXd& U, Workspace& ws);

  int size() const { return r_; }
  /// W(q), J.
  double energy(const Eigen::VectorXd& q) const;
  /// gradient = dW/dq (N in reduced units) and, when given, hessian = d2W/dq2 and energy = W, at q, from one
  /// contraction of the tables. No allocation.
  void evaluate(const Eigen::VectorXd& q, Eigen::VectorXd& gradient, Eigen::MatrixXd* hessian,
                double* energy = nullptr) const;
  /// The rest stiffness U^T K U.
  const Eigen::MatrixXd& rest_stiffness() const { return A_; }
  /// max over the points of c_p = sqrt(sum_k |G_pk|_F^2), the basis vectors' displacement gradients there: every
  /// point's gradient at u = U q is at most |q| c_p (Cauchy-Schwarz), which bounds inversion (reduced_solver.hpp)
  double gradient_bound() const { return gradient_bound_; }
  double build_s() const { return build_s_; }
  /// the tables' memory, bytes
  double bytes() const;

 private:
  /// B(q) and C(q) of q into the scratch matrices.
  void contract(const Eigen::VectorXd& q) const;
  int r_ = 0, pairs_ = 0;
  Eigen::MatrixXd A_;  ///< r x r
  Eigen::MatrixXd b_;  ///< pairs x r: b_klm in row pair(k, l), column m
  Eigen::MatrixXd c_;  ///< pairs x pairs: c_klmn in row pair(k, l), column pair(m, n)
  double build_s_ = 0;
  double gradient_bound_ = 0;
  // scratch (mutable: evaluating is logically const and allocates nothing)
  mutable Eigen::VectorXd w_, bq_, cq_;
  mutable Eigen::MatrixXd B_, C_;
};

}  // namespace pointhaptics
