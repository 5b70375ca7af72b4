#pragma once
/// @file The simulation: a Model, its State and the solver's Workspace, and the step pipeline.
#include <pointhaptics/core/state.hpp>
#include <pointhaptics/core/workspace.hpp>
#include <pointhaptics/io/result_json.hpp>
#include <pointhaptics/io/scene.hpp>
#include <pointhaptics/solvers/explicit_solver.hpp>
#include <pointhaptics/solvers/implicit_solver.hpp>
#include <pointhaptics/solvers/newton.hpp>

#include <functional>
#include <memory>

namespace pointhaptics {

class Simulation {
 public:
  /// Take the model (never written again) and prepare the solver; n_threads = 0: all hardware threads.
  Simulation(Model model, const SolverSpec& solver, int n_threads = 0);
  ~Simulation();
  Simulation(Simulation&&) noexcept;

  /// Advance by one solver step (dt): explicit (sub-stepped) or implicit dynamics; for a static solver,
  /// solve for the equilibrium under the full load (once; later calls start from the last solution).
  void step();
  /// Dynamics: step until state().time reaches `duration`; static: one solve. progress(fraction) is
  /// called after each step.
  void run(double duration, const std::function<void(double)>& progress = {});

  const Model& model() const { return model_; }
  const State& state() const { return state_; }
  /// Replace the state (same model); used by tests and by replay.
  void set_state(const State& state) { state_ = state; }
  const SolverSpec& solver() const { return solver_; }
  /// State-dependent forces added at every dynamic step (probe contact): explicit dynamics evaluates them
  /// at every sub-step, implicit dynamics once per step (held over it). Not owned; nullptr: none.
  void set_dynamic_forces(DynamicForces* forces) { dynamic_forces_ = forces; }
  double stable_dt() const { return stable_dt_; }

  /// Results at the current state: energies, reactions, residual, timing.
  RunSummary summary();

 private:
  NewtonSettings newton_settings() const;

  Model model_;
  SolverSpec solver_;
  State state_;
  Workspace ws_;
  Points extra_forces_;
  Eigen::Matrix<double, 9, Eigen::Dynamic> springs_;
  DynamicForces* dynamic_forces_ = nullptr;
  std::unique_ptr<NewtonSolver> newton_;      ///< static
  std::unique_ptr<ImplicitSolver> implicit_;  ///< implicit
  double stable_dt_ = 0;
  long long steps_ = 0, substeps_ = 0, iterations_ = 0, cg_iterations_ = 0;
  bool converged_ = true;
  double residual_ = 0;
  std::string failure_;
  double step_seconds_ = 0;
};

}  // namespace pointhaptics
