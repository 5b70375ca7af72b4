#include <pointhaptics/reduction/reduced_integrator.hpp>

#include <algorithm>
#include <cmath>
#include <utility>

namespace pointhaptics {

ReducedIntegrator::ReducedIntegrator(const SvkPolynomial& forces, Eigen::VectorXd external, double damping)
    : forces_(forces), external_(std::move(external)), damping_(damping), llt_(forces.size()) {
  const int r = forces.size();
  gradient_.resize(r);
  condensed_.resize(r);
  direction_.resize(r);
  trial_.resize(r);
  anchor_.resize(r);
  scaled_force_.resize(r);
  start_.resize(r);
  iterate_.resize(r);
  coupling_gradient_.resize(r);
  hessian_.resize(r, r);  // llt_ is sized where it is made: an assigned LLT would copy its unset status
}

ReducedSolveReport ReducedIntegrator::minimise(Eigen::VectorXd& x, const Eigen::VectorXd& force, double inertia,
                                               const Eigen::VectorXd& anchor, double tolerance, int max_iterations,
                                               bool stop_at_budget, ReducedCoupling* coupling) {
  ReducedSolveReport report;
  // the residual's scale: the load, or what the rest stiffness makes of the current coordinates, or inertia's
  trial_.noalias() = forces_.rest_stiffness() * x;
  double scale = std::max({force.norm(), trial_.norm(), inertia * (x - anchor).norm(), 1e-300});
  // Newton with backtracking (Armijo) on the objective, which each evaluation gives with the gradient: a step is
  // taken whole and halved only when the objective at its end says so, so a good step costs one evaluation
  double before = 0, slope = 0, alpha = 1;
  bool checking = false;  // the last step's end is to be checked against `before`
  for (int evaluations = 0; evaluations < 4 * max_iterations + 30; ++evaluations) {
    double energy = 0;
    forces_.evaluate(x, gradient_, &hessian_, &energy);
    if (coupling) {
      // a contact region's energy; its forces count in the residual's scale (a tool can press on an object at
      // rest)
      double coupled = 0;
      coupling_gradient_.setZero();
      if (!coupling->evaluate(x, coupled, coupling_gradient_)) {
        if (!checking || (alpha *= 0.5) < 1e-9) return report;
        x = start_ + alpha * direction_;
        coupling->move(alpha);
        continue;
      }
      energy += coupled;
      gradient_ += coupling_gradient_;
      scale = std::max(scale, coupling_gradient_.norm());
    }
    const double value = energy - force.dot(x) + 0.5 * inertia * (x - anchor).squaredNorm();
    if (!std::isfinite(value)) return report;
    if (checking && value > before + 1e-4 * alpha * slope) {
      if ((alpha *= 0.5) < 1e-9) return report;
      x = start_ + alpha * direction_;
      if (coupling) coupling->move(alpha);
      continue;
    }
    gradient_ -= force;
    gradient_.noalias() += inertia * (x - anchor);
    report.residual = coupling ? std::hypot(gradient_.norm(), coupling->residual()) : gradient_.norm();
    if (report.residual <= tolerance * scale) {
      report.converged = true;
      return report;
    }
    if (report.iterations == max_iterations) return report;
    ++report.iterations;
    hessian_.diagonal().array() += inertia;
    if (coupling) coupling->add_hessian(hessian_);
    llt_.compute(hessian_);
    if (llt_.info() != Eigen::Success) {
      // indefinite (the geometric term under compression): the rest stiffness, positive definite, instead
      hessian_ = forces_.rest_stiffness();
      hessian_.diagonal().array() += inertia;
      if (coupling) coupling->add_hessian(hessian_);
      llt_.compute(hessian_);
    }
    // with a coupling, its unknowns eliminated (ReducedCoupling): the condensed gradient, and the slope of the
    // step in both
    condensed_ = gradient_;
    if (coupling) coupling->condense(condensed_);
    direction_ = llt_.solve(condensed_);
    direction_ *= -1;
    before = value;
    slope = gradient_.dot(direction_);
    if (coupling) slope += coupling->begin_move(direction_);
    alpha = 1;
    // near the answer the objective's change falls below its round-off: then Newton's step is not checked
    checking = -slope > 1e-11 * std::abs(value);
    start_ = x;
    x += direction_;
    if (coupling) coupling->move(1);
    if (stop_at_budget && report.iterations == max_iterations) {
      report.at_budget = true;
      return report;
    }
  }
  return report;
}

ReducedSolveReport ReducedIntegrator::step(ReducedState& state, double dt, double tolerance, int max_iterations,
                                           bool accept_at_budget, ReducedCoupling* coupling) {
  // q' minimises W - f.q' + (1/dt^2 + c/dt) |q' - a|^2 / 2 with a = q + dt v / (1 + c dt): the two quadratic terms
  // |q' - q - dt v|^2 / (2 dt^2) + c |q' - q|^2 / (2 dt) differ from it by a constant
  const double inertia = this->inertia(dt);
  anchor_ = state.q + carry(dt) * state.v;
  iterate_ = state.q + dt * state.v;  // warm start
  const ReducedSolveReport report =
      minimise(iterate_, external_, inertia, anchor_, tolerance, max_iterations, accept_at_budget, coupling);
  if (!report.converged && !report.at_budget) return report;
  state.v = (iterate_ - state.q) / dt;
  state.q = iterate_;
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
    iterate_ = q;
    report = minimise(iterate_, scaled_force_, 0.0, anchor_, tolerance, max_iterations);
    total += report.iterations;
    if (report.converged) {
      q = iterate_;
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
