#pragma once
/// @file What every solver is: one step of a model's state, reported the same way by all three (explicit,
/// implicit, static). The simulation's step pipeline (simulation.cpp) calls it between its other stages.
#include <pointhaptics/core/parameters.hpp>
#include <pointhaptics/core/state.hpp>
#include <pointhaptics/core/workspace.hpp>
#include <pointhaptics/solvers/newton.hpp>

#include <memory>
#include <string>

namespace pointhaptics {

/// Forces that depend on the state (a tool's contact), evaluated by the solver where it needs them: at
/// every explicit sub-step (so that stiff contact springs are integrated at the stable sub-step, not held
/// over a whole step), once per implicit step (linearised about the step's start).
class DynamicForces {
 public:
  virtual ~DynamicForces() = default;
  /// Add the forces (N) at `state` into f (3 x n).
  virtual void add(const Model& model, const State& state, Points& f) = 0;
  /// The forces' stiffness -df_i/du_i per point (3x3, column-major, 9 x n, N/m, symmetric positive
  /// semi-definite), added into `springs`, for implicit steps; false if there is none to add. Called
  /// after add() at the same state.
  virtual bool add_stiffness(const Model&, const State&, Eigen::Matrix<double, 9, Eigen::Dynamic>&) { return false; }
  /// The largest stiffness (N/m) these forces can put on one point (an upper bound of the largest
  /// eigenvalue of its 3x3 block), for the explicit stable step; 0 if they have no springs.
  virtual double max_point_stiffness() const { return 0; }
  /// The forces as a term of the energy, which the Newton solvers (static, implicit) minimise with the
  /// material's instead of calling add() and add_stiffness(); nullptr if they have none.
  virtual EnergyTerm* energy_term() { return nullptr; }
  /// The forces that are not in energy_term(), added into f at `state` (the Newton solvers take them as loads,
  /// with add_stiffness()'s springs): true if there were any. By default all of add() when there is no term.
  virtual bool add_beyond_energy(const Model& model, const State& state, Points& f) {
    if (energy_term()) return false;
    add(model, state, f);
    return true;
  }
  /// Once per step, after it, at the state it reached (a probe's local contact model for the haptic side);
  /// `ws` is the step's workspace (its threads; what it holds is the solver's, for the next step).
  virtual void after_step(const Model&, const State&, Workspace&) {}
};

enum class StepStatus {
  CONVERGED,  ///< the step is a result (explicit: finite and bounded; Newton: within the tolerance)
  AT_BUDGET,  ///< implicit in real time: the iteration budget ended the step above the tolerance, as asked
  FAILED,     ///< not a result: `failure` says why (divergence, Newton or load stepping gave up)
};

/// What one step did. Every solver reports the same way and none throws for a step that fails
/// numerically: the pipeline records the report, and a failed state is never stepped again.
struct StepReport {
  StepStatus status = StepStatus::CONVERGED;
  int substeps = 0;                   ///< explicit sub-steps, or static load increments
  int iterations = 0;                 ///< Newton iterations (explicit: the sub-steps)
  long long cg_iterations = 0;        ///< CG iterations, summed
  int factorisations = 0;             ///< preconditioner = "cholesky": numeric factorisations of the tangent
  int background_factorisations = 0;  ///< ... of them, made on a worker thread
  double factor_bytes = 0;            ///< ... and the factor's size, bytes (0: none; "two_level": the coarse factor's)
  index_t coarse_points = 0;          ///< preconditioner = "two_level": the coarse level's points (0: none)
  double residual = 0;                ///< Newton's relative residual at the end (0 for explicit steps)
  std::string failure;                ///< why the step FAILED (empty otherwise; allocated only then)
};

/// One step of a model's state. A solver is made for one model and keeps buffers sized for it, so that a
/// step allocates nothing; held points follow their prescribed displacement inside the step.
class Solver {
 public:
  virtual ~Solver() = default;
  /// Dynamics: advance `state` by the solver's dt; static: solve for the equilibrium under the full load
  /// (later calls start from the last solution). `forces`: the tools' state-dependent forces (nullptr:
  /// none). Never throws for a numerical failure (the report says FAILED and why).
  virtual StepReport step(const Model& model, State& state, Workspace& ws, DynamicForces* forces) = 0;
  /// The explicit stable step at rest, s (0 for the others).
  virtual double stable_dt() const { return 0; }
  /// A solver made for a new model of the same object (a level of detail's new active set, a cut) takes over
  /// what `previous` carried from step to step about the object's state (explicit: the planned stiffening).
  virtual void continue_from(const Solver& /*previous*/) {}
  /// Whether the simulation runs on the wall clock (a probe in real time): work that can run off the
  /// simulation's thread (the Cholesky preconditioner's refactorisation) is then taken up when it is ready
  /// instead of at a reproducible point.
  virtual void set_real_time(bool /*real_time*/) {}
  /// The neighbourhoods inverted (det F <= 0) at `state`, the last step's result, for the step's diagnostics: by
  /// default those of the gradients its force evaluations left in `ws` (mechanics/inversion.hpp); a solver that
  /// leaves none there answers from `state` itself.
  virtual index_t count_inverted(const Model& model, const State& state, Workspace& ws);
  /// A solver whose step leaves the state's displacement and velocity to be written when something reads them (a
  /// reduced model's u = U q and v = U q': two products with the 3n x r basis, several times its step) says so
  /// here, and publish() writes them; the simulation calls it before anything reads the state
  /// (ModelSimulation::state()). Others write the state in the step: false, and nothing to do.
  virtual bool unpublished() const { return false; }
  /// the displacement unwritten (tools read it at every step; a solver may write it and leave the velocity)
  virtual bool displacement_unpublished() const { return unpublished(); }
  virtual void publish(State& /*state*/, Workspace& /*ws*/) {}
};

/// The solver a spec asks for, for `model`. `stable_dt`: explicit only, the stable step if already known
/// (0: compute it, ~40 tangent products).
std::unique_ptr<Solver> make_solver(const Model& model, const SolverSpec& spec, double stable_dt = 0);

/// Newton's settings for a spec: its tolerance (default 1e-8 static, 1e-6 implicit), iterations, and for
/// implicit real time the iteration budget, whose last iterate is kept.
NewtonSettings newton_settings(const SolverSpec& spec);

/// Held points at their prescribed displacement at time t (ramped in over each group's ramp), times
/// `load_factor` (static load stepping scales them with the load). With a velocity and a step h > 0 their
/// velocity becomes the motion over that step. The one loop over held points of every solver.
void hold_points(const Model& model, double t, Points& u, Points* velocity = nullptr, double h = 0,
                 double load_factor = 1);

/// Prescribed displacement of a fixed group at time t (ramped in linearly over group.ramp).
Vec3 prescribed_displacement(const FixedGroup& group, double t);

}  // namespace pointhaptics
