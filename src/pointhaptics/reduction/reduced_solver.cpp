#include <pointhaptics/reduction/reduced_solver.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/mechanics/inversion.hpp>
#include <pointhaptics/reduction/basis_cache.hpp>

#include <Eigen/Eigenvalues>

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <numbers>

namespace pointhaptics {

void ReducedSolver::make_or_read_basis(const Model& model, Workspace& ws) {
  ModalBasisSettings settings;
  settings.size = spec_.reduction.modes;
  const std::string cache_dir = spec_.reduction.cache == "auto" ? default_basis_cache_dir() : spec_.reduction.cache;
  const std::uint64_t key = cache_dir.empty() ? 0 : basis_key(model, settings, spec_.reduction.basis_spacing);
  if (!cache_dir.empty()) {
    cache_file_ = basis_cache_file(cache_dir, key);
    CachedBasis cached = read_basis_cache(cache_file_, key, model.n_points, settings.size);
    if (cached.basis) {
      basis_ = std::move(*cached.basis);
      from_cache_ = true;
    } else if (!cached.missing) {
      cache_note_ = fmt::format("the kept basis {} was not used ({}): made again", cache_file_, cached.why);
    }
  }
  if (!from_cache_) {
    if (spec_.reduction.basis_spacing > 0) {
      // the basis of a coarser sampling, carried to the points: the set-up's factor tens of times smaller
      const Model coarse = coarse_model(model, spec_.reduction.basis_spacing);
      Workspace coarse_ws(coarse, ws.n_threads());
      if (coarse.f_ext.squaredNorm() > 0) settings.loads = {coarse.f_ext};
      basis_ = carry_basis(build_modal_basis(coarse, settings, coarse_ws), coarse, model);
    } else {
      if (model.f_ext.size() == 3 * model.n_points && model.f_ext.squaredNorm() > 0) settings.loads = {model.f_ext};
      basis_ = build_modal_basis(model, settings, ws);
    }
    if (!cache_file_.empty()) {
      // a basis that cannot be kept (a full disk, a folder without rights) costs the next run its set-up, not
      // this run its result
      try {
        write_basis_cache(cache_file_, key, basis_);
      } catch (const Error& e) {
        cache_note_ = fmt::format("the basis was not kept: {}", e.what());
        cache_file_.clear();
      }
    }
  }
}

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
  make_or_read_basis(model, ws);
  polynomial_ = std::make_unique<SvkPolynomial>(model, basis_.U, ws);
  Eigen::VectorXd external = Eigen::VectorXd::Zero(spec.reduction.modes);
  if (model.f_ext.size() == 3 * model.n_points)
    external = basis_.U.transpose() * Eigen::Map<const Eigen::VectorXd>(model.f_ext.data(), model.f_ext.size());
  integrator_ = std::make_unique<ReducedIntegrator>(*polynomial_, std::move(external), model.material.damping);
  // the reduced model's lowest natural frequency: its mass is the identity (U is mass-orthonormal), so omega^2 are
  // the eigenvalues of its rest stiffness
  const Eigen::VectorXd omega2 =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(polynomial_->rest_stiffness(), Eigen::EigenvaluesOnly)
          .eigenvalues();
  first_frequency_hz_ = std::sqrt(std::max(omega2.minCoeff(), 0.0)) / (2 * std::numbers::pi);
  reduced_.q = Eigen::VectorXd::Zero(spec.reduction.modes);
  reduced_.v = Eigen::VectorXd::Zero(spec.reduction.modes);
  setup_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

index_t ReducedSolver::count_inverted(const Model& model, const State& state, Workspace& ws) {
  if (reduced_.q.norm() * polynomial_->gradient_bound() < 1) {  // |G_p| < 1 at every point: det(I + G_p) > 0
    steps_since_count_ = exact_count_every;
    return last_count_ = 0;
  }
  if (++steps_since_count_ < exact_count_every) return last_count_;
  steps_since_count_ = 0;
  if (!positions_unpublished_) return last_count_ = pointhaptics::count_inverted(model, state.u, ws);
  inversion_u_.resize(3, model.n_points);
  Eigen::Map<Eigen::VectorXd>(inversion_u_.data(), inversion_u_.size()).noalias() = basis_.U * reduced_.q;
  return last_count_ = pointhaptics::count_inverted(model, inversion_u_, ws);
}

void ReducedSolver::take_state(const Model& model, const State& state) {
  Points weighted = state.u * model.mass.asDiagonal();
  reduced_.q = basis_.U.transpose() * Eigen::Map<const Eigen::VectorXd>(weighted.data(), weighted.size());
  weighted = state.velocity * model.mass.asDiagonal();
  reduced_.v = basis_.U.transpose() * Eigen::Map<const Eigen::VectorXd>(weighted.data(), weighted.size());
  positions_unpublished_ = velocities_unpublished_ = false;  // the state holds what was given
  patch_in_state_ = false;
  if (patch_) patch_->forget_velocities();
}

void ReducedSolver::publish(State& state, Workspace& ws) {
  write(state, ws, positions_unpublished_, velocities_unpublished_);
  positions_unpublished_ = velocities_unpublished_ = false;
}

void ReducedSolver::write(State& state, Workspace& ws, bool positions, bool velocities) {
  if (!positions && !velocities) return;
  // on the step's threads, each its rows of U (each product costs several reduced steps)
  Eigen::Map<Eigen::VectorXd> u(state.u.data(), state.u.size()), v(state.velocity.data(), state.velocity.size());
  ws.for_each_chunk([&](int chunk) {
    const Eigen::Index begin = 3 * static_cast<Eigen::Index>(ws.chunk_begin(chunk));
    const Eigen::Index rows = 3 * static_cast<Eigen::Index>(ws.chunk_end(chunk)) - begin;
    if (positions) u.segment(begin, rows).noalias() = basis_.U.middleRows(begin, rows) * reduced_.q;
    if (velocities) v.segment(begin, rows).noalias() = basis_.U.middleRows(begin, rows) * reduced_.v;
  });
  // the contact patch's points move as it solved them
  if (velocities && patch_in_state_) patch_->write_velocities(state.velocity);
}

ContactPatch* ReducedSolver::begin_contact(const Model& model, const State& state, DynamicForces& forces, int threads) {
  // the tools' forces at the step's start and their springs (a probe's, linearly implicit as in the full implicit
  // solver), on a patch of points in full resolution around where they act
  if (tool_forces_.cols() != model.n_points) {
    tool_forces_ = Points::Zero(3, model.n_points);
    springs_ = ContactPatch::Blocks::Zero(9, model.n_points);
  }
  // (nonzero only where the last step's tools acted, which the patch found: a pass over every point less)
  if (patch_)
    for (const index_t i : patch_->touched()) {
      tool_forces_.col(i).setZero();
      springs_.col(i).setZero();
    }
  if (forces.add_beyond_energy(model, state, tool_forces_)) forces.add_stiffness(model, state, springs_);
  if (!patch_) patch_ = std::make_unique<ContactPatch>(model, basis_.U, spec_.reduction.contact_rings, threads);
  ContactPatch::Step step;
  step.tool_forces = &tool_forces_;
  step.springs = &springs_;
  step.start = &state;
  if (spec_.kind != SolverKind::STATIC) {
    step.inertia = integrator_->inertia(spec_.dt);
    step.carry = integrator_->carry(spec_.dt);
  }
  reduced_anchor_ = reduced_.q + step.carry * reduced_.v;
  step.reduced_anchor = &reduced_anchor_;
  step.reduced_velocity = &reduced_.v;
  return patch_->begin_step(model, step) ? patch_.get() : nullptr;
}

StepReport ReducedSolver::step(const Model& model, State& state, Workspace& ws, DynamicForces* forces) {
  StepReport report;
  ContactPatch* coupling = nullptr;
  if (forces) {
    if (forces->energy_term()) {
      report.status = StepStatus::FAILED;
      report.failure =
          "reduction: held tools, obstacles and contact between bodies are not coupled to a reduced model yet (a "
          "probe is)";
      return report;
    }
    coupling = begin_contact(model, state, *forces, ws.n_threads());
  }
  const double tolerance = spec_.tolerance > 0 ? spec_.tolerance : spec_.kind == SolverKind::STATIC ? 1e-8 : 1e-6;
  ReducedSolveReport solved;
  if (spec_.kind == SolverKind::STATIC) {
    if (coupling) {
      report.status = StepStatus::FAILED;
      report.failure = "reduction: a tool on a reduced model needs solver.kind = \"implicit\" (not yet static)";
      return report;
    }
    solved = integrator_->solve_static(reduced_.q, tolerance, spec_.max_iterations);
    reduced_.v.setZero();
  } else {
    const bool budget = spec_.iteration_budget > 0;
    solved = integrator_->step(reduced_, spec_.dt, tolerance, budget ? spec_.iteration_budget : spec_.max_iterations,
                               budget, coupling);
  }
  // the contact patch's Hessian lags from step to step while Newton converges in a few iterations with it
  if (coupling && solved.iterations > refresh_after_iterations) coupling->refresh_hessian();
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
            : fmt::format("reduced step: Newton did not converge in {} iterations (residual {:.3g}{}{})",
                          solved.iterations, solved.residual,
                          coupling && *coupling->failure() ? "; contact patch: " : "",
                          coupling ? coupling->failure() : "");
    return report;
  }
  // the state's finite check, on the coordinates (the state may not be written yet)
  if (!reduced_.q.allFinite() || !reduced_.v.allFinite()) {
    report.status = StepStatus::FAILED;
    report.failure = "reduced step: the coordinates are not finite";
    return report;
  }
  if (spec_.kind != SolverKind::STATIC) state.time += spec_.dt;
  positions_unpublished_ = velocities_unpublished_ = true;
  patch_in_state_ = coupling != nullptr;
  if (forces) {
    // tools read the displacement at every step (not the velocity): written now, with the contact patch's points
    // in full (their velocities too, which the next step reads; the rest of v when something reads it)
    write(state, ws, true, false);
    positions_unpublished_ = false;
    if (coupling) coupling->finish_step(state.u, state.velocity, spec_.kind == SolverKind::STATIC ? 0.0 : spec_.dt);
  }
  return report;
}

}  // namespace pointhaptics
