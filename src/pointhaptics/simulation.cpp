#include <pointhaptics/simulation.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/solvers/explicit_solver.hpp>
#include <pointhaptics/solvers/reactions.hpp>
#include <pointhaptics/solvers/static_solver.hpp>

#include <fmt/format.h>

#include <chrono>
#include <cmath>

namespace pointhaptics {

Simulation::Simulation(Model model, const SolverSpec& solver, int n_threads)
    : model_(std::move(model)), solver_(solver), state_(State::at_rest(model_)), ws_(model_, n_threads) {
  stable_dt_ = stable_time_step(model_);
  extra_forces_ = Points::Zero(3, model_.n_points);
  if (solver_.kind == SolverKind::STATIC) newton_ = std::make_unique<NewtonSolver>(model_);
  if (solver_.kind == SolverKind::IMPLICIT) implicit_ = std::make_unique<ImplicitSolver>(model_);
  // held points start at their prescribed displacement at t = 0
  for (const FixedGroup& group : model_.fixed_groups)
    for (index_t i : group.points) state_.u.col(i) = prescribed_displacement(group, 0.0);
}

Simulation::~Simulation() = default;
Simulation::Simulation(Simulation&&) noexcept = default;

NewtonSettings Simulation::newton_settings() const {
  NewtonSettings s;
  s.tolerance = solver_.tolerance > 0 ? solver_.tolerance : solver_.kind == SolverKind::STATIC ? 1e-8 : 1e-6;
  s.max_iterations = solver_.max_iterations;
  s.max_cg_iterations = solver_.max_cg_iterations;
  if (solver_.kind == SolverKind::IMPLICIT && solver_.iteration_budget > 0) {
    s.max_iterations = solver_.iteration_budget;
    s.accept_at_budget = true;
  }
  return s;
}

void Simulation::step() {
  const auto start = std::chrono::steady_clock::now();
  switch (solver_.kind) {
    case SolverKind::EXPLICIT: {
      // internal forces, then symplectic Euler, sub-stepped below the stable step
      const ExplicitStepStats stats = explicit_step(model_, state_, ws_, solver_.dt, stable_dt_, dynamic_forces_);
      substeps_ += stats.substeps;
      iterations_ += stats.substeps;
      break;
    }
    case SolverKind::IMPLICIT: {
      const Points* extra = nullptr;
      const Eigen::Matrix<double, 9, Eigen::Dynamic>* springs = nullptr;
      if (dynamic_forces_) {
        extra_forces_.setZero();
        dynamic_forces_->add(model_, state_, extra_forces_);
        extra = &extra_forces_;
        springs_.setZero(9, model_.n_points);
        if (dynamic_forces_->add_stiffness(model_, state_, springs_)) springs = &springs_;
      }
      const NewtonStats stats = implicit_->step(model_, state_, ws_, solver_.dt, newton_settings(), extra, springs);
      iterations_ += stats.iterations;
      cg_iterations_ += stats.cg_iterations;
      residual_ = stats.residual;
      converged_ = converged_ && stats.residual <= newton_settings().tolerance;
      break;
    }
    case SolverKind::STATIC: {
      const StaticStats stats = solve_static(model_, state_, ws_, *newton_, newton_settings());
      iterations_ += stats.iterations;
      cg_iterations_ += stats.cg_iterations;
      substeps_ += stats.load_steps;
      residual_ = stats.residual;
      converged_ = stats.converged;
      failure_ = stats.failure;
      break;
    }
  }
  ++steps_;
  step_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void Simulation::run(double duration, const std::function<void(double)>& progress) {
  if (solver_.kind == SolverKind::STATIC) {
    step();
    if (progress) progress(1.0);
    return;
  }
  const long long n_steps = std::llround(std::ceil(duration / solver_.dt - 1e-9));
  for (long long k = 0; k < n_steps; ++k) {
    step();
    if (progress) progress(static_cast<double>(k + 1) / n_steps);
  }
}

RunSummary Simulation::summary() {
  RunSummary s;
  s.solver_kind = std::string(to_string(solver_.kind));
  s.converged = state_.u.allFinite() && converged_;
  s.failure = failure_;
  s.steps = steps_;
  s.substeps = substeps_;
  s.iterations = iterations_;
  s.cg_iterations = cg_iterations_;
  s.stable_dt = stable_dt_;
  compute_internal_forces(model_, state_.u, ws_);
  s.reactions = support_reactions(model_, ws_.f_int);
  // dynamics is out of balance by the inertia; its Newton residual includes it
  s.residual = solver_.kind == SolverKind::IMPLICIT ? residual_ : relative_residual(model_, ws_.f_int);
  s.strain_energy = strain_energy(model_, state_.u).total();
  s.kinetic_energy = kinetic_energy(model_, state_.velocity);
  s.wall_s = step_seconds_;
  s.step_ms_mean = steps_ > 0 ? 1e3 * step_seconds_ / steps_ : 0;
  s.steps_per_s = step_seconds_ > 0 ? steps_ / step_seconds_ : 0;
  return s;
}

}  // namespace pointhaptics
