// Tests for solvers/newton: Newton-CG minimises the problem's energy (quadratically near the answer), the
// inertia term pulls toward the anchor, springs act like their energy says, and a hard problem is reported,
// never thrown.
#include <pointhaptics/solvers/newton.hpp>

#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>
#include <pointhaptics/solvers/reactions.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

// a 6 x 3 x 3 bar held at x = 0, free elsewhere
Model held_bar() {
  Model model = build_model(test::jittered_box(6, 3, 3, 0.01, 0.1), MaterialParams{}, KernelParams{});
  FixedGroup clamp;
  clamp.name = "clamp";
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.X(0, i) < 0.005) {
      model.fixed[i] = 1;
      clamp.points.push_back(i);
    }
  model.fixed_groups.push_back(clamp);
  return model;
}

TEST(Newton, SmallLoadsConvergeInAFewIterationsToTheBalance) {
  Model model = held_bar();
  for (index_t i = 0; i < model.n_points; ++i)
    if (!model.fixed[i]) model.f_ext(1, i) = -1e-4;
  Workspace ws(model, 1);
  NewtonSolver newton(model);
  NewtonProblem problem;
  problem.load = &model.f_ext;
  Points u = Points::Zero(3, model.n_points);
  const NewtonStats stats = newton.solve(model, problem, u, ws, NewtonSettings{});
  ASSERT_TRUE(stats.converged) << stats.failure;
  EXPECT_LE(stats.iterations, 4);  // nearly linear: quadratic convergence from the first step
  EXPECT_LE(stats.residual, 1e-8);
  compute_internal_forces(model, u, ws);
  EXPECT_LT(relative_residual(model, ws.f_int), 1e-7);
}

TEST(Newton, AStiffInertiaTermPullsTheAnswerOntoTheAnchor) {
  // minimising W - b.u + 0.5 k |u - a|_M^2 with k far above the material's stiffness: u ~ a + b / (k m)
  const Model model = held_bar();
  Workspace ws(model, 1);
  NewtonSolver newton(model);
  const Points anchor = test::random_field(model.n_points, 1e-6, 5);
  Points load = Points::Zero(3, model.n_points);
  NewtonProblem problem;
  problem.load = &load;
  problem.inertia = 1e12;
  problem.anchor = &anchor;
  Points u = Points::Zero(3, model.n_points);
  NewtonSettings settings;
  settings.tolerance = 1e-10;
  ASSERT_TRUE(newton.solve(model, problem, u, ws, settings).converged);
  for (index_t i = 0; i < model.n_points; ++i) {
    if (model.fixed[i]) {
      EXPECT_EQ(u.col(i).norm(), 0.0);  // held points keep what u had
      continue;
    }
    ASSERT_LE((u.col(i) - anchor.col(i)).norm(), 1e-3 * anchor.col(i).norm() + 1e-12) << "point " << i;
  }
}

TEST(Newton, SpringsBalanceTheLoadLikeTheirEnergySays) {
  // stiff springs on every free point toward c: u ~ c + S^-1 b when S dominates the material
  Model model = held_bar();
  Workspace ws(model, 1);
  NewtonSolver newton(model);
  Eigen::Matrix<double, 9, Eigen::Dynamic> springs = Eigen::Matrix<double, 9, Eigen::Dynamic>::Zero(9, model.n_points);
  const double s = 1e10;
  for (index_t i = 0; i < model.n_points; ++i) springs.col(i) = (s * Mat3::Identity()).reshaped();
  const Points anchor = test::random_field(model.n_points, 1e-6, 6);
  Points load = Points::Constant(3, model.n_points, 1e-3);
  NewtonProblem problem;
  problem.load = &load;
  problem.springs = &springs;
  problem.spring_anchor = &anchor;
  Points u = Points::Zero(3, model.n_points);
  ASSERT_TRUE(newton.solve(model, problem, u, ws, NewtonSettings{}).converged);
  for (index_t i = 0; i < model.n_points; ++i) {
    if (!model.fixed[i]) {
      ASSERT_LE((u.col(i) - anchor.col(i) - load.col(i) / s).norm(), 1e-3 * anchor.col(i).norm()) << i;
    }
  }
}

TEST(Newton, AHardProblemIsReportedNotThrown) {
  Model model = held_bar();
  for (index_t i = 0; i < model.n_points; ++i)
    if (!model.fixed[i]) model.f_ext(1, i) = -0.5;  // far beyond one Newton step
  Workspace ws(model, 1);
  NewtonSolver newton(model);
  NewtonProblem problem;
  problem.load = &model.f_ext;
  NewtonSettings settings;
  settings.max_iterations = 1;
  settings.tolerance = 1e-12;
  Points u = Points::Zero(3, model.n_points);
  NewtonStats stats;
  EXPECT_NO_THROW(stats = newton.solve(model, problem, u, ws, settings));
  EXPECT_FALSE(stats.converged);
  EXPECT_STRNE(stats.failure, "");
  EXPECT_TRUE(u.allFinite());
  // with the budget accepted, the same iterate is kept as a result (implicit real time)
  settings.accept_at_budget = true;
  u.setZero();
  EXPECT_TRUE(newton.solve(model, problem, u, ws, settings).converged);
}

}  // namespace
}  // namespace pointhaptics
