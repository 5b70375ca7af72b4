#pragma once
/// @file Static equilibrium: Newton with line search on the total potential energy, with automatic
/// load stepping when a full step fails.
#include <pointhaptics/solvers/solver.hpp>

namespace pointhaptics {

struct StaticStats {
  bool converged = false;
  int iterations = 0;  ///< Newton iterations over all load steps
  long long cg_iterations = 0;
  int factorisations = 0;             ///< preconditioner = "cholesky": numeric factorisations of the tangent
  int background_factorisations = 0;  ///< ... of them, made on a worker thread
  int projected = 0;                  ///< Newton iterations that used the positive semi-definite tangent
  int load_steps = 0;                 ///< converged load increments
  int cutbacks = 0;                   ///< failed increments that were retried with a smaller one
  double residual = 0;                ///< relative residual at the end
  int multiplier_updates = 0;  ///< with a constrained term (a tool's contact): its augmented Lagrangian's updates
  std::string failure;         ///< why it did not converge
};

/// Solve f_int(u) + f_ext = 0 on the free points, with held points at their prescribed displacement.
/// Starts from state.u (e.g. the rest state) and takes the whole load at once; when Newton fails it
/// halves the load increment (down to 1e-4 of the load) and grows it again after successes. The load
/// factor scales f_ext and the prescribed displacements together. state.u holds the last converged
/// equilibrium (the full load when converged); velocity is set to zero. `term`: a further energy (a tool's
/// contact) minimised with the rest; a constrained one is solved again after each update of its multipliers
/// until its constraint is met (at most 50 updates, else the solve fails saying so).
StaticStats solve_static(const Model& model, State& state, Workspace& ws, NewtonSolver& newton,
                         const NewtonSettings& settings, EnergyTerm* term = nullptr);

/// solve_static() as a Solver; its buffers are the workspace's, sized once for the model, so that a solve
/// allocates nothing. A solve that does not reach the full load is FAILED (the state holds
/// the last converged equilibrium).
class StaticSolver final : public Solver {
 public:
  StaticSolver(const Model& model, const NewtonSettings& settings);
  StepReport step(const Model& model, State& state, Workspace& ws, DynamicForces* forces) override;

 private:
  NewtonSettings settings_;
  NewtonSolver newton_;  // its vectors and the increment's are the workspace's (Workspace::solver_scratch())
};

}  // namespace pointhaptics
