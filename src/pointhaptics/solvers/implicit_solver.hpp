#pragma once
/// @file Implicit dynamics: backward Euler solved by Newton-CG, warm-started, with an optional
/// iteration budget for real time.
#include <pointhaptics/core/state.hpp>
#include <pointhaptics/solvers/newton.hpp>

namespace pointhaptics {

/// One backward Euler step of dt with mass-proportional damping c:
///   M (v' - v) / dt = f_int(u') + f_ext - c M v',   u' = u + dt v'.
/// As a minimisation (so Newton can line-search): u' minimises
///   W(u') - f_ext . u' + (1/(2 dt^2)) |u' - u - dt v|_M^2 + (c/(2 dt)) |u' - u|_M^2,
/// whose Hessian is K + (1/dt^2 + c/dt) M. The initial guess is u + dt v (warm start). Held points
/// follow their prescribed displacement. With settings.accept_at_budget the step keeps the iterate
/// reached within settings.max_iterations (real time); otherwise a step that fails throws Error.
class ImplicitSolver {
 public:
  explicit ImplicitSolver(const Model& model);
  /// extra_forces (3 x n, N), if given, are added to the constant loads for this step; with springs
  /// (9 x n, their stiffness -df/du per point) they are linearised about the step's start,
  /// f(u) = f - S (u - u_n), which keeps stiff contact springs stable at any dt.
  NewtonStats step(const Model& model, State& state, Workspace& ws, double dt, const NewtonSettings& settings,
                   const Points* extra_forces = nullptr, const Eigen::Matrix<double, 9, Eigen::Dynamic>* springs = nullptr);

 private:
  NewtonSolver newton_;
  Points anchor_, u_next_, load_, u_start_;
};

}  // namespace pointhaptics
