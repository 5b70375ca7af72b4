#include <pointhaptics/reduction/reduced_integrator.hpp>

#include <algorithm>
#include <cmath>
#include <utility>

namespace pointhaptics {

ReducedIntegrator::ReducedIntegrator(const SvkPolynomial& forces, Eigen::VectorXd external, double damping)
    : forces_(forces), external_(std::move(external)), damping_(damping) {
  const int r = forces.size();
  gradient_.resize(r);
  direction_.resize(r);
  trial_.resize(r);
  anchor_.resize(r);
  scaled_force_.resize(r);
  start_.resize(r);
  hessian_.resize(r, r);
  llt_ = Eigen::LLT<Eigen::MatrixXd>(r);
}

double ReducedIntegrator::objective(const Eigen::VectorXd& x, const Eigen::VectorXd& force, double inertia,
                                    const Eigen::VectorXd& anchor) const {
  return forces_.energy(x) - force.dot(x) + 0.5 * inertia * (x - anchor).squaredNorm();
}

ReducedSolveReport ReducedIntegrator::minimise(Eigen::VectorXd& x, const Eigen::VectorXd& force, double inertia,
                                               const Eigen::VectorXd& anchor, double tolerance, int max_iterations) {
  ReducedSolveReport report;
  // the residual's scale: the load, or what the rest stiffness makes of the current coordinates, or inertia's
  trial_.noalias() = forces_.rest_stiffness() * x;
  const double scale = std::max({force.norm(), trial_.norm(), inertia * (x - anchor).norm(), 1e-300});
  for (report.iterations = 0; report.iterations <= max_iterations; ++report.iterations) {
    forces_.evaluate(x, gradient_, &hessian_);
    gradient_ -= force;
    gradient_.noalias() += inertia * (x - anchor);
    report.residual = gradient_.norm();
    if (!std::isfinite(report.residual)) return report;
    if (report.residual <= tolerance * scale) {
      report.converged = true;
      return report;
    }
    if (report.iterations == max_iterations) break;
    hessian_.diagonal().array() += inertia;
    llt_.compute(hessian_);
    if (llt_.info() != Eigen::Success) {
      // indefinite (the geometric term under compression): the rest stiffness, positive definite, instead
      hessian_ = forces_.rest_stiffness();
      hessian_.diagonal().array() += inertia;
      llt_.compute(hessian_);
    }
    direction_ = llt_.solve(gradient_);
    direction_ *= -1;
    // backtracking on the objective (Armijo), Newton's full step first
    const double before = objective(x, force, inertia, anchor), slope = gradient_.dot(direction_);
    // near the answer the objective's change falls below its round-off: then Newton's full step is taken
    const bool resolvable = -slope > 1e-11 * std::abs(before);
    double alpha = 1;
    trial_ = x + direction_;
    for (int halving = 0; resolvable && halving < 30; ++halving) {
      if (objective(trial_, force, inertia, anchor) <= before + 1e-4 * alpha * slope) break;
      alpha *= 0.5;
      trial_ = x + alpha * direction_;
    }
    x = trial_;
  }
  return report;
}

ReducedSolveReport ReducedIntegrator::step(ReducedState& state, double dt, double tolerance, int max_iterations) {
  // q' minimises W - f.q' + (1/dt^2 + c/dt) |q' - a|^2 / 2 with a = q + dt v / (1 + c dt): the two quadratic terms
  // |q' - q - dt v|^2 / (2 dt^2) + c |q' - q|^2 / (2 dt) differ from it by a constant
  const double inertia = 1 / (dt * dt) + damping_ / dt;
  anchor_ = state.q + (dt / (1 + damping_ * dt)) * state.v;
  start_ = state.q + dt * state.v;  // warm start
  const ReducedSolveReport report = minimise(start_, external_, inertia, anchor_, tolerance, max_iterations);
  if (!report.converged) return report;
  state.v = (start_ - state.q) / dt;
  state.q = start_;
  return report;
}

ReducedSolveReport ReducedIntegrator::solve_static(Eigen::VectorXd& q, double tolerance, int max_iterations) {
  anchor_.setZero();
  // the whole load first; when Newton does not get there, halves of what is left, each from the last answer
  double reached = 0, share = 1;
  ReducedSolveReport report;
  int total = 0;
  while (reached < 1) {
    const double target = std::min(1.0, reached + share);
    scaled_force_ = target * external_;
    start_ = q;
    report = minimise(start_, scaled_force_, 0.0, anchor_, tolerance, max_iterations);
    total += report.iterations;
    if (report.converged) {
      q = start_;
      reached = target;
      share *= 2;
    } else if ((share *= 0.5) < 1e-4) {
      break;
    }
  }
  report.iterations = total;
  report.load_reached = reached;
  report.converged = reached >= 1;
  return report;
}

}  // namespace pointhaptics
