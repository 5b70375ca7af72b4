#include <pointhaptics/solvers/static_solver.hpp>

#include <pointhaptics/core/run_control.hpp>
#include <pointhaptics/mechanics/viscoelasticity.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <limits>

namespace pointhaptics {

namespace {

StaticStats load_stepping(const Model& model, State& state, Workspace& ws, NewtonSolver& newton,
                          const NewtonSettings& settings, Points& load, Points& trial, EnergyTerm* term,
                          StaticStats stats) {
  double reached = 0.0, increment = 1.0;
  const double min_increment = 1e-4;
  NewtonProblem problem;
  problem.load = &load;
  problem.term = term;
  while (reached < 1.0) {
    throw_if_stop_requested("load steps");
    const double factor = std::min(1.0, reached + increment);
    load = factor * model.f_ext;
    // predictor: the last equilibrium, scaled to the new load factor (exact for a linear response)
    if (reached > 0) trial = state.u * (factor / reached);
    else trial = state.u;
    hold_points(model, std::numeric_limits<double>::infinity(), trial, nullptr, 0, factor);  // ramps are for dynamics
    const NewtonStats ns = newton.solve(model, problem, trial, ws, settings);
    stats.iterations += ns.iterations;
    stats.cg_iterations += ns.cg_iterations;
    stats.factorisations += ns.factorisations;
    stats.background_factorisations += ns.background_factorisations;
    stats.projected += ns.projected;
    stats.residual = ns.residual;
    if (ns.converged) {
      state.u = trial;
      reached = factor;
      ++stats.load_steps;
      increment = std::min(2.0 * increment, 1.0);
      continue;
    }
    ++stats.cutbacks;
    increment *= 0.5;
    if (increment < min_increment) {
      stats.failure = fmt::format("static solver: no equilibrium beyond {:.4g} of the load ({}; residual {:.3g})",
                                  reached, ns.failure, ns.residual);
      break;
    }
  }
  stats.converged = reached >= 1.0;
  state.velocity.setZero();
  return stats;
}

}  // namespace

StaticStats solve_static(const Model& model, State& state, Workspace& ws, NewtonSolver& newton,
                         const NewtonSettings& settings, EnergyTerm* term) {
  SolverScratch& scratch = ws.solver_scratch();
  // a viscoelastic material at equilibrium has relaxed fully: its long-term shear modulus
  if (!model.material.prony.empty()) relaxed_material(model, ws);
  StaticStats stats = load_stepping(model, state, ws, newton, settings, scratch.load, scratch.next, term, {});
  // a constrained term (augmented Lagrangian): minimise again with its updated multipliers until it is met
  constexpr int max_updates = 50;
  while (term && stats.converged && !term->update_multipliers(model, state.u)) {
    if (++stats.multiplier_updates > max_updates) {
      stats.converged = false;
      stats.failure = fmt::format(
          "static solver: the contact constraints (a tool's, an obstacle's, between bodies) are still not met "
          "after {} updates of their multipliers",
          max_updates);
      break;
    }
    stats.load_steps = 0;
    stats = load_stepping(model, state, ws, newton, settings, scratch.load, scratch.next, term, stats);
  }
  return stats;
}

StaticSolver::StaticSolver(const Model& model, const NewtonSettings& settings) : settings_(settings), newton_(model) {}

StepReport StaticSolver::step(const Model& model, State& state, Workspace& ws, DynamicForces* forces) {
  const StaticStats stats =
      solve_static(model, state, ws, newton_, settings_, forces ? forces->energy_term() : nullptr);
  StepReport report;
  report.status = stats.converged ? StepStatus::CONVERGED : StepStatus::FAILED;
  report.substeps = stats.load_steps;
  report.iterations = stats.iterations;
  report.cg_iterations = stats.cg_iterations;
  report.factorisations = stats.factorisations;
  report.background_factorisations = stats.background_factorisations;
  report.factor_bytes = newton_.preconditioner_bytes();
  report.coarse_points = newton_.coarse_points();
  report.residual = stats.residual;
  report.failure = stats.failure;
  // an object that nothing holds (no held point; an obstacle's friction only once it presses) has rigid-body
  // modes that the first minimisation does not fix, and round-off can slide it along them: a block pressed by a
  // tool onto a table slid 412 m aside in one build and "converged" there. Not a result: said so
  if (report.status == StepStatus::CONVERGED &&
      std::none_of(model.fixed.begin(), model.fixed.end(), [](auto f) { return f != 0; })) {
    const double slide = state.u.rowwise().mean().norm();
    if (slide > model.extent) {
      report.status = StepStatus::FAILED;
      report.failure = fmt::format(
          "static solver: the object slid {:.3g} m as a rigid body (more than its size): nothing holds it in place "
          "(hold points with [[fixed]], or run it in dynamics, where its inertia does)",
          slide);
    }
  }
  return report;
}

}  // namespace pointhaptics
