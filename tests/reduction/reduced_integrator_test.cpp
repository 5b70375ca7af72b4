// Tests for reduction/reduced_integrator: the reduced static solve of a cantilever under a tip load agrees with the
// full point model's static solve (small and large deflections), reduced backward Euler steps settle on the
// reduced static answer (a step allocates nothing: tests/step_allocations_test.cpp).
#include <pointhaptics/pointhaptics.hpp>
#include <pointhaptics/reduction/modal_basis.hpp>
#include <pointhaptics/reduction/reduced_integrator.hpp>
#include <pointhaptics/reduction/svk_polynomial.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

constexpr double spacing = 0.01, length = 0.11;

// a 12 x 4 x 4 cantilever of St. Venant-Kirchhoff points (E = 100 kPa), held at x = 0, a load `force` (N) down
// spread over its tip's points
Model cantilever(double force) {
  MaterialParams m;
  m.young = 1e5;
  m.poisson = 0.3;
  m.density = 1000;
  Model model = build_model(test::jittered_box(12, 4, 4, spacing, 0.1), m, KernelParams{});
  int tip = 0;
  for (index_t i = 0; i < model.n_points; ++i) {
    model.fixed[static_cast<std::size_t>(i)] = model.X(0, i) < 0.5 * spacing;
    tip += model.X(0, i) > length - 0.5 * spacing;
  }
  model.f_ext.setZero(3, model.n_points);
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.X(0, i) > length - 0.5 * spacing) model.f_ext(1, i) = -force / tip;
  return model;
}

double tip_deflection(const Model& model, const Points& u) {
  double sum = 0;
  int n = 0;
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.X(0, i) > length - 0.5 * spacing) {
      sum += u(1, i);
      ++n;
    }
  return -sum / n;
}

struct Reduced {
  explicit Reduced(const Model& model, int modes) : ws(model, 2) {
    ModalBasisSettings settings;
    settings.size = modes;
    settings.loads = {model.f_ext};
    basis = build_modal_basis(model, settings, ws);
    polynomial = std::make_unique<SvkPolynomial>(model, basis.U, ws);
    integrator = std::make_unique<ReducedIntegrator>(
        *polynomial, basis.U.transpose() * Eigen::Map<const Eigen::VectorXd>(model.f_ext.data(), model.f_ext.size()),
        model.material.damping);
  }
  Workspace ws;
  ModalBasis basis;
  std::unique_ptr<SvkPolynomial> polynomial;
  std::unique_ptr<ReducedIntegrator> integrator;
};

TEST(ReducedStatics, CantileverTipDeflectionIsTheFullModelsWithinTwoPercent) {
  // 0.01 N: about 0.6% of the length (linear); 0.3 N: about 17%, where the geometry's nonlinearity matters
  for (double force : {0.01, 0.3}) {
    const Model model = cantilever(force);
    SolverSpec statics;
    statics.kind = SolverKind::STATIC;
    Simulation full(model, statics, 2);
    full.step();
    ASSERT_TRUE(full.summary().converged);
    const double expected = tip_deflection(model, full.state().u);

    Reduced reduced(model, 12);
    Eigen::VectorXd q = Eigen::VectorXd::Zero(12);
    const ReducedSolveReport report = reduced.integrator->solve_static(q);
    ASSERT_TRUE(report.converged) << "reached " << report.load_reached;
    const double measured = tip_deflection(model, displacement_of(reduced.basis.U, q, model.n_points));
    EXPECT_NEAR(measured, expected, 0.02 * expected) << "force " << force << " N";
    if (force > 0.1) {
      EXPECT_GT(expected, 0.1 * length);
    }
  }
}

TEST(ReducedDynamics, BackwardEulerStepsSettleOnTheStaticAnswer) {
  Model model = cantilever(0.05);
  model.material.damping = 30;
  Reduced reduced(model, 10);
  Eigen::VectorXd settled = Eigen::VectorXd::Zero(10);
  ASSERT_TRUE(reduced.integrator->solve_static(settled).converged);
  ReducedState state{Eigen::VectorXd::Zero(10), Eigen::VectorXd::Zero(10)};
  double deepest = 0;
  for (int k = 0; k < 2000; ++k) {
    ASSERT_TRUE(reduced.integrator->step(state, 1e-3).converged) << "step " << k;
    deepest = std::max(deepest, tip_deflection(model, displacement_of(reduced.basis.U, state.q, model.n_points)));
  }
  const double final = tip_deflection(model, displacement_of(reduced.basis.U, state.q, model.n_points));
  const double expected = tip_deflection(model, displacement_of(reduced.basis.U, settled, model.n_points));
  EXPECT_NEAR(final, expected, 1e-3 * expected);
  EXPECT_GT(deepest, final);  // it overshot on the way: dynamics, not a static solve in disguise
  EXPECT_LT(state.v.norm(), 1e-3 * settled.norm());
}

}  // namespace
}  // namespace pointhaptics
