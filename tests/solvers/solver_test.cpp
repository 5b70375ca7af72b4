// Tests for solvers/solver: the spec makes the solver it names, Newton's settings follow the spec, and held
// points follow their prescribed, ramped displacement.
#include <pointhaptics/solvers/solver.hpp>

#include <pointhaptics/mechanics/model_builder.hpp>
#include <pointhaptics/solvers/explicit_solver.hpp>
#include <pointhaptics/solvers/implicit_solver.hpp>
#include <pointhaptics/solvers/static_solver.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace pointhaptics {
namespace {

Model ramped_bar() {
  Model model = build_model(test::jittered_box(4, 3, 3, 0.01, 0.0), MaterialParams{}, KernelParams{});
  FixedGroup pulled{"pulled", Vec3(0.002, 0, 0), 0.1, {}};
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.X(0, i) > 0.025) {
      model.fixed[i] = 1;
      pulled.points.push_back(i);
    }
  model.fixed_groups.push_back(pulled);
  return model;
}

TEST(Solver, TheSpecMakesTheSolverItNames) {
  const Model model = ramped_bar();
  SolverSpec spec;
  spec.kind = SolverKind::EXPLICIT;
  EXPECT_NE(dynamic_cast<ExplicitSolver*>(make_solver(model, spec).get()), nullptr);
  EXPECT_GT(make_solver(model, spec).get()->stable_dt(), 0.0);
  EXPECT_DOUBLE_EQ(make_solver(model, spec, 1.5e-5)->stable_dt(), 1.5e-5);  // a known stable step is kept
  spec.kind = SolverKind::IMPLICIT;
  EXPECT_NE(dynamic_cast<ImplicitSolver*>(make_solver(model, spec).get()), nullptr);
  spec.kind = SolverKind::STATIC;
  EXPECT_NE(dynamic_cast<StaticSolver*>(make_solver(model, spec).get()), nullptr);
}

TEST(Solver, NewtonSettingsFollowTheSpec) {
  SolverSpec spec;
  spec.kind = SolverKind::STATIC;
  EXPECT_DOUBLE_EQ(newton_settings(spec).tolerance, 1e-8);
  spec.kind = SolverKind::IMPLICIT;
  EXPECT_DOUBLE_EQ(newton_settings(spec).tolerance, 1e-6);
  EXPECT_FALSE(newton_settings(spec).accept_at_budget);
  spec.iteration_budget = 3;
  spec.tolerance = 1e-9;
  const NewtonSettings budget = newton_settings(spec);
  EXPECT_TRUE(budget.accept_at_budget);
  EXPECT_EQ(budget.max_iterations, 3);
  EXPECT_DOUBLE_EQ(budget.tolerance, 1e-9);
}

TEST(Solver, HeldPointsFollowTheirRampAndTheLoadFactor) {
  const Model model = ramped_bar();
  Points u = Points::Zero(3, model.n_points), v = Points::Zero(3, model.n_points);
  hold_points(model, 0.05, u, &v, 0.01);  // half-way up the 0.1 s ramp
  const index_t held = model.fixed_groups[0].points.front();
  EXPECT_DOUBLE_EQ(u(0, held), 0.001);
  EXPECT_DOUBLE_EQ(v(0, held), 0.1);                                                 // 1 mm over the 10 ms step
  hold_points(model, std::numeric_limits<double>::infinity(), u, nullptr, 0, 0.25);  // static, a quarter of the load
  EXPECT_DOUBLE_EQ(u(0, held), 0.0005);
  // free points are not touched
  for (index_t i = 0; i < model.n_points; ++i) {
    if (!model.fixed[i]) {
      ASSERT_EQ(u.col(i).norm(), 0.0);
    }
  }
}

}  // namespace
}  // namespace pointhaptics
