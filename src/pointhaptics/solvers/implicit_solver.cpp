#include <pointhaptics/solvers/implicit_solver.hpp>

#include <pointhaptics/mechanics/viscoelasticity.hpp>

#include <algorithm>

#include <fmt/format.h>

namespace pointhaptics {

ImplicitSolver::ImplicitSolver(const Model& model, double dt, const NewtonSettings& settings)
    : dt_(dt), settings_(settings), newton_(model) {}

StepReport ImplicitSolver::step(const Model& model, State& state, Workspace& ws, DynamicForces* forces) {
  const double dt = dt_;
  const double c = model.material.damping;
  const double k = 1.0 / (dt * dt) + c / dt;
  SolverScratch& scratch = ws.solver_scratch();
  Points &anchor = scratch.anchor, &next = scratch.next, &load = scratch.load, &start = scratch.start,
         &tool_forces = scratch.tool_forces;
  Eigen::Matrix<double, 9, Eigen::Dynamic>& springs = scratch.springs;
  // the two quadratic terms combine into 0.5 k |u' - a|_M^2 with a = ((u + dt v)/dt^2 + c u/dt) / k
  anchor = (state.u + dt * state.velocity) * (1.0 / (dt * dt * k)) + state.u * (c / (dt * k));
  next = state.u + dt * state.velocity;  // warm start
  const double t_next = state.time + dt;
  hold_points(model, t_next, next);
  NewtonProblem problem;
  problem.load = &model.f_ext;
  problem.inertia = k;
  problem.anchor = &anchor;
  if (forces) {
    problem.term = forces->energy_term();  // contacts minimised with the rest: their stiffness fully implicit
    // the rest (a probe's springs): its forces at the step's start as a load, its springs linearly implicit
    tool_forces.setZero();
    if (forces->add_beyond_energy(model, state, tool_forces)) {
      load = model.f_ext + tool_forces;
      problem.load = &load;
      springs.setZero();
      if (forces->add_stiffness(model, state, springs)) {
        start = state.u;
        problem.springs = &springs;
        problem.spring_anchor = &start;
      }
    }
  }
  // a viscoelastic material over this step: relaxed shear modulus and the history's overstress
  begin_viscous_step(model, state, dt, ws);
  const NewtonStats stats = newton_.solve(model, problem, next, ws, settings_);
  StepReport report;
  report.iterations = stats.iterations;
  report.cg_iterations = stats.cg_iterations;
  report.factorisations = stats.factorisations;
  report.background_factorisations = stats.background_factorisations;
  report.factor_bytes = newton_.preconditioner_bytes();
  report.coarse_points = newton_.coarse_points();
  report.residual = stats.residual;
  if (!stats.converged) {
    report.status = StepStatus::FAILED;
    report.failure = fmt::format(
        "implicit step at t = {:.6g} s did not converge ({}, residual {:.3g} after {} Newton "
        "iterations); try a smaller dt or a larger solver.max_iterations",
        state.time, stats.failure, stats.residual, stats.iterations);
    return report;
  }
  // a step the iteration budget ended keeps its iterate, as the scene asked (real time): counted, not a failure
  if (settings_.accept_at_budget && stats.residual > settings_.tolerance) report.status = StepStatus::AT_BUDGET;
  state.velocity = (next - state.u) / dt;
  state.u = next;  // copied, not swapped: NumPy views point into the state's buffer
  state.time = t_next;
  end_viscous_step(model, dt, state, ws);
  return report;
}

}  // namespace pointhaptics
