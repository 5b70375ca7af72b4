#include <pointhaptics/simulation.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/solvers/explicit_solver.hpp>
#include <pointhaptics/solvers/reactions.hpp>

#include <fmt/format.h>

#include <chrono>
#include <cmath>

namespace pointhaptics {

Simulation::Simulation(Model model, const SolverSpec& solver, int n_threads)
    : model_(std::move(model)), solver_(solver), state_(State::at_rest(model_)), ws_(model_, n_threads) {
  if (solver_.kind != SolverKind::EXPLICIT)
    throw Error(fmt::format("solver.kind = \"{}\" is not available in this version yet; use kind = \"explicit\"",
                            to_string(solver_.kind)));
  stable_dt_ = stable_time_step(model_);
  // held points start at their prescribed displacement at t = 0
  for (const FixedGroup& group : model_.fixed_groups)
    for (index_t i : group.points) state_.u.col(i) = prescribed_displacement(group, 0.0);
}

void Simulation::step() {
  const auto start = std::chrono::steady_clock::now();
  // explicit dynamics: internal forces, then symplectic Euler, sub-stepped below the stable step
  const ExplicitStepStats stats = explicit_step(model_, state_, ws_, solver_.dt, stable_dt_);
  substeps_ += stats.substeps;
  ++steps_;
  step_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void Simulation::run(double duration, const std::function<void(double)>& progress) {
  const long long n_steps = std::llround(std::ceil(duration / solver_.dt - 1e-9));
  for (long long k = 0; k < n_steps; ++k) {
    step();
    if (progress) progress(static_cast<double>(k + 1) / n_steps);
  }
}

RunSummary Simulation::summary() {
  RunSummary s;
  s.solver_kind = std::string(to_string(solver_.kind));
  s.converged = state_.u.allFinite();
  s.steps = steps_;
  s.substeps = substeps_;
  s.iterations = substeps_;
  s.stable_dt = stable_dt_;
  compute_internal_forces(model_, state_.u, ws_);
  s.reactions = support_reactions(model_, ws_.f_int);
  s.residual = relative_residual(model_, ws_.f_int);
  s.strain_energy = strain_energy(model_, state_.u).total();
  s.kinetic_energy = kinetic_energy(model_, state_.velocity);
  s.wall_s = step_seconds_;
  s.step_ms_mean = steps_ > 0 ? 1e3 * step_seconds_ / steps_ : 0;
  s.steps_per_s = step_seconds_ > 0 ? steps_ / step_seconds_ : 0;
  return s;
}

}  // namespace pointhaptics
