#pragma once
/// @file Explicit dynamics: symplectic Euler with automatic sub-steps below the stable step.
#include <pointhaptics/solvers/solver.hpp>

namespace pointhaptics {

/// Largest stable explicit step, s: safety x 2 / omega_max, the symplectic Euler limit, with omega_max^2 the
/// largest eigenvalue of M^-1 K at rest (free points) from 40 Lanczos steps on the matrix-free tangent.
/// The safety (0.8) covers Lanczos approaching omega_max from below and the stiffening of large strains.
/// On the shipped scenes this is 1.25-1.4x the older estimate below; costs ~40 tangent products, once.
/// `lanczos_steps`: 40 by default; 20 already lands within 0.2% of it on the models measured (a 13k-point
/// half-sphere) and halves the cost, which level-of-detail re-selection uses.
/// `n_threads`: for the tangent products (1 by default: a level-of-detail build on a worker thread must not
/// take the simulation's cores; 0: all).
/// `focus`: start Lanczos on these points only (random there, zero elsewhere), to find in a few steps the
/// fastest modes a local change made there (a cut); empty: everywhere.
double stable_time_step(const Model& model, double safety = 0.8, int lanczos_steps = 40, int n_threads = 1,
                        const std::vector<index_t>& focus = {});

/// stable_time_step() of the patch of the model within `rings` neighbour steps of `around` (a cut's points), the
/// ring beyond held (mechanics/model_patch.hpp), started on `around`: the fastest modes a local change made,
/// at the cost of the patch. The patch's tangent is the model's restricted to it, so its modes are the model's
/// held at the patch's edge: a mode that reaches beyond the patch is found slower than it is, and `rings` must
/// cover the change's reach (tests/simulation_test.cpp checks it against Lanczos on the whole model).
double local_stable_time_step(const Model& model, const std::vector<index_t>& around, int rings, double safety = 0.8,
                              int lanczos_steps = 12);

/// The older, cheaper estimate: safety x a / c_p with a the smallest point distance and c_p the p-wave
/// speed sqrt((lambda + 2 mu + k_v + alpha E) / rho) of the densest point. Used when Lanczos cannot run.
double estimated_stable_time_step(const Model& model, double safety = 0.7);

/// The stable step once springs of up to `spring_stiffness` (N/m, the largest eigenvalue of one point's
/// 3x3 spring block) act on points of mass at least `min_mass` (kg): omega_max^2 of M^-1 (K + S) is at
/// most omega_K^2 + spring_stiffness / min_mass (Weyl), so the step shrinks to safety x 2 / sqrt of that.
/// `stable_dt` is the springless step stable_time_step() gave with the same safety.
double stable_time_step_with_springs(double stable_dt, double spring_stiffness, double min_mass, double safety = 0.8);

/// The largest material stiffening() (energies/svk.hpp) over the gradients of the workspace's last force evaluation (1 at rest):
/// the factor by which the material is stiffer than the rest state the stable step was computed for.
double strain_stiffening(const Model& model, Workspace& ws);

/// The lightest free point's mass, kg (infinity if none is free).
double min_free_mass(const Model& model);

/// Advance the state by dt with ceil(dt / stable step) equal symplectic Euler sub-steps, the stable step
/// shortened for the springs of `forces` (stable_time_step_with_springs) and by sqrt(1.25 / strain_stiffening())
/// where the material, at the state the step starts from, is stretched by more than its safety factor covers:
///   v <- (v + h M^-1 (f_int + f_ext + f_tools)) / (1 + h c),   u <- u + h v   (c: mass-proportional damping)
/// Held points follow their prescribed displacement. A displacement that becomes non-finite or grows
/// beyond 100 times the object's size (divergence) ends the step FAILED, naming the time and the point.
/// `forces`, if given, are evaluated at every sub-step. `planned_stiffening`, if given, carries the stiffening
/// the sub-steps were planned for from step to step: it rises with the material's at once and falls back to
/// it over about half a second, so that the sub-step does not swing with an oscillation's phase (which pumps
/// energy into it); without it each step plans for the stiffening of the state it starts from alone.
StepReport explicit_step(const Model& model, State& state, Workspace& ws, double dt, double stable_dt,
                         DynamicForces* forces = nullptr, double* planned_stiffening = nullptr);

/// explicit_step() as a Solver: steps of `dt` below the model's stable step.
class ExplicitSolver final : public Solver {
 public:
  /// stable_dt: the model's stable step if already known (0: stable_time_step(model)).
  ExplicitSolver(const Model& model, double dt, double stable_dt = 0);
  StepReport step(const Model& model, State& state, Workspace& ws, DynamicForces* forces) override;
  double stable_dt() const override { return stable_dt_; }
  void continue_from(const Solver& previous) override;
  /// The stiffening its next step plans for at least (relaxing), explicit_step()'s planned_stiffening.
  double planned_stiffening() const { return planned_stiffening_; }

 private:
  double dt_, stable_dt_;
  double planned_stiffening_ = 1;  ///< explicit_step()'s, carried across steps
};

}  // namespace pointhaptics
