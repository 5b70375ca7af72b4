#pragma once
/// @file The simulation: a Model, its State and the solver's Workspace, and the step pipeline.
#include <pointhaptics/core/state.hpp>
#include <pointhaptics/core/workspace.hpp>
#include <pointhaptics/io/result_json.hpp>
#include <pointhaptics/io/scene.hpp>

#include <functional>

namespace pointhaptics {

class Simulation {
 public:
  /// Take the model (never written again) and prepare the solver; n_threads = 0: all hardware threads.
  /// Throws Error for a solver kind this version does not provide.
  Simulation(Model model, const SolverSpec& solver, int n_threads = 0);

  /// Advance by one solver step (dt).
  void step();
  /// Step until state().time reaches `duration`; progress(fraction) is called after each step.
  void run(double duration, const std::function<void(double)>& progress = {});

  const Model& model() const { return model_; }
  const State& state() const { return state_; }
  /// Replace the state (same model); used by tests and by replay.
  void set_state(const State& state) { state_ = state; }
  const SolverSpec& solver() const { return solver_; }
  double stable_dt() const { return stable_dt_; }

  /// Results at the current state: energies, reactions, residual, timing.
  RunSummary summary();

 private:
  Model model_;
  SolverSpec solver_;
  State state_;
  Workspace ws_;
  double stable_dt_ = 0;
  long long steps_ = 0, substeps_ = 0;
  double step_seconds_ = 0;
};

}  // namespace pointhaptics
