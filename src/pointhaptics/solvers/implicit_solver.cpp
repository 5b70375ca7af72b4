#include <pointhaptics/solvers/implicit_solver.hpp>

#include <fmt/format.h>

namespace pointhaptics {

ImplicitSolver::ImplicitSolver(const Model& model, double dt, const NewtonSettings& settings)
    : dt_(dt),
      settings_(settings),
      newton_(model),
      anchor_(Points::Zero(3, model.n_points)),
      u_next_(Points::Zero(3, model.n_points)),
      load_(Points::Zero(3, model.n_points)),
      u_start_(Points::Zero(3, model.n_points)),
      tool_forces_(Points::Zero(3, model.n_points)),
      springs_(Eigen::Matrix<double, 9, Eigen::Dynamic>::Zero(9, model.n_points)) {}

StepReport ImplicitSolver::step(const Model& model, State& state, Workspace& ws, DynamicForces* forces) {
  const double dt = dt_;
  const double c = model.material.damping;
  const double k = 1.0 / (dt * dt) + c / dt;
  // the two quadratic terms combine into 0.5 k |u' - a|_M^2 with a = ((u + dt v)/dt^2 + c u/dt) / k
  anchor_ = (state.u + dt * state.velocity) * (1.0 / (dt * dt * k)) + state.u * (c / (dt * k));
  u_next_ = state.u + dt * state.velocity;  // warm start
  const double t_next = state.time + dt;
  hold_points(model, t_next, u_next_);
  NewtonProblem problem;
  problem.load = &model.f_ext;
  problem.inertia = k;
  problem.anchor = &anchor_;
  if (forces) {
    tool_forces_.setZero();
    forces->add(model, state, tool_forces_);
    load_ = model.f_ext + tool_forces_;
    problem.load = &load_;
    springs_.setZero();
    if (forces->add_stiffness(model, state, springs_)) {
      u_start_ = state.u;
      problem.springs = &springs_;
      problem.spring_anchor = &u_start_;
    }
  }
  const NewtonStats stats = newton_.solve(model, problem, u_next_, ws, settings_);
  StepReport report;
  report.iterations = stats.iterations;
  report.cg_iterations = stats.cg_iterations;
  report.residual = stats.residual;
  if (!stats.converged) {
    report.status = StepStatus::FAILED;
    report.failure = fmt::format("implicit step at t = {:.6g} s did not converge ({}, residual {:.3g} after {} Newton "
                                 "iterations); try a smaller dt or a larger solver.max_iterations",
                                 state.time, stats.failure, stats.residual, stats.iterations);
    return report;
  }
  // a step the iteration budget ended keeps its iterate, as the scene asked (real time): counted, not a failure
  if (settings_.accept_at_budget && stats.residual > settings_.tolerance) report.status = StepStatus::AT_BUDGET;
  state.velocity = (u_next_ - state.u) / dt;
  state.u = u_next_;  // copied, not swapped: NumPy views point into the state's buffer
  state.time = t_next;
  return report;
}

}  // namespace pointhaptics
