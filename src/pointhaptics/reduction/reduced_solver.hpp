#pragma once
/// @file The solver of a reduced model (issue 49, `[reduction]`): the basis and the polynomial are made when it is
/// (the set-up), then each static solve or backward Euler step runs full Newton in the r reduced coordinates
/// (reduced_integrator.hpp) and writes u = U q and v = U q' into the state, so every output reads it as a full
/// model's.
#include <pointhaptics/reduction/modal_basis.hpp>
#include <pointhaptics/reduction/reduced_integrator.hpp>
#include <pointhaptics/solvers/solver.hpp>

#include <memory>

namespace pointhaptics {

class ReducedSolver final : public Solver {
 public:
  /// Builds the basis (spec.reduction.modes vectors; the model's constant loads' static response among them) and
  /// the polynomial. Throws Error for what a reduced model does not do yet: an explicit solver, held points moved
  /// by a prescribed displacement, a material other than St. Venant-Kirchhoff (svk_polynomial.hpp).
  ReducedSolver(const Model& model, const SolverSpec& spec, Workspace& ws);
  /// A static solve or one backward Euler step. State-dependent forces (tools, contact) are not reduced yet: a
  /// step given any FAILS, naming them.
  StepReport step(const Model& model, State& state, Workspace& ws, DynamicForces* forces) override;
  const ModalBasis& basis() const { return basis_; }
  const SvkPolynomial& polynomial() const { return *polynomial_; }
  double setup_s() const { return setup_s_; }

 private:
  SolverSpec spec_;
  ModalBasis basis_;
  std::unique_ptr<SvkPolynomial> polynomial_;
  std::unique_ptr<ReducedIntegrator> integrator_;
  ReducedState reduced_;
  double setup_s_ = 0;
};

}  // namespace pointhaptics
