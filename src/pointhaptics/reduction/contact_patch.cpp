#include <pointhaptics/reduction/contact_patch.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/mechanics/forces.hpp>

#include <algorithm>

namespace pointhaptics {

namespace {

Eigen::Map<Eigen::VectorXd> flat(Points& p) { return {p.data(), p.size()}; }

}  // namespace

ContactPatch::ContactPatch(const Model& model, const Eigen::MatrixXd& U, int rings, int threads)
    : U_(U), rings_(rings), threads_(threads), newton_(model) {
  if (rings < 1) throw Error("reduction.contact_rings: at least 1 (the points a tool acts on and a ring around them)");
  if (U.rows() != 3 * model.n_points) throw Error("contact patch: the basis is not the model's");
  // the patch's own solves: tight enough that the reduced Newton's line search sees its energy without noise (1e-9
  // gave the same forces to four digits at 1.2 times the cost); its
  // tangent factorised (a few hundred points: a small factor, and the condensation's r solves then take a few
  // CG iterations each)
  settings_.tolerance = 1e-7;
  settings_.max_iterations = 50;
  settings_.preconditioner = Preconditioner::CHOLESKY;
  settings_.refactorisation = Refactorisation::IN_PLACE;
  inside_.assign(static_cast<std::size_t>(model.n_points), 0);
}

void ContactPatch::build(const Model& model, const std::vector<index_t>& touched) {
  std::fill(inside_.begin(), inside_.end(), 0);
  patch_ = model_patch(model, neighbourhood(model, touched, rings_), 3);  // three: its energy exact (model_patch.hpp)
  for (const index_t i : neighbourhood(model, touched, rings_ - 1)) inside_[static_cast<std::size_t>(i)] = 1;
  const index_t n = patch_.model.n_points;
  const Eigen::Index r = U_.cols();
  U_patch_.resize(3 * n, r);
  for (index_t k = 0; k < n; ++k)
    U_patch_.middleRows(3 * k, 3) = U_.middleRows(3 * patch_.full_of[static_cast<std::size_t>(k)], 3);
  // a patch of a few thousand points is faster on one thread than shared (measured: a third of a 225-point
  // patch's step went to handing chunks between two)
  ws_ = std::make_unique<Workspace>(patch_.model, n < 4096 ? 1 : threads_);
  // the free points' own solves need only the stencils that reach them: the same patch with every ring beyond the
  // first passive (their gradients, which the first ring's hourglass pairs read, are still made whole), a third of
  // the stencils here
  inner_ = patch_.model;
  inner_.n_passive = n - patch_.ring_end.front();
  inner_ws_ = std::make_unique<Workspace>(inner_, n < 4096 ? 1 : threads_);
  newton_ = NewtonSolver(inner_);
  for (Points* p : {&tool_, &load_, &start_, &rest_, &star_, &w_, &anchor_, &reduced_anchor_, &forces_at_rest_,
                    &scratch_, &product_})
    *p = Points::Zero(3, n);
  springs_ = Blocks::Zero(9, n);
  condensed_start_.assign(static_cast<std::size_t>(r), Points::Zero(3, n));
  largest_free_points_ = std::max(largest_free_points_, patch_.n_free);
  ++rebuilds_;
}

bool ContactPatch::begin_step(const Model& model, const Step& step) {
  const Points& tool_forces = *step.tool_forces;
  const Blocks& springs = *step.springs;
  std::vector<index_t>& touched = touched_;  // (kept: a step allocates only to grow it)
  touched.clear();
  for (index_t i = 0; i < model.n_points; ++i)
    if (tool_forces.col(i).squaredNorm() > 0 || springs.col(i).squaredNorm() > 0) touched.push_back(i);
  // a patch the tools have left stays for release_steps: its correction, which has mass, moves on as the full
  // model's points would (dropped at once, the indentation sprang back into a probe that came back to it, and a
  // stiff cantilever under a sliding probe diverged)
  steps_untouched_ = touched.empty() ? steps_untouched_ + 1 : 0;
  active_ = !touched.empty() || (!patch_.full_of.empty() && steps_untouched_ <= release_steps);
  if (!active_) {
    patch_ = ModelPatch{};
    std::fill(inside_.begin(), inside_.end(), 0);
    return false;
  }
  const bool rebuilt = patch_.full_of.empty() || std::any_of(touched.begin(), touched.end(), [&](index_t i) {
                         return !inside_[static_cast<std::size_t>(i)];
                       });
  if (rebuilt) build(model, touched);
  const index_t n = patch_.model.n_points;
  for (index_t k = 0; k < n; ++k) {
    const index_t i = patch_.full_of[static_cast<std::size_t>(k)];
    tool_.col(k) = tool_forces.col(i);
    start_.col(k) = step.start->u.col(i);
    anchor_.col(k) = step.start->u.col(i) + step.carry * step.start->velocity.col(i);
    springs_.col(k) = springs.col(i);
  }
  inertia_ = step.inertia;
  basis_product(*step.reduced_anchor, reduced_anchor_);
  // the correction the step starts from: what the state carries beyond U q (zero where A is new)
  basis_product(*step.q, rest_);
  w_ = start_ - rest_;
  for (index_t k = patch_.n_free; k < n; ++k) w_.col(k).setZero();
  load_ = patch_.model.f_ext + tool_;
  if (rebuilt) hessian_valid_ = false;
  uses_this_step_ = 0;
  return true;
}

void ContactPatch::basis_product(const Eigen::VectorXd& x, Points& out) const { flat(out).noalias() = U_patch_ * x; }

NewtonProblem ContactPatch::problem() {
  NewtonProblem problem;
  problem.load = &load_;
  problem.springs = &springs_;
  problem.spring_anchor = &start_;
  problem.inertia = inertia_;
  problem.anchor = &anchor_;
  return problem;
}

bool ContactPatch::evaluate(const Eigen::VectorXd& q, double& energy, Eigen::VectorXd& gradient) {
  const Model& patch = patch_.model;
  failure_ = "";
  // the patch's stencils as the reduced model has them (U_P q): their energy and forces, taken out again
  basis_product(q, rest_);
  const double rest_energy = strain_energy(patch, rest_, &gradients_).total();
  compute_internal_forces(patch, rest_, *ws_);
  forces_at_rest_ = ws_->f_int;
  // the correction minimised out at this q, the rings held at U_R q (w is zero there), from the last one
  star_ = rest_ + w_;
  const NewtonStats stats = newton_.solve(inner_, problem(), star_, *inner_ws_, settings_);
  inner_iterations_ += stats.iterations;
  if (!stats.converged) {
    failure_ = stats.failure;
    return false;
  }
  w_ = star_ - rest_;
  const double star_energy = strain_energy(patch, star_, &gradients_).total();
  compute_internal_forces(patch, star_, *ws_);
  // Pi's part (contact_patch.hpp): E_P(u*) - E_P(U_P q) - (f + t)_A . w - t_A . U_A q + springs(u*), and its
  // gradient in q at this w: U_P^T (f_P(U_P q) - f_P(u*)) + U_A^T (S (u* - c) - t)
  double e = star_energy - rest_energy;
  scratch_ = forces_at_rest_ - ws_->f_int;
  for (index_t k = 0; k < patch_.n_free; ++k) {
    if (patch.fixed[static_cast<std::size_t>(k)]) continue;
    const Vec3 stretch = star_.col(k) - start_.col(k);
    const Mat3 S = Eigen::Map<const Mat3>(springs_.col(k).data());
    e += 0.5 * stretch.dot(S * stretch) - load_.col(k).dot(w_.col(k)) - tool_.col(k).dot(rest_.col(k));
    scratch_.col(k) += S * stretch - tool_.col(k);
    // the inertia of u_A in full, less the reduced model's of U_A q
    const double km = inertia_ * patch.mass[k];
    const Vec3 behind = star_.col(k) - anchor_.col(k), reduced_behind = rest_.col(k) - reduced_anchor_.col(k);
    e += 0.5 * km * (behind.squaredNorm() - reduced_behind.squaredNorm());
    scratch_.col(k) += km * (behind - reduced_behind);
  }
  gradient.noalias() += U_patch_.transpose() * flat(scratch_);
  energy = e;
  return true;
}

void ContactPatch::add_hessian(Eigen::MatrixXd& hessian) {
  // a step that needs many iterations with the lagged Hessian (a contact that comes and goes) gets a new one
  if (++uses_this_step_ > lagged_iterations) hessian_valid_ = false;
  if (!hessian_valid_) {
    uses_this_step_ = 0;
    const Model& patch = patch_.model;
    const Eigen::Index r = U_patch_.cols();
    const Eigen::Index free_rows = 3 * patch_.n_free;
    hessian_.setZero(r, r);
    // less the patch's stencils as the polynomial has them: their exact tangent at U_P q in the basis
    rest_tangent_.linearise(patch, rest_, TangentMode::EXACT, ws_.get());
    for (Eigen::Index k = 0; k < r; ++k) {
      flat(product_) = U_patch_.col(k);
      rest_tangent_.apply(patch, product_, *ws_, scratch_);
      hessian_.col(k).noalias() -= U_patch_.transpose() * flat(scratch_);
    }
    // less the reduced model's inertia on A, k U_A^T M_A U_A
    for (index_t i = 0; i < patch_.n_free; ++i)
      if (!patch.fixed[static_cast<std::size_t>(i)])
        hessian_.noalias() -=
            (inertia_ * patch.mass[i]) * U_patch_.middleRows(3 * i, 3).transpose() * U_patch_.middleRows(3 * i, 3);
    // plus the full model's there, condensed onto the held rings: z_k = H d_k with d_k = U_R e_k (zero on A),
    // y_k = H_AA^-1 z_k on A, and d_l . z_k - z_l . y_k
    const NewtonProblem problem = this->problem();
    newton_.linearise(inner_, problem, star_, *inner_ws_);
    star_tangent_.linearise(patch, star_, TangentMode::PROJECTED, ws_.get());
    z_free_.resize(free_rows, r);  // (allocates only when the patch changes)
    y_free_.resize(free_rows, r);
    for (Eigen::Index k = 0; k < r; ++k) {
      flat(product_) = U_patch_.col(k);
      product_.leftCols(patch_.n_free).setZero();
      star_tangent_.apply(patch, product_, *ws_, scratch_);
      hessian_.col(k).noalias() += U_patch_.bottomRows(U_patch_.rows() - free_rows).transpose() *
                                   flat(scratch_).tail(U_patch_.rows() - free_rows);
      Points& y = condensed_start_[static_cast<std::size_t>(k)];
      newton_.solve_linearised(inner_, problem, scratch_, y, condensation_tolerance, condensation_iterations,
                               *inner_ws_);
      // held points of the model within A carry no correction: zero rows of z and y
      for (index_t i = 0; i < patch_.n_free; ++i)
        if (patch.fixed[static_cast<std::size_t>(i)]) scratch_.col(i).setZero(), y.col(i).setZero();
      z_free_.col(k) = flat(scratch_).head(free_rows);
      y_free_.col(k) = flat(y).head(free_rows);
    }
    hessian_.noalias() -= z_free_.transpose() * y_free_;
    hessian_ = 0.5 * (hessian_ + hessian_.transpose()).eval();
    hessian_valid_ = true;
  }
  hessian += hessian_;
}

void ContactPatch::write_state(Points& u, Points& velocity, double dt) const {
  if (!active_) return;
  for (index_t k = 0; k < patch_.n_free; ++k) {
    const index_t i = patch_.full_of[static_cast<std::size_t>(k)];
    u.col(i) = star_.col(k);
    if (dt > 0) velocity.col(i) = (star_.col(k) - start_.col(k)) / dt;
  }
}

}  // namespace pointhaptics
