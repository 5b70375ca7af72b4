#include <pointhaptics/reduction/reduced_solver.hpp>

#include <pointhaptics/core/error.hpp>

#include <fmt/format.h>

#include <chrono>

namespace pointhaptics {

ReducedSolver::ReducedSolver(const Model& model, const SolverSpec& spec, Workspace& ws) : spec_(spec) {
  const auto start = std::chrono::steady_clock::now();
  if (spec.kind == SolverKind::EXPLICIT)
    throw Error(
        "reduction: needs solver.kind = \"implicit\" or \"static\" (a reduced model is stepped by Newton in "
        "its coordinates; explicit steps would gain nothing)");
  for (const FixedGroup& group : model.fixed_groups)
    if (group.displacement.squaredNorm() > 0)
      throw Error(
          fmt::format("reduction: {} moves its points (displacement); a reduced model's held points stay at "
                      "rest (not yet otherwise)",
                      group.name));
  ModalBasisSettings settings;
  settings.size = spec.reduction.modes;
  if (spec.reduction.basis_spacing > 0) {
    // the basis of a coarser sampling, carried to the points: the set-up's factor tens of times smaller
    const Model coarse = coarse_model(model, spec.reduction.basis_spacing);
    Workspace coarse_ws(coarse, ws.n_threads());
    if (coarse.f_ext.squaredNorm() > 0) settings.loads = {coarse.f_ext};
    basis_ = carry_basis(build_modal_basis(coarse, settings, coarse_ws), coarse, model);
  } else {
    if (model.f_ext.size() == 3 * model.n_points && model.f_ext.squaredNorm() > 0) settings.loads = {model.f_ext};
    basis_ = build_modal_basis(model, settings, ws);
  }
  polynomial_ = std::make_unique<SvkPolynomial>(model, basis_.U, ws);
  Eigen::VectorXd external = Eigen::VectorXd::Zero(spec.reduction.modes);
  if (model.f_ext.size() == 3 * model.n_points)
    external = basis_.U.transpose() * Eigen::Map<const Eigen::VectorXd>(model.f_ext.data(), model.f_ext.size());
  integrator_ = std::make_unique<ReducedIntegrator>(*polynomial_, std::move(external), model.material.damping);
  reduced_.q = Eigen::VectorXd::Zero(spec.reduction.modes);
  reduced_.v = Eigen::VectorXd::Zero(spec.reduction.modes);
  setup_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

StepReport ReducedSolver::step(const Model& model, State& state, Workspace& /*ws*/, DynamicForces* forces) {
  StepReport report;
  if (forces) {
    report.status = StepStatus::FAILED;
    report.failure = "reduction: tools, probes and contact are not reduced yet (issue 49, item 2)";
    return report;
  }
  const double tolerance = spec_.tolerance > 0 ? spec_.tolerance : spec_.kind == SolverKind::STATIC ? 1e-8 : 1e-6;
  ReducedSolveReport solved;
  if (spec_.kind == SolverKind::STATIC) {
    solved = integrator_->solve_static(reduced_.q, tolerance, spec_.max_iterations);
    reduced_.v.setZero();
  } else {
    const bool budget = spec_.iteration_budget > 0;
    solved = integrator_->step(reduced_, spec_.dt, tolerance, budget ? spec_.iteration_budget : spec_.max_iterations,
                               budget);
    state.time += spec_.dt;
  }
  report.iterations = solved.iterations;
  report.substeps = 1;
  report.residual = solved.residual;
  report.status = solved.converged   ? StepStatus::CONVERGED
                  : solved.at_budget ? StepStatus::AT_BUDGET
                                     : StepStatus::FAILED;
  if (report.status == StepStatus::FAILED) {
    report.failure =
        spec_.kind == SolverKind::STATIC
            ? fmt::format("reduced static solve: no equilibrium beyond {:.3g} of the load", solved.load_reached)
            : fmt::format("reduced step: Newton did not converge in {} iterations (residual {:.3g})", solved.iterations,
                          solved.residual);
    return report;
  }
  Eigen::Map<Eigen::VectorXd>(state.u.data(), state.u.size()).noalias() = basis_.U * reduced_.q;
  Eigen::Map<Eigen::VectorXd>(state.velocity.data(), state.velocity.size()).noalias() = basis_.U * reduced_.v;
  (void)model;
  return report;
}

}  // namespace pointhaptics
