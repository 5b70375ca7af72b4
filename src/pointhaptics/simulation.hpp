#pragma once
/// @file The simulation: a Model, its State and the solver's Workspace, and the step pipeline.
#include <pointhaptics/core/state.hpp>
#include <pointhaptics/core/workspace.hpp>
#include <pointhaptics/io/result_json.hpp>
#include <pointhaptics/io/scene.hpp>
#include <pointhaptics/lod/active_set.hpp>
#include <pointhaptics/solvers/explicit_solver.hpp>
#include <pointhaptics/solvers/implicit_solver.hpp>
#include <pointhaptics/solvers/newton.hpp>
#include <pointhaptics/solvers/static_solver.hpp>

#include <functional>
#include <memory>

namespace pointhaptics {

struct LodBuild;  // simulation.cpp

class Simulation {
 public:
  /// Take the model (never written again) and prepare the solver; n_threads = 0: all hardware threads.
  Simulation(Model model, const SolverSpec& solver, int n_threads = 0);
  ~Simulation();
  Simulation(Simulation&&) noexcept;

  /// Advance by one solver step (dt): explicit (sub-stepped) or implicit dynamics; for a static solver,
  /// solve for the equilibrium under the full load (once; later calls start from the last solution).
  void step();
  /// Dynamics: step until state().time reaches `duration` (ceil(duration / dt) steps); static: one solve.
  /// after_step(step, n_steps), if given, is called after each step; returning false stops the run there
  /// (an interrupted run keeps the state reached).
  void run(double duration, const std::function<bool(long long step, long long n_steps)>& after_step = {});

  /// The simulated model and its state: the whole object, or with levels of detail the active set.
  const Model& model() const { return model_; }
  const State& state() const { return state_; }

  /// Levels of detail (seed §3): from now on simulate only the points selected around `contact` (the
  /// reference configuration, m; snapped to the nearest point of the object); model() becomes the active
  /// set and full_model() the object. Throws Error on bad parameters.
  void enable_lod(const LodParams& params, const Vec3& contact);
  bool lod_enabled() const { return lod_ != nullptr; }
  /// Re-select when the contact point is farther than params.reselect h from the one of the last
  /// selection, or at contact onset (`onset`) when it is farther than a quarter of that. The state
  /// carries over: the active state goes back to the object (absorbed points follow by MLS), the new
  /// active set takes its points' displacements and velocities. `asynchronous`: the new active set is
  /// built on a worker thread while this one keeps stepping the old one, and takes over at the first call
  /// after it is ready (the contact may have moved meanwhile; the next call re-selects again if so).
  /// Returns the new index of each old active point (-1 if no longer simulated) when a new active set
  /// took over, else an empty vector. Allocates (a new model): not a per-step operation.
  std::vector<index_t> update_lod(const Vec3& contact, bool onset = false, bool asynchronous = false);
  /// The contact point of a probe at `probe` for update_lod(), in the reference configuration: when
  /// grabbing (`grabbed`: indices into model()), where the grabbed points are in the object; when pushing,
  /// the probe carried back by the mean displacement of the `touched` points (the probe itself if none).
  Vec3 lod_contact_of_probe(const Vec3& probe, const std::vector<index_t>& grabbed = {},
                            const std::vector<index_t>& touched = {}) const;
  const Model& full_model() const;
  /// The object's state (with levels of detail: the active state carried back; absorbed points follow
  /// their selected point by first-order MLS, the rest keep their last displacement).
  const State& full_state();
  const ActiveSet* active_set() const;
  /// The selection the active set was built from (nullptr without levels of detail).
  const Selection* lod_selection() const;
  /// Selections made so far (0 without levels of detail): a new one means a new active set.
  long long lod_selections() const;
  /// Replace the state (same model); used by tests and by replay.
  void set_state(const State& state);
  const SolverSpec& solver() const { return solver_; }
  /// State-dependent forces added at every dynamic step (probe contact): explicit dynamics evaluates them
  /// at every sub-step, implicit dynamics once per step (held over it). Not owned; nullptr: none.
  void set_dynamic_forces(DynamicForces* forces) { dynamic_forces_ = forces; }
  double stable_dt() const { return stable_dt_; }

  /// Results at the current state: energies, reactions, residual, timing.
  RunSummary summary();

 private:
  NewtonSettings newton_settings() const;
  void step_solver();
  void prepare_solver(double stable_dt = 0);  // for model_: stable step (0: compute it), solver objects
  std::vector<index_t> take_over(LodBuild build, bool built_here);
  struct Lod;
  std::unique_ptr<Lod> lod_;

  Model model_;
  SolverSpec solver_;
  State state_;
  Workspace ws_;
  int n_threads_ = 0;
  Points extra_forces_;
  Eigen::Matrix<double, 9, Eigen::Dynamic> springs_;
  DynamicForces* dynamic_forces_ = nullptr;
  std::unique_ptr<StaticSolver> static_;      ///< static
  std::unique_ptr<ImplicitSolver> implicit_;  ///< implicit
  double stable_dt_ = 0;
  long long steps_ = 0, substeps_ = 0, iterations_ = 0, cg_iterations_ = 0;
  bool converged_ = true;
  long long budget_steps_ = 0;  ///< implicit steps the iteration budget ended above the tolerance
  double residual_ = 0;
  std::string failure_;
  double step_seconds_ = 0;
};

}  // namespace pointhaptics
