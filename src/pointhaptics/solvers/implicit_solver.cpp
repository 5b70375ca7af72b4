#include <pointhaptics/solvers/implicit_solver.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/solvers/explicit_solver.hpp>

#include <fmt/format.h>

namespace pointhaptics {

ImplicitSolver::ImplicitSolver(const Model& model)
    : newton_(model),
      anchor_(Points::Zero(3, model.n_points)),
      u_next_(Points::Zero(3, model.n_points)),
      load_(Points::Zero(3, model.n_points)),
      u_start_(Points::Zero(3, model.n_points)) {}

NewtonStats ImplicitSolver::step(const Model& model, State& state, Workspace& ws, double dt,
                                 const NewtonSettings& settings, const Points* extra_forces,
                                 const Eigen::Matrix<double, 9, Eigen::Dynamic>* springs) {
  const double c = model.material.damping;
  const double k = 1.0 / (dt * dt) + c / dt;
  // the two quadratic terms combine into 0.5 k |u' - a|_M^2 with a = ((u + dt v)/dt^2 + c u/dt) / k
  anchor_ = (state.u + dt * state.velocity) * (1.0 / (dt * dt * k)) + state.u * (c / (dt * k));
  u_next_ = state.u + dt * state.velocity;  // warm start
  const double t_next = state.time + dt;
  for (const FixedGroup& group : model.fixed_groups) {
    const Vec3 target = prescribed_displacement(group, t_next);
    for (index_t i : group.points) u_next_.col(i) = target;
  }
  NewtonProblem problem;
  if (extra_forces) {
    load_ = model.f_ext + *extra_forces;
    problem.load = &load_;
  } else {
    problem.load = &model.f_ext;
  }
  problem.inertia = k;
  problem.anchor = &anchor_;
  if (springs) {
    u_start_ = state.u;
    problem.springs = springs;
    problem.spring_anchor = &u_start_;
  }
  const NewtonStats stats = newton_.solve(model, problem, u_next_, ws, settings);
  if (!stats.converged)
    throw Error(fmt::format("implicit step at t = {:.6g} s did not converge ({}, residual {:.3g} after {} Newton "
                            "iterations); try a smaller dt or a larger solver.max_iterations",
                            state.time, stats.failure, stats.residual, stats.iterations));
  state.velocity = (u_next_ - state.u) / dt;
  state.u = u_next_;  // copied, not swapped: NumPy views point into the state's buffer
  state.time = t_next;
  return stats;
}

}  // namespace pointhaptics
