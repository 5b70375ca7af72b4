#pragma once
/// @file Explicit dynamics: symplectic Euler with automatic sub-steps below the stable step.
#include <pointhaptics/core/state.hpp>
#include <pointhaptics/core/workspace.hpp>

namespace pointhaptics {

/// Largest stable explicit step, s: safety x 2 / omega_max, the symplectic Euler limit, with omega_max^2 the
/// largest eigenvalue of M^-1 K at rest (free points) from 40 Lanczos steps on the matrix-free tangent.
/// The safety (0.8) covers Lanczos approaching omega_max from below and the stiffening of large strains.
/// On the shipped scenes this is 1.25-1.4x the older estimate below; costs ~40 tangent products, once.
/// `lanczos_steps`: 40 by default; 20 already lands within 0.2% of it on the models measured (a 13k-point
/// half-sphere) and halves the cost, which level-of-detail re-selection uses.
double stable_time_step(const Model& model, double safety = 0.8, int lanczos_steps = 40);

/// The older, cheaper estimate: safety x a / c_p with a the smallest point distance and c_p the p-wave
/// speed sqrt((lambda + 2 mu + k_v + alpha E) / rho) of the densest point. Used when Lanczos cannot run.
double estimated_stable_time_step(const Model& model, double safety = 0.7);

/// Prescribed displacement of a fixed group at time t (ramped in linearly over group.ramp).
Vec3 prescribed_displacement(const FixedGroup& group, double t);

struct ExplicitStepStats {
  int substeps = 0;  ///< sub-steps taken for this step
};

/// Advance the state by dt with ceil(dt / stable step) equal symplectic Euler sub-steps:
///   v <- (v + h M^-1 (f_int + f_ext)) / (1 + h c),   u <- u + h v   (c: mass-proportional damping)
/// Held points follow their prescribed displacement. Throws Error naming the step and point if a
/// displacement becomes non-finite or grows beyond 100 times the object's size (divergence).
/// Forces that depend on the state and are evaluated at every sub-step (e.g. probe contact), so that
/// stiff contact springs are integrated at the stable sub-step, not held over a whole step.
class DynamicForces {
 public:
  virtual ~DynamicForces() = default;
  /// Add the forces (N) at `state` into f (3 x n).
  virtual void add(const Model& model, const State& state, Points& f) = 0;
  /// The forces' stiffness -df_i/du_i per point (3x3, column-major, 9 x n, N/m, symmetric positive
  /// semi-definite), added into `springs`, for implicit steps; false if there is none to add. Called
  /// after add() at the same state.
  virtual bool add_stiffness(const Model&, const State&, Eigen::Matrix<double, 9, Eigen::Dynamic>&) { return false; }
};

/// extra, if given, is evaluated at every sub-step and added to the constant loads.
ExplicitStepStats explicit_step(const Model& model, State& state, Workspace& ws, double dt, double stable_dt,
                                DynamicForces* extra = nullptr);

}  // namespace pointhaptics
