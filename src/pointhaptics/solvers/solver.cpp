#include <pointhaptics/solvers/solver.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/mechanics/inversion.hpp>
#include <pointhaptics/solvers/explicit_solver.hpp>
#include <pointhaptics/solvers/implicit_solver.hpp>
#include <pointhaptics/solvers/static_solver.hpp>

#include <algorithm>
#include <cmath>

namespace pointhaptics {

NewtonSettings newton_settings(const SolverSpec& spec) {
  NewtonSettings s;
  s.tolerance = spec.tolerance > 0 ? spec.tolerance : spec.kind == SolverKind::STATIC ? 1e-8 : 1e-6;
  s.max_iterations = spec.max_iterations;
  s.max_cg_iterations = spec.max_cg_iterations;
  s.preconditioner = spec.preconditioner;
  s.refactor_iterations = spec.refactor_iterations;
  s.refactorisation = spec.refactorisation;
  if (spec.kind == SolverKind::IMPLICIT && spec.iteration_budget > 0) {
    s.max_iterations = spec.iteration_budget;
    s.accept_at_budget = true;
  }
  return s;
}

index_t Solver::count_inverted(const Model& model, const State& /*state*/, Workspace& ws) {
  return pointhaptics::count_inverted(model, ws);
}

std::unique_ptr<Solver> make_solver(const Model& model, const SolverSpec& spec, double stable_dt) {
  switch (spec.kind) {
    case SolverKind::EXPLICIT: return std::make_unique<ExplicitSolver>(model, spec.dt, stable_dt);
    case SolverKind::IMPLICIT: return std::make_unique<ImplicitSolver>(model, spec.dt, newton_settings(spec));
    case SolverKind::STATIC: return std::make_unique<StaticSolver>(model, newton_settings(spec));
  }
  throw Error("solver: unknown kind");
}

Vec3 prescribed_displacement(const FixedGroup& group, double t) {
  const double s = group.ramp > 0 ? std::clamp(t / group.ramp, 0.0, 1.0) : 1.0;
  return s * group.displacement;
}

void hold_points(const Model& model, double t, Points& u, Points* velocity, double h, double load_factor) {
  for (const FixedGroup& group : model.fixed_groups) {
    const Vec3 target = load_factor * prescribed_displacement(group, t);
    for (const index_t i : group.points) {
      if (velocity && h > 0) velocity->col(i) = (target - u.col(i)) / h;
      u.col(i) = target;
    }
  }
}

}  // namespace pointhaptics
