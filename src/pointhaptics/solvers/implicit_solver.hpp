#pragma once
/// @file Implicit dynamics: backward Euler solved by Newton-CG, warm-started, with an optional
/// iteration budget for real time.
#include <pointhaptics/solvers/solver.hpp>

namespace pointhaptics {

/// One backward Euler step of dt with mass-proportional damping c:
///   M (v' - v) / dt = f_int(u') + f_ext - c M v',   u' = u + dt v'.
/// As a minimisation (so Newton can line-search): u' minimises
///   W(u') - f_ext . u' + (1/(2 dt^2)) |u' - u - dt v|_M^2 + (c/(2 dt)) |u' - u|_M^2,
/// whose Hessian is K + (1/dt^2 + c/dt) M. The initial guess is u + dt v (warm start). Held points
/// follow their prescribed displacement. With settings.accept_at_budget the step keeps the iterate
/// reached within settings.max_iterations (AT_BUDGET, real time); otherwise a step that does not
/// converge is FAILED and leaves the state as it was.
class ImplicitSolver final : public Solver {
 public:
  ImplicitSolver(const Model& model, double dt, const NewtonSettings& settings);
  /// The tools' forces are evaluated once at the step's start and, with their springs, linearised about
  /// it, f(u) = f - S (u - u_n), which keeps stiff contact springs stable at any dt.
  StepReport step(const Model& model, State& state, Workspace& ws, DynamicForces* forces) override;
  void set_real_time(bool real_time) override { settings_.real_time = real_time; }
  /// Newton's solver and its preconditioner's state (the Cholesky factor), for inspection.
  NewtonSolver& newton() { return newton_; }

 private:
  double dt_;
  NewtonSettings settings_;
  NewtonSolver newton_;  // its vectors and the step's are the workspace's (Workspace::solver_scratch())
};

}  // namespace pointhaptics
