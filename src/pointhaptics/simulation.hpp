#pragma once
/// @file The simulation: a Model, its State and the solver's Workspace, and the step pipeline.
#include <pointhaptics/core/state.hpp>
#include <pointhaptics/core/workspace.hpp>
#include <pointhaptics/haptics/probe_tool.hpp>
#include <pointhaptics/io/result_json.hpp>
#include <pointhaptics/io/scene.hpp>
#include <pointhaptics/lod/active_set.hpp>
#include <pointhaptics/solvers/solver.hpp>

#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace pointhaptics {

struct LodBuild;  // simulation.cpp

/// What a step takes from outside the object. The caller fills it between steps (MuJoCo's step1/step2:
/// read the last step's outputs, set the inputs, step); the step reads it in its first stage.
struct StepInputs {
  Vec3 device = Vec3::Constant(NAN);  ///< the probe's device point in the scene, m (NaN: the probe is lifted off)
  bool button = false;                ///< the device's button (grab)
};

/// Counters and timers of the steps so far: the simulation's diagnostics, read by summary().
struct StepDiagnostics {
  long long steps = 0;          ///< steps taken (a static solve is one)
  long long substeps = 0;       ///< explicit sub-steps, static load increments
  long long iterations = 0;     ///< Newton iterations (explicit: sub-steps)
  long long cg_iterations = 0;
  long long budget_steps = 0;   ///< implicit steps the iteration budget ended above the tolerance
  double residual = 0;          ///< the last Newton residual
  StepStatus status = StepStatus::CONVERGED;  ///< of the last step
  bool failed = false;          ///< a step failed: the state is not a result, and no step follows
  std::string failure;          ///< why
  double step_seconds = 0;      ///< wall time in steps, s, and in its stages:
  double active_set_seconds = 0, tools_seconds = 0, solve_seconds = 0;
};

class Simulation {
 public:
  /// Take the model (never written again) and prepare the solver; n_threads = 0: all hardware threads.
  Simulation(Model model, const SolverSpec& solver, int n_threads = 0);
  ~Simulation();
  Simulation(Simulation&&) noexcept;

  /// One step, as a table of contents (simulation.cpp): the inputs -> the active set (levels of detail follow
  /// the probe) -> the tools placed -> the solver (forces and time integration, held points) -> the finite
  /// check -> the outputs published. Dynamics: dt (explicit: sub-stepped below the stable step); static: the
  /// equilibrium under the full load (later calls start from the last solution). Never throws for a step that
  /// fails numerically: the report says FAILED and why, diagnostics() keeps it, and a further step throws
  /// Error (a failed state is not a result). Throws Error for a step after a failed one.
  const StepReport& step();
  /// Dynamics: step until state().time reaches `duration` (ceil(duration / dt) steps); static: one solve.
  /// Stops at a failed step (diagnostics().failed says so). after_step(step, n_steps), if given, is called
  /// after each step; returning false stops the run there (an interrupted run keeps the state reached).
  void run(double duration, const std::function<bool(long long step, long long n_steps)>& after_step = {});
  /// Filled by the caller before a step (MuJoCo's step1/step2).
  StepInputs& inputs() { return inputs_; }
  const StepDiagnostics& diagnostics() const { return diagnostics_; }

  /// A probe from now on (dynamics only): placed at every step on a coupling spring of `coupling_stiffness`
  /// (N/m) toward inputs().device, its force capped at `max_force` (N), pushing or grabbing the points.
  /// With levels of detail the active set follows its contact point, re-selected on a worker thread when
  /// `asynchronous_lod` (real time) and in place otherwise (reproducible runs).
  void attach_probe(const ProbeParams& params, double coupling_stiffness, double max_force, bool asynchronous_lod);
  void detach_probe();
  /// The probe (nullptr without one): its position, contact set and last local contact model.
  const ProbeTool* probe() const { return probe_ ? &*probe_ : nullptr; }

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
  double stable_dt() const { return stable_dt_; }

  /// Results at the current state: energies, reactions, residual, timing.
  RunSummary summary();

 private:
  // the stages of step()
  void follow_contact();
  void place_tools();
  void check_finite(StepReport& report) const;
  void record(const StepReport& report, double seconds);

  void prepare_solver(double stable_dt = 0);  // for model_: the solver (stable step 0: compute it)
  std::vector<index_t> take_over(LodBuild build, bool built_here);
  struct Lod;
  std::unique_ptr<Lod> lod_;

  Model model_;
  SolverSpec solver_;
  State state_;
  Workspace ws_;
  int n_threads_ = 0;
  std::unique_ptr<Solver> solver_impl_;
  double stable_dt_ = 0;
  StepInputs inputs_;
  StepReport report_;
  StepDiagnostics diagnostics_;
  std::optional<ProbeTool> probe_;
  bool asynchronous_lod_ = false;
};

}  // namespace pointhaptics
