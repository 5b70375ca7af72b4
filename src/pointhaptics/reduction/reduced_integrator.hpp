#pragma once
/// @file Steps and static solves in the reduced coordinates (issue 49): full Newton in r unknowns on the reduced
/// energy (svk_polynomial.hpp), the same backward Euler as the full implicit solver (solvers/implicit_solver.hpp)
/// with the basis' unit mass (U^T M U = I):
///   q' minimises W(q') - f . q' + |q' - q - dt v|^2 / (2 dt^2) + c |q' - q|^2 / (2 dt),   v' = (q' - q) / dt,
/// whose Hessian is K(q') + (1 / dt^2 + c / dt) I. A static solve minimises W(q) - f . q, in load steps when
/// one Newton solve does not converge. No allocation after construction.
#include <pointhaptics/reduction/svk_polynomial.hpp>

namespace pointhaptics {

struct ReducedState {
  Eigen::VectorXd q, v;  ///< coordinates and their rates
};

/// A part of the energy beyond the polynomial and the loads with unknowns of its own, minimised together with q
/// (one Newton on both): the region a tool touches in full resolution, whose points are its unknowns
/// (contact_patch.hpp). Newton's system in (q, its unknowns v) is solved with v eliminated:
///   [H_qq H_qv; H_vq H_vv] [dq; dv] = -[g_q; g_v],
///   (H_qq - H_qv H_vv^-1 H_vq) dq = -(g_q - H_qv H_vv^-1 g_v),   dv = -H_vv^-1 (g_v + H_vq dq).
/// Each Newton iteration calls evaluate(), add_hessian(), condense() and begin_move() in this order; a line search
/// then calls move() with the share of the step it tries, before evaluate() there.
class ReducedCoupling {
 public:
  virtual ~ReducedCoupling() = default;
  /// Its energy at q and its own unknowns' current values, with its gradient in q (at fixed v) added into
  /// `gradient`; false when it is not finite there (the step backtracks, or fails).
  virtual bool evaluate(const Eigen::VectorXd& q, double& energy, Eigen::VectorXd& gradient) = 0;
  /// |g_v| of the last evaluation, in the units of the reduced gradient (U is mass-orthonormal: each point's
  /// force divided by the square root of its mass), for Newton's convergence test
  virtual double residual() const = 0;
  /// H_qq's part and the Schur complement -H_qv H_vv^-1 H_vq (or positive semi-definite approximations of them) at
  /// the last evaluation, added into `hessian`
  virtual void add_hessian(Eigen::MatrixXd& hessian) = 0;
  /// gradient -= H_qv H_vv^-1 g_v: the right-hand side of the condensed system
  virtual void condense(Eigen::VectorXd& gradient) = 0;
  /// Its unknowns' step for the reduced one dq, dv = -H_vv^-1 (g_v + H_vq dq), from where they are now; returns
  /// g_v . dv (its share of the step's slope)
  virtual double begin_move(const Eigen::VectorXd& dq) = 0;
  /// its unknowns at the step's start plus alpha times its step
  virtual void move(double alpha) = 0;
};

struct ReducedSolveReport {
  bool converged = false;
  int iterations = 0;       ///< Newton's
  double residual = 0;      ///< |gradient of what is minimised| at the end, in the basis' units
  double load_reached = 1;  ///< a static solve's share of its load (1 when converged)
  bool at_budget = false;   ///< a real-time step ended by its iteration budget and kept its iterate
};

class ReducedIntegrator {
 public:
  /// `external`: U^T f of the dead loads (gravity, tractions); `damping`: mass-proportional, 1/s.
  ReducedIntegrator(const SvkPolynomial& forces, Eigen::VectorXd external, double damping);
  const Eigen::VectorXd& external() const { return external_; }
  /// A backward Euler step of dt minimises inertia(dt) |q' - a|^2 / 2 + W(q') - f . q' with the anchor
  /// a = q + carry(dt) v (of any displacement and velocity: the contact patch's points take the same).
  double inertia(double dt) const { return 1 / (dt * dt) + damping_ / dt; }
  double carry(double dt) const { return dt / (1 + damping_ * dt); }
  /// One backward Euler step of dt. Newton stops at a residual below `tolerance` times the load's size (or the
  /// inertia's, whichever is larger) or after `max_iterations`; a step that does not converge leaves `state` as
  /// it was, unless `accept_at_budget` (real time, as the full implicit solver's iteration budget): then the
  /// iterate after max_iterations Newton steps is taken without evaluating it again (at_budget in the report).
  /// `coupling`: a further part of the energy (a tool's contact region), minimised with the rest.
  ReducedSolveReport step(ReducedState& state, double dt, double tolerance = 1e-9, int max_iterations = 20,
                          bool accept_at_budget = false, ReducedCoupling* coupling = nullptr);
  /// The equilibrium W'(q) = load_scale f, from q (its start, and its answer).
  ReducedSolveReport solve_static(Eigen::VectorXd& q, double tolerance = 1e-10, int max_iterations = 50);

 private:
  /// Newton on phi(x) = W(x) - f . x + inertia |x - anchor|^2 / 2 with a backtracking line search, from x.
  ReducedSolveReport minimise(Eigen::VectorXd& x, const Eigen::VectorXd& force, double inertia,
                              const Eigen::VectorXd& anchor, double tolerance, int max_iterations,
                              bool stop_at_budget = false, ReducedCoupling* coupling = nullptr);
  const SvkPolynomial& forces_;
  Eigen::VectorXd external_;
  double damping_;
  // scratch
  Eigen::VectorXd gradient_, condensed_, direction_, trial_, anchor_, scaled_force_, start_, iterate_,
      coupling_gradient_;
  Eigen::MatrixXd hessian_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
};

}  // namespace pointhaptics
