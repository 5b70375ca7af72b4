#include <pointhaptics/solvers/explicit_solver.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/core/run_control.hpp>
#include <pointhaptics/geometry/neighbour_search.hpp>
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/mechanics/model_patch.hpp>
#include <pointhaptics/mechanics/tangent.hpp>
#include <pointhaptics/mechanics/viscoelasticity.hpp>

#include <Eigen/Eigenvalues>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>

namespace pointhaptics {

double estimated_stable_time_step(const Model& model, double safety) {
  const std::vector<index_t> nearest = nearest_neighbour(model.X);
  double a = std::numeric_limits<double>::infinity();
  for (index_t i = 0; i < model.n_points; ++i)
    if (nearest[i] >= 0) a = std::min(a, (model.X.col(nearest[i]) - model.X.col(i)).norm());
  if (!std::isfinite(a)) a = model.spacing > 0 ? model.spacing : model.h;
  // the lightest point per unit volume vibrates fastest; in kernel-volume mode m_i / v_i is not the density
  double rho = std::numeric_limits<double>::infinity();
  for (index_t i = 0; i < model.n_points; ++i) rho = std::min(rho, model.mass[i] / model.volume[i]);
  const MaterialParams& m = model.material;
  const double modulus = model.max_p_wave_modulus() + m.volume_stiffness + m.hourglass * model.max_young();
  return safety * a / std::sqrt(modulus / rho);
}

double stable_time_step(const Model& model, double safety, int lanczos_steps, int n_threads,
                        const std::vector<index_t>& focus) {
  // Lanczos on M^-1/2 K M^-1/2 over the free points at rest: its largest Ritz value approaches the
  // largest omega^2 from below, and symplectic Euler is stable for h < 2 / omega_max
  const Eigen::Index n = 3 * static_cast<Eigen::Index>(model.n_points);
  Eigen::VectorXd scale(n);
  for (index_t i = 0; i < model.n_points; ++i)
    for (int a = 0; a < 3; ++a)
      scale[3 * i + a] = model.fixed[i] || !(model.mass[i] > 0) ? 0.0 : 1.0 / std::sqrt(model.mass[i]);
  // (a neighbour search: made only when Lanczos cannot answer)
  auto fallback = [&] { return estimated_stable_time_step(model, 0.7); };
  if (scale.squaredNorm() == 0) return fallback();
  Workspace ws(model, n_threads);
  Tangent K;
  K.linearise(model, Points::Zero(3, model.n_points), TangentMode::EXACT, &ws);
  std::mt19937 rng(12345);
  std::normal_distribution<double> noise;
  Eigen::VectorXd q(n), q_prev = Eigen::VectorXd::Zero(n);
  q.setZero();
  for (const index_t i : focus)
    for (int a = 0; a < 3; ++a) q[3 * i + a] = scale[3 * i + a] > 0 ? noise(rng) : 0.0;
  if (q.squaredNorm() == 0)
    for (Eigen::Index k = 0; k < n; ++k) q[k] = scale[k] > 0 ? noise(rng) : 0.0;
  q.normalize();
  Points in(3, model.n_points), out(3, model.n_points);
  const int steps = static_cast<int>(std::min<Eigen::Index>(std::max(2, lanczos_steps), n));
  Eigen::VectorXd alpha = Eigen::VectorXd::Zero(steps), beta = Eigen::VectorXd::Zero(steps);
  int done = 0;
  double b = 0;
  for (; done < steps; ++done) {
    Eigen::Map<Eigen::VectorXd>(in.data(), n) = q.cwiseProduct(scale);
    K.apply(model, in, ws, out);
    Eigen::VectorXd w = Eigen::Map<const Eigen::VectorXd>(out.data(), n).cwiseProduct(scale);
    alpha[done] = w.dot(q);
    w -= alpha[done] * q + b * q_prev;
    b = w.norm();
    beta[done] = b;
    if (!(b > 1e-12 * std::abs(alpha[done]))) {
      ++done;
      break;  // an invariant subspace: the Ritz values are exact
    }
    q_prev = q;
    q = w / b;
  }
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(done, done);
  for (int k = 0; k < done; ++k) {
    T(k, k) = alpha[k];
    if (k + 1 < done) T(k, k + 1) = T(k + 1, k) = beta[k];
  }
  const double omega2 =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(T, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
  if (!(omega2 > 0) || !std::isfinite(omega2)) return fallback();
  return safety * 2.0 / std::sqrt(omega2);
}

double local_stable_time_step(const Model& model, const std::vector<index_t>& around, int rings, double safety,
                              int lanczos_steps) {
  const ModelPatch patch = model_patch(model, neighbourhood(model, around, rings));
  // the free points come first in the patch, in increasing order, and `around` is among them
  const auto free_end = patch.full_of.begin() + patch.n_free;
  std::vector<index_t> focus;
  for (const index_t i : around)
    focus.push_back(static_cast<index_t>(std::lower_bound(patch.full_of.begin(), free_end, i) - patch.full_of.begin()));
  return stable_time_step(patch.model, safety, lanczos_steps, 1, focus);
}

double stable_time_step_with_springs(double stable_dt, double spring_stiffness, double min_mass, double safety) {
  if (!(spring_stiffness > 0) || !(min_mass > 0) || !std::isfinite(min_mass)) return stable_dt;
  const double omega = 2 * safety / stable_dt;
  return 2 * safety / std::sqrt(omega * omega + spring_stiffness / min_mass);
}

double min_free_mass(const Model& model) {
  double m = std::numeric_limits<double>::infinity();
  for (index_t i = 0; i < model.n_points; ++i)
    if (!model.fixed[i]) m = std::min(m, model.mass[i]);
  return m;
}

namespace {
const double covered_stiffening = 1.25;    // stiffening the safety factor of stable_time_step() absorbs
const double stiffening_relax_time = 0.5;  // s: how slowly the planned stiffening falls back (explicit_step)
const int many_substeps = 1000;            // sub-steps in one step worth a progress report
}  // namespace

StepReport explicit_step(const Model& model, State& state, Workspace& ws, double dt, double stable_dt,
                         DynamicForces* forces, double* planned_stiffening) {
  // a viscoelastic material: one viscous step over dt, as an implicit step takes it. Its sub-steps see the
  // stress the step would end with at their u (the relaxed shear modulus and the history's overstress), and
  // the history joins the state at the step's end: once per step, not per sub-step (it cost 1.4 force loops)
  const bool viscous = !model.material.prony.empty();
  if (viscous) begin_viscous_step(model, state, dt, ws);
  // the first sub-step's forces, at the state the step starts from: its stiffening plans the sub-steps (a
  // state set from outside, a new active set's, is planned for as it is, not for what the workspace saw last)
  compute_internal_forces(model, state.u, ws);
  // the rest-state step, shortened by the springs of the state-dependent forces (a probe's contact: issue
  // 21, 1e4 N/m diverged), then where the material is stretched beyond what its safety factor covers (0.8
  // leaves omega^2 a margin of 1.56; a quarter is kept for stiffening)
  if (forces) stable_dt = stable_time_step_with_springs(stable_dt, forces->max_point_stiffness(), min_free_mass(model));
  double stiffening = strain_stiffening(model, ws);
  if (planned_stiffening) {
    // the plan follows a rise at once and a fall only slowly: a sub-step that followed the stiffening's every
    // swing changed with the phase of an oscillation and pumped energy into it (parametric resonance: a beam
    // pressed deep by a probe rang at 2 m/s for good after the hand let go; steady sub-steps let it settle)
    stiffening = std::max(stiffening, 1 + (*planned_stiffening - 1) * std::exp(-dt / stiffening_relax_time));
    *planned_stiffening = stiffening;
  }
  stable_dt *= std::min(1.0, std::sqrt(covered_stiffening / stiffening));
  const int n_sub = std::max(1, static_cast<int>(std::ceil(dt / stable_dt * (1 - 1e-12))));
  const double h = dt / n_sub;
  const double c = model.material.damping;
  const double limit2 = (100 * model.extent) * (100 * model.extent);
  StepReport report;
  double* first_bad = ws.chunk_scalars.data();  // per chunk: the first diverged point, or -1 (no atomics)
  // a stiff object can need millions of sub-steps in one step: they are polled (a stop leaves the state at the
  // last sub-step, a consistent state at its time) and, when many, shown as progress
  std::optional<Progress> progress;
  if (n_sub >= many_substeps) progress.emplace(substep_phase, n_sub);
  for (int sub = 0; sub < n_sub; ++sub) {
    if (progress) progress->reach(sub);
    else throw_if_stop_requested(substep_phase);
    if (sub > 0) compute_internal_forces(model, state.u, ws);
    if (forces) {
      ws.acceleration.setZero();  // scratch for the dynamic forces
      forces->add(model, state, ws.acceleration);
    }
    ws.for_each_chunk([&](int chunk) {
      first_bad[chunk] = -1;
      for (index_t i = ws.chunk_begin(chunk); i < ws.chunk_end(chunk); ++i) {
        if (model.fixed[i] || (!ws.asleep.empty() && ws.asleep[static_cast<std::size_t>(i)])) continue;
        auto v = state.velocity.col(i);
        auto u = state.u.col(i);
        Vec3 f = ws.f_int.col(i) + model.f_ext.col(i);
        if (forces) f += ws.acceleration.col(i);
        v = (v + h / model.mass[i] * f) / (1 + h * c);
        u += h * v;
        if (!(u.squaredNorm() < limit2) && first_bad[chunk] < 0) first_bad[chunk] = i;  // also catches NaN
      }
    });
    state.time += h;
    hold_points(model, state.time, state.u, &state.velocity, h);
    report.substeps = report.iterations = sub + 1;
    for (int chunk = 0; chunk < ws.n_threads(); ++chunk) {
      if (first_bad[chunk] < 0) continue;
      const auto i = static_cast<index_t>(first_bad[chunk]);
      report.status = StepStatus::FAILED;
      report.failure = fmt::format(
          "explicit solver diverged at t = {:.6g} s (sub-step {} of {}, h = {:.3g} s): point {} has displacement "
          "({:.3g}, {:.3g}, {:.3g}) m; lower dt, add damping or check the material",
          state.time, sub + 1, n_sub, h, i, state.u(0, i), state.u(1, i), state.u(2, i));
      return report;
    }
  }
  if (viscous) end_viscous_step(model, dt, state, ws);
  return report;
}

ExplicitSolver::ExplicitSolver(const Model& model, double dt, double stable_dt)
    : dt_(dt), stable_dt_(stable_dt > 0 ? stable_dt : stable_time_step(model)) {}

void ExplicitSolver::continue_from(const Solver& previous) {
  if (const auto* explicit_previous = dynamic_cast<const ExplicitSolver*>(&previous))
    planned_stiffening_ = explicit_previous->planned_stiffening_;
}

StepReport ExplicitSolver::step(const Model& model, State& state, Workspace& ws, DynamicForces* forces) {
  return explicit_step(model, state, ws, dt_, stable_dt_, forces, &planned_stiffening_);
}

}  // namespace pointhaptics
