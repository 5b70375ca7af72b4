#include <pointhaptics/solvers/newton.hpp>

#include <pointhaptics/core/run_control.hpp>

#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/solvers/reactions.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <thread>

namespace pointhaptics {
namespace {

double dot(const Points& a, const Points& b) { return (a.array() * b.array()).sum(); }

// z = B r with B the block-Jacobi preconditioner's inverted diagonal blocks
void precondition_blocks(const Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks, const Points& r, Points& z) {
  for (Eigen::Index i = 0; i < r.cols(); ++i) z.col(i) = Eigen::Map<const Mat3>(blocks.col(i).data()) * r.col(i);
}

// blocks += the problem's own 3x3 diagonal terms beyond the material: the inertia's, the springs' and, unless
// `term` is false, its further term's (block-Jacobi takes only these; the Cholesky factor takes the term's
// coupling between points where the term gives it: EnergyTerm::add_to_matrix)
void add_problem_blocks(const Model& model, const NewtonProblem& problem,
                        Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks, bool term = true) {
  if (problem.term && term) problem.term->add_diagonal_blocks(blocks);
  for (index_t i = 0; i < model.n_points; ++i) {
    Eigen::Map<Mat3> B(blocks.col(i).data());
    B.diagonal().array() += problem.inertia * model.mass[i];
    if (problem.springs) B += Eigen::Map<const Mat3>(problem.springs->col(i).data());
  }
}

}  // namespace

bool NewtonSettings::refactor_in_background(int threads) const {
  if (preconditioner != Preconditioner::CHOLESKY) return false;
  if (refactorisation == Refactorisation::BACKGROUND) return true;
  const auto cores = static_cast<long long>(available_cores());
  return refactorisation == Refactorisation::AUTO && real_time && cores >= threads + 2LL;
}

NewtonSolver::NewtonSolver(const Model&) {}

void NewtonSolver::mask_held(const Model& model, Points& x) const {
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.fixed[i]) x.col(i).setZero();
}

double NewtonSolver::energy(const Model& model, const NewtonProblem& problem, const Points& u,
                            std::vector<Mat3>& gradients, const ViscousStep& step) const {
  double pi = strain_energy(model, u, &gradients, step).total();
  for (index_t i = 0; i < model.n_points; ++i) {
    if (model.fixed[i]) continue;
    pi -= problem.load->col(i).dot(u.col(i));
    if (problem.inertia > 0)
      pi += 0.5 * problem.inertia * model.mass[i] * (u.col(i) - problem.anchor->col(i)).squaredNorm();
    if (problem.springs) {
      const Vec3 e = u.col(i) - problem.spring_anchor->col(i);
      pi += 0.5 * e.dot(Eigen::Map<const Mat3>(problem.springs->col(i).data()) * e);
    }
  }
  if (problem.term) pi += problem.term->energy(model, u);
  return pi;
}

double NewtonSolver::residual(const Model& model, const NewtonProblem& problem, const Points& u, Workspace& ws,
                              Points& r) const {
  compute_internal_forces(model, u, ws);
  r = ws.f_int + *problem.load;
  double inertial = 0;
  if (problem.inertia > 0) {
    for (index_t i = 0; i < model.n_points; ++i) {
      const Vec3 f = problem.inertia * model.mass[i] * (u.col(i) - problem.anchor->col(i));
      if (!model.fixed[i]) inertial += f.squaredNorm();
      r.col(i) -= f;
    }
  }
  if (problem.springs)
    for (index_t i = 0; i < model.n_points; ++i)
      r.col(i) -= Eigen::Map<const Mat3>(problem.springs->col(i).data()) * (u.col(i) - problem.spring_anchor->col(i));
  // a term's forces (a tool's contact) are part of the force scale: pressing on a body at rest, they are all
  // there is at the first iterate
  double term_forces = 0;
  if (problem.term) {
    Points& f = ws.solver_scratch().term_forces;
    f.setZero(3, model.n_points);
    problem.term->add_forces(model, u, f);
    r += f;
    term_forces = f.norm();
  }
  mask_held(model, r);
  const double scale =
      std::max({problem.load->norm(), ws.f_int.norm(), std::sqrt(inertial), term_forces, force_floor_, 1e-300});
  return r.norm() / scale;
}

bool NewtonSolver::blocks_stale(const Model& model, const NewtonProblem& problem, Workspace& ws) const {
  return refresh_blocks_ || blocks_model_ != &model || ws.solver_scratch().blocks.cols() != model.n_points ||
         blocks_inertia_ != problem.inertia || blocks_springs_ != (problem.springs != nullptr) ||
         blocks_term_ != (problem.term != nullptr);
}

void NewtonSolver::note_cg_rate(long long iterations, double eta) {
  const double decades = std::max(1.0, -std::log10(std::max(eta, 1e-300)));
  const double rate = static_cast<double>(iterations) / decades;
  if (cg_rate_at_build_ < 0) cg_rate_at_build_ = rate;
  else if (rate > 1.5 * cg_rate_at_build_ + 1) refresh_blocks_ = true;
}

void NewtonSolver::build_preconditioner(const Model& model, const NewtonProblem& problem, const Points& u,
                                        Workspace& ws) {
  // the two-level preconditioner's coarse level lags with the blocks (rebuilt with them)
  two_level_ = kind_ == Preconditioner::TWO_LEVEL && (coarse_.built_for(model) || coarse_.build(model)) &&
               coarse_.factorise(model, u, problem.inertia);
  blocks_model_ = &model;
  blocks_inertia_ = problem.inertia;
  blocks_springs_ = problem.springs != nullptr;
  blocks_term_ = problem.term != nullptr;
  refresh_blocks_ = false;
  cg_rate_at_build_ = -1;
  const double inertia = problem.inertia;
  Eigen::Matrix<double, 9, Eigen::Dynamic>& blocks = ws.solver_scratch().blocks;
  tangent_.diagonal_blocks(model, blocks, &ws);
  add_problem_blocks(model, problem, blocks);
  for (index_t i = 0; i < model.n_points; ++i) {
    Eigen::Map<Mat3> B(blocks.col(i).data());
    if (model.fixed[i]) {
      B.setZero();
      continue;
    }
    Mat3 sym = 0.5 * (B + B.transpose());
    Eigen::LLT<Mat3> llt(sym);
    if (llt.info() == Eigen::Success && std::isfinite(sym.trace())) {
      B = llt.solve(Mat3::Identity());
    } else {
      // an indefinite block (exact tangent under compression): a scaled identity keeps PCG well posed
      const double t = std::max(std::abs(sym.trace()) / 3.0, inertia * model.mass[i]);
      B = t > 0 && std::isfinite(t) ? Mat3(Mat3::Identity() / t) : Mat3(Mat3::Identity());
    }
  }
}

void NewtonSolver::assemble(const Model& model, const NewtonProblem& problem, Workspace& ws) {
  if (!cholesky_.analysed_for(model)) {
    build_tangent_pattern(model, matrix_);
    cholesky_.analyse(model, matrix_);
  }
  assemble_tangent(model, tangent_, matrix_, &ws);
  const bool coupled = problem.term && problem.term->add_to_matrix(matrix_);
  added_blocks_.setZero(9, model.n_points);
  add_problem_blocks(model, problem, added_blocks_, !coupled);
  for (index_t i = 0; i < model.n_points; ++i)
    Eigen::Map<Mat3>(matrix_.values.data() + 9 * static_cast<std::size_t>(matrix_.diagonal[i])) +=
        Eigen::Map<const Mat3>(added_blocks_.col(i).data());
}

bool NewtonSolver::factorise(const Model& model, const NewtonProblem& problem, Workspace& ws) {
  assemble(model, problem, ws);
  return cholesky_.factorise(matrix_);
}

void NewtonSolver::take_background_factor(NewtonStats& stats) {
  if (cholesky_.take_background()) {
    factor_stale_ = false;
    ++stats.factorisations;
    ++stats.background_factorisations;
    refactorise_ = false;
    return;
  }
  // not positive definite. An exact tangent: the factor in use is kept (tried again, and a new one made of the
  // projected tangent when CG is slow with it); a projected one (never expected): refactorise in place
  factor_stale_ = false;
  if (background_mode_ == TangentMode::EXACT) exact_indefinite_ = true;
  else refactorise_ = true;
}

void NewtonSolver::precondition(const Points& r, Points& z, Workspace& ws) {
  if (use_cholesky_) {
    cholesky_.solve(r, z);
    return;
  }
  precondition_blocks(ws.solver_scratch().blocks, r, z);
  if (two_level_) coarse_.add_correction(*blocks_model_, r, z);
}

void NewtonSolver::apply_tangent(const Model& model, const NewtonProblem& problem, const Points& p, Workspace& ws,
                                 Points& q) const {
  tangent_.apply(model, p, ws, q);
  if (problem.inertia > 0) q += problem.inertia * (p.array().rowwise() * model.mass.transpose().array()).matrix();
  if (problem.springs)
    for (index_t i = 0; i < model.n_points; ++i)
      q.col(i) += Eigen::Map<const Mat3>(problem.springs->col(i).data()) * p.col(i);
  if (problem.term) problem.term->add_tangent_product(p, q);
  mask_held(model, q);
}

void NewtonSolver::linearise(const Model& model, const NewtonProblem& problem, const Points& u, Workspace& ws,
                             bool material) {
  if (problem.term) problem.term->linearise(model, u, TangentMode::PROJECTED);
  if (!material) return;
  tangent_.linearise(model, u, TangentMode::PROJECTED, &ws);
  build_preconditioner(model, problem, u, ws);
  preconditioner_mode_ = TangentMode::PROJECTED;
}

bool NewtonSolver::linearise_factorised(const Model& model, const NewtonProblem& problem, const Points& u,
                                        Workspace& ws) {
  linearise(model, problem, u, ws);
  kind_ = Preconditioner::CHOLESKY;
  use_cholesky_ = factorise(model, problem, ws);
  factor_stale_ = false;
  refactorise_ = !use_cholesky_;
  return use_cholesky_;
}

int NewtonSolver::solve_linearised(const Model& model, const NewtonProblem& problem, const Points& b, Points& x,
                                   double tolerance, int max_iterations, Workspace& ws) {
  SolverScratch& s = ws.solver_scratch();
  Points &r = s.r, &dx = s.dx;
  // the residual of the warm start, then CG on the correction
  apply_tangent(model, problem, x, ws, r);
  r = b - r;
  mask_held(model, r);
  const double target = tolerance * b.norm(), left = r.norm();
  if (!(left > target)) return 0;
  long long iterations = 0;
  const bool positive = conjugate_gradients(model, problem, r, target / left, max_iterations, ws, dx, iterations);
  if (positive) x += dx;
  return positive ? static_cast<int>(iterations) : -static_cast<int>(iterations);
}

bool NewtonSolver::conjugate_gradients(const Model& model, const NewtonProblem& problem, const Points& r, double eta,
                                       int max_iterations, Workspace& ws, Points& x, long long& iterations) {
  SolverScratch& s = ws.solver_scratch();
  Points &cg_r = s.cg_r, &cg_z = s.cg_z, &cg_p = s.cg_p, &cg_q = s.cg_q;
  x.setZero();
  cg_r = r;
  precondition(cg_r, cg_z, ws);
  cg_p = cg_z;
  double rz = dot(cg_r, cg_z);
  const double target = eta * r.norm();
  for (int k = 0; k < max_iterations; ++k) {
    throw_if_stop_requested("conjugate gradients");  // each iteration costs about a force evaluation
    apply_tangent(model, problem, cg_p, ws, cg_q);
    const double curvature = dot(cg_p, cg_q);
    ++iterations;
    if (!(curvature > 0)) return false;  // negative curvature: the caller switches to the projected tangent
    const double alpha = rz / curvature;
    x += alpha * cg_p;
    cg_r -= alpha * cg_q;
    if (cg_r.norm() <= target) break;
    precondition(cg_r, cg_z, ws);
    const double rz_next = dot(cg_r, cg_z);
    cg_p = cg_z + (rz_next / rz) * cg_p;
    rz = rz_next;
  }
  return true;
}

NewtonStats NewtonSolver::solve(const Model& model, const NewtonProblem& problem, Points& u, Workspace& ws,
                                const NewtonSettings& settings) {
  NewtonStats stats;
  if (settings.preconditioner != kind_) refresh_blocks_ = true;  // another preconditioner: build it
  kind_ = settings.preconditioner;
  SolverScratch& s = ws.solver_scratch();
  Points &r = s.r, &dx = s.dx, &trial = s.trial;
  // with nothing pushing but round-off (a tool only touching, no load) the residual is measured against the
  // model's force floor, not against that round-off, which no iterate lowers (the shipped indentation scene
  // took 700 Newton iterations to report "not converged")
  force_floor_ = force_floor(model);
  const bool background = settings.refactor_in_background(ws.n_threads());
  // a factor made in the background during an earlier solve (of this model: a new one is analysed again)
  if (cholesky_.background_pending() && cholesky_.analysed_for(model) &&
      (!settings.real_time || cholesky_.background_ready()))
    take_background_factor(stats);
  double rel = residual(model, problem, u, ws, r);
  // Pi at the current iterate, evaluated only when a line search needs it (NaN: not yet)
  double pi = NAN;
  auto current_pi = [&] {
    if (std::isnan(pi)) pi = energy(model, problem, u, s.gradients, viscous_step(ws));
    return pi;
  };
  for (;;) {
    stats.residual = rel;
    if (!std::isfinite(rel)) {
      stats.failure = "non-finite residual";
      return stats;
    }
    if (rel <= settings.tolerance) {
      stats.converged = true;
      return stats;
    }
    if (stats.iterations >= settings.max_iterations) {
      stats.converged = settings.accept_at_budget;
      stats.failure = "iteration limit reached";
      return stats;
    }
    throw_if_stop_requested("Newton iterations");
    ++stats.iterations;
    // in real time a background factor is taken up as soon as it is ready
    if (settings.real_time && cholesky_.background_ready() && cholesky_.analysed_for(model))
      take_background_factor(stats);
    // inexact Newton: the linear solve is as accurate as the residual (quadratic convergence), at most
    // 1e-2, and never much more accurate than the tolerance needs
    const double eta = std::max(std::min(0.01, rel), 0.5 * settings.tolerance / rel);
    bool descent = false;
    for (TangentMode mode : {TangentMode::EXACT, TangentMode::PROJECTED}) {
      tangent_.linearise(model, u, mode, &ws);
      if (problem.term) problem.term->linearise(model, u, mode);
      // the block-Jacobi preconditioner is rebuilt when the tangent's mode changes, for another model or problem,
      // and when CG has slowed with it; in between it lags across iterations and steps (it changes slowly, and
      // costs a few tangent products: a quarter of an implicit step on the 10k-point beam when rebuilt every step)
      if (mode != preconditioner_mode_ || blocks_stale(model, problem, ws)) build_preconditioner(model, problem, u, ws);
      preconditioner_mode_ = mode;
      // the Cholesky factor lags across iterations and solves while CG converges fast with it
      // (an exact tangent found indefinite once is not factorised again: only a projected one, which is not)
      use_cholesky_ = settings.preconditioner == Preconditioner::CHOLESKY && cholesky_.factorised() && !refactorise_ &&
                      !factor_stale_;
      if (settings.preconditioner == Preconditioner::CHOLESKY && !use_cholesky_ && !factor_stale_ &&
          (mode == TangentMode::PROJECTED || !exact_indefinite_)) {
        use_cholesky_ = factorise(model, problem, ws);
        if (use_cholesky_) {
          ++stats.factorisations;
          factor_stale_ = false;
        }
        if (!use_cholesky_ && mode == TangentMode::EXACT) exact_indefinite_ = true;
        refactorise_ = !use_cholesky_;
      }
      const long long cg_before = stats.cg_iterations;
      // while a refactorisation runs in the background the factor can fall far behind the tangent (a contact
      // that moved: its stiff springs on other points), and CG with it then takes thousands of iterations
      // (0.5 s of a 1 ms step, measured): cut short, this iteration is solved with block-Jacobi instead
      const bool may_fall_back = use_cholesky_ && background;
      const int stale_limit = 4 * settings.refactor_iterations;
      bool positive = conjugate_gradients(
          model, problem, r, eta,
          may_fall_back ? std::min(stale_limit, settings.max_cg_iterations) : settings.max_cg_iterations, ws, dx,
          stats.cg_iterations);
      const long long factor_cg = use_cholesky_ ? stats.cg_iterations - cg_before : 0;
      if (may_fall_back && positive && factor_cg >= stale_limit) {
        use_cholesky_ = false;
        factor_stale_ = true;  // block-Jacobi until the worker's factor is taken up
        ++stats.stale_factor_fallbacks;
        const long long blocks_before = stats.cg_iterations;
        positive = conjugate_gradients(model, problem, r, eta, settings.max_cg_iterations, ws, dx, stats.cg_iterations);
        if (positive) note_cg_rate(stats.cg_iterations - blocks_before, eta);
      } else if (!use_cholesky_ && positive) {
        note_cg_rate(stats.cg_iterations - cg_before, eta);
      }
      if (factor_cg > settings.refactor_iterations) {
        // the factor has aged: refreshed in place at the next iteration, or in the background from this
        // iteration's tangent while the old factor keeps serving (assembled here, a fraction of the
        // factorisation; after this iteration's CG, which needs the tangent as it was linearised)
        if (!background) {
          refactorise_ = true;
        } else if (!cholesky_.background_pending()) {
          // an exact tangent found indefinite before is not factorised again: the projected one at this iterate
          // (the line search that follows needs no tangent, and the next iteration linearises afresh)
          const TangentMode factor_mode = exact_indefinite_ ? TangentMode::PROJECTED : mode;
          if (factor_mode != mode) {
            tangent_.linearise(model, u, factor_mode, &ws);
            if (problem.term) problem.term->linearise(model, u, factor_mode);
          }
          assemble(model, problem, ws);
          if (cholesky_.factorise_in_background(matrix_)) background_mode_ = factor_mode;
          else refactorise_ = true;
        }
      }
      if (positive && dot(dx, r) > 0) {
        descent = true;
        break;
      }
      ++stats.projected;
    }
    if (!descent) {
      precondition(r, dx, ws);  // preconditioned steepest descent, a descent direction for SPD blocks
      if (!(dot(dx, r) > 0)) dx = r;
    }
    // backtracking line search: a step is taken when it lowers Pi (Armijo) or the residual. Near
    // convergence Pi's change is below its round-off (~1e-11 relative here, sums of cancelling
    // terms) while the residual still falls quadratically, so both are needed.
    const double slope = dot(dx, r);  // -dPi/dalpha at alpha = 0
    double alpha = 1.0;
    bool accepted = false;
    for (int k = 0; k < 30 && !accepted; ++k, alpha *= 0.5) {
      throw_if_stop_requested("a line search");
      trial = u + alpha * dx;
      Points& r_trial = s.cg_r;  // scratch: CG is done for this iteration
      const double rel_trial = residual(model, problem, trial, ws, r_trial);
      if (!std::isfinite(rel_trial)) continue;
      // the residual test first: it costs nothing more, and Pi is only needed when it fails
      const bool lowers_residual = rel_trial <= (1.0 - 1e-4 * alpha) * rel;
      const double pi_trial = lowers_residual ? NAN : energy(model, problem, trial, s.gradients, viscous_step(ws));
      const double pi_now = lowers_residual ? NAN : current_pi();
      const bool armijo = !lowers_residual && std::isfinite(pi_trial) && pi_trial <= pi_now - 1e-4 * alpha * slope &&
                          std::abs(pi_trial - pi_now) > 1e-9 * std::max(std::abs(pi_now), 1e-300);
      if (armijo || lowers_residual) {
        u = trial;  // copied, not swapped: u is often the state, whose buffer NumPy views point into
        r.swap(r_trial);
        rel = rel_trial;
        pi = pi_trial;  // NaN when not computed: current_pi() evaluates it if it is ever needed
        accepted = true;
      }
    }
    if (!accepted && slope <= 1e-12 * std::abs(current_pi())) {
      // the Newton step promises less than the round-off of Pi: the residual is at its floor (forces are
      // sums of large cancelling stencil terms) above the tolerance, which double precision cannot reach on
      // this problem: said so, not reported as converged (issue 52: a tolerance of 1e-300 "converged" at 1.8e-14)
      stats.residual = rel;
      stats.stalled = true;
      stats.failure = "the residual stalled at double precision's floor above the tolerance (raise solver.tolerance)";
      return stats;
    }
    if (!accepted) {
      stats.residual = rel;
      stats.failure = "line search found no decrease";
      return stats;
    }
  }
}

}  // namespace pointhaptics
