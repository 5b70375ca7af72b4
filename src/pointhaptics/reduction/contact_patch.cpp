#include <pointhaptics/reduction/contact_patch.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/mechanics/forces.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>

namespace pointhaptics {

namespace {

Eigen::Map<Eigen::VectorXd> flat(Points& p) { return {p.data(), p.size()}; }

}  // namespace

ContactPatch::ContactPatch(const Model& model, const Eigen::MatrixXd& U, int rings, int threads)
    : U_(U), rings_(rings), threads_(threads), newton_(model) {
  if (rings < 1) throw Error("reduction.contact_rings: at least 1 (the points a tool acts on and a ring around them)");
  if (U.rows() != 3 * model.n_points) throw Error("contact patch: the basis is not the model's");
  inside_.assign(static_cast<std::size_t>(model.n_points), 0);
  velocity_slot_.assign(static_cast<std::size_t>(model.n_points), -1);
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
  // the tangent on A needs only the stencils that reach it: the same patch with every ring beyond the first passive
  // (their gradients, which the first ring's hourglass pairs read, are still made whole), a third of the stencils
  // here
  inner_ = patch_.model;
  inner_.n_passive = n - patch_.ring_end.front();
  inner_ws_ = std::make_unique<Workspace>(inner_, n < 4096 ? 1 : threads_);
  newton_ = NewtonSolver(inner_);
  for (Points* p : {&tool_, &load_, &start_, &rest_, &star_, &anchor_, &reduced_anchor_, &residual_, &solved_,
                    &move_start_, &move_, &forces_at_rest_, &scratch_, &product_})
    *p = Points::Zero(3, n);
  springs_ = Blocks::Zero(9, n);
  condensed_start_.assign(static_cast<std::size_t>(r), Points::Zero(3, n));
  // |U_A^T g| <= |U_A|_2 |g|: the most a force on A's points moves the reduced gradient (its residual is measured
  // so: weighted by each point's mass instead, a stiff patch's forces on points of a few grams were held to a
  // hundred times the reduced model's tolerance)
  const Eigen::MatrixXd gram = U_patch_.topRows(3 * patch_.n_free).transpose() * U_patch_.topRows(3 * patch_.n_free);
  reach_ =
      std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(gram, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff());
  largest_free_points_ = std::max(largest_free_points_, patch_.n_free);
  ++rebuilds_;
}

bool ContactPatch::begin_step(const Model& model, const Step& step) {
  const Points& tool_forces = *step.tool_forces;
  const Blocks& springs = *step.springs;
  std::vector<index_t>& touched = touched_;  // (kept: a step allocates only to grow it)
  touched.clear();
  for (index_t i = 0; i < model.n_points; ++i)
    if (tool_forces.col(i).squaredNorm() != 0 || springs.col(i).squaredNorm() != 0) touched.push_back(i);  // NaN too
  // a patch the tools have left stays for release_steps: its correction, which has mass, moves on as the full
  // model's points would (dropped at once, the indentation sprang back into a probe that came back to it, and a
  // stiff cantilever under a sliding probe diverged)
  steps_untouched_ = touched.empty() ? steps_untouched_ + 1 : 0;
  active_ = !touched.empty() || (!patch_.full_of.empty() && steps_untouched_ <= release_steps);
  if (!active_) {
    patch_ = ModelPatch{};
    std::fill(inside_.begin(), inside_.end(), 0);
    forget_velocities();
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
    springs_.col(k) = springs.col(i);
  }
  // A's anchors: a = u + carry v, v as the last step left it where it solved the point in full, else the reduced
  // model's (the state's v is written only when read)
  for (index_t k = 0; k < patch_.n_free; ++k) {
    const index_t slot = velocity_slot_[static_cast<std::size_t>(patch_.full_of[static_cast<std::size_t>(k)])];
    const Vec3 velocity = slot >= 0               ? Vec3(velocity_.col(slot))
                          : step.reduced_velocity ? Vec3(U_patch_.middleRows(3 * k, 3) * *step.reduced_velocity)
                                                  : Vec3::Zero();
    anchor_.col(k) = start_.col(k) + step.carry * velocity;
  }
  inertia_ = step.inertia;
  basis_product(*step.reduced_anchor, reduced_anchor_);
  // A's points start where their momentum carries them (as q does: reduced_integrator.cpp), the model's held
  // points among them where they are
  for (index_t k = 0; k < patch_.n_free; ++k)
    star_.col(k) = patch_.model.fixed[static_cast<std::size_t>(k)] ? start_.col(k) : anchor_.col(k);
  move_.setZero();
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

double ContactPatch::energy_near(const Points& u) {
  return strain_energy_near(inner_, u, patch_.ring_end[0], patch_.ring_end[1], gradients_).total();
}

bool ContactPatch::evaluate(const Eigen::VectorXd& q, double& energy, Eigen::VectorXd& gradient) {
  const Model& patch = patch_.model;
  const index_t n = patch.n_points, n_free = patch_.n_free;
  failure_ = "";
  // the patch's stencils as the reduced model has them (U_P q): their energy and forces, taken out again. The
  // energy of what moves with A alone (the rest cancels); the forces of the whole patch (with its outer rings
  // passive, a passive point's pairs are charged through the neighbour's gradient only: the rings' forces would
  // not be the energy's gradient)
  basis_product(q, rest_);
  const double rest_energy = energy_near(rest_);
  compute_internal_forces(patch, rest_, *ws_);
  forces_at_rest_ = ws_->f_int;
  // the patch in full: v on A, the rings held at U_R q
  star_.rightCols(n - n_free) = rest_.rightCols(n - n_free);
  const double star_energy = energy_near(star_);
  compute_internal_forces(patch, star_, *ws_);
  // Pi's part (contact_patch.hpp): E_P(u) - E_P(U_P q) - (f + t)_A . w - t_A . U_A q + springs(u) + the inertia of
  // u_A in full less the reduced model's of U_A q. Its gradient in q at fixed v:
  //   U_P^T f_P(U_P q) - U_R^T f_R(u) + U_A^T (f_A - k M_A (U_A q - U_A a_q)),
  // and in v: -f_A(u) + S (v - c) - (f + t)_A + k M_A (v - a_A)
  double e = star_energy - rest_energy;
  scratch_ = forces_at_rest_;
  scratch_.rightCols(n - n_free) -= ws_->f_int.rightCols(n - n_free);
  for (index_t k = 0; k < n_free; ++k) {
    if (patch.fixed[static_cast<std::size_t>(k)]) {
      residual_.col(k).setZero();
      continue;
    }
    const Vec3 stretch = star_.col(k) - start_.col(k);
    const Mat3 S = Eigen::Map<const Mat3>(springs_.col(k).data());
    const double km = inertia_ * patch.mass[k];
    const Vec3 behind = star_.col(k) - anchor_.col(k), reduced_behind = rest_.col(k) - reduced_anchor_.col(k);
    e += 0.5 * stretch.dot(S * stretch) - load_.col(k).dot(star_.col(k) - rest_.col(k)) -
         tool_.col(k).dot(rest_.col(k)) + 0.5 * km * (behind.squaredNorm() - reduced_behind.squaredNorm());
    scratch_.col(k) += load_.col(k) - tool_.col(k) - km * reduced_behind;
    residual_.col(k) = S * stretch - ws_->f_int.col(k) - load_.col(k) + km * behind;
  }
  if (!std::isfinite(e) || !residual_.leftCols(n_free).allFinite()) {
    failure_ = "its energy is not finite";
    return false;
  }
  gradient.noalias() += U_patch_.transpose() * flat(scratch_);
  energy = e;
  return true;
}

double ContactPatch::residual() const { return reach_ * residual_.leftCols(patch_.n_free).norm(); }

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
    if (!newton_.linearise_factorised(inner_, problem(), star_, *inner_ws_))
      throw Error("contact patch: the tangent on the points in full cannot be factorised (it is not finite)");
    ++hessians_;
    star_tangent_.linearise(patch, star_, TangentMode::PROJECTED, ws_.get());
    z_free_.resize(free_rows, r);  // (allocates only when the patch changes)
    y_free_.resize(free_rows, r);
    for (Eigen::Index k = 0; k < r; ++k) {
      flat(product_) = U_patch_.col(k);
      product_.leftCols(patch_.n_free).setZero();
      star_tangent_.apply(patch, product_, *ws_, scratch_);
      hessian_.col(k).noalias() += U_patch_.bottomRows(U_patch_.rows() - free_rows).transpose() *
                                   flat(scratch_).tail(U_patch_.rows() - free_rows);
      // held points of the model within A carry no unknown: zero rows of z and y
      for (index_t i = 0; i < patch_.n_free; ++i)
        if (patch.fixed[static_cast<std::size_t>(i)]) scratch_.col(i).setZero();
      scratch_.rightCols(patch.n_points - patch_.n_free).setZero();
      // by CG on the tangent with its factor as the preconditioner: the factor is of the assembled tangent, whose
      // hourglass part is a bound (tangent_matrix.hpp), and a Schur complement made with it directly left each
      // Newton iteration halving the residual instead of squaring it
      Points& y = condensed_start_[static_cast<std::size_t>(k)];
      newton_.solve_linearised(inner_, problem(), scratch_, y, condensation_tolerance, condensation_iterations,
                               *inner_ws_);
      z_free_.col(k) = flat(scratch_).head(free_rows);
      y_free_.col(k) = flat(y).head(free_rows);
    }
    hessian_.noalias() -= z_free_.transpose() * y_free_;
    hessian_ = 0.5 * (hessian_ + hessian_.transpose()).eval();
    hessian_valid_ = true;
  }
  hessian += hessian_;
}

void ContactPatch::condense(Eigen::VectorXd& gradient) {
  // s = H_AA^-1 g_v (the factor of the Hessian in use), and g_q - H_qv s = g_q - Z^T s
  const Eigen::Index free_rows = 3 * patch_.n_free;
  solved_.setZero();
  newton_.solve_linearised(inner_, problem(), residual_, solved_, direction_tolerance, direction_iterations,
                           *inner_ws_);
  gradient.noalias() -= z_free_.transpose() * flat(solved_).head(free_rows);
}

double ContactPatch::begin_move(const Eigen::VectorXd& dq) {
  // dv = -H_AA^-1 (g_v + H_AR U_R dq) = -(s + Y dq); zero at held points (s and Y are)
  const Eigen::Index free_rows = 3 * patch_.n_free;
  move_start_.leftCols(patch_.n_free) = star_.leftCols(patch_.n_free);
  flat(move_).head(free_rows).noalias() = -y_free_ * dq;
  flat(move_).head(free_rows) -= flat(solved_).head(free_rows);
  return flat(residual_).head(free_rows).dot(flat(move_).head(free_rows));
}

void ContactPatch::move(double alpha) {
  const index_t n_free = patch_.n_free;
  star_.leftCols(n_free) = move_start_.leftCols(n_free) + alpha * move_.leftCols(n_free);
}

void ContactPatch::finish_step(Points& u, Points& velocity, double dt) {
  forget_velocities();
  if (!active_) return;
  const index_t n_free = patch_.n_free;
  velocity_.resize(3, n_free);  // (allocates only when the patch changes)
  for (index_t k = 0; k < n_free; ++k) {
    const index_t i = patch_.full_of[static_cast<std::size_t>(k)];
    finished_free_.push_back(i);
    velocity_slot_[static_cast<std::size_t>(i)] = k;
    velocity_.col(k) = dt > 0 ? Vec3((star_.col(k) - start_.col(k)) / dt) : Vec3::Zero();
    u.col(i) = star_.col(k);
  }
  write_velocities(velocity);
}

void ContactPatch::write_velocities(Points& velocity) const {
  for (std::size_t k = 0; k < finished_free_.size(); ++k)
    velocity.col(finished_free_[k]) = velocity_.col(static_cast<Eigen::Index>(k));
}

void ContactPatch::forget_velocities() {
  for (const index_t i : finished_free_) velocity_slot_[static_cast<std::size_t>(i)] = -1;
  finished_free_.clear();
}

}  // namespace pointhaptics
