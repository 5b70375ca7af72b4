// Tests for solvers/newton and solvers/static_solver: equilibrium, load stepping, indefinite tangents,
// prescribed displacements.
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/solvers/reactions.hpp>
#include <pointhaptics/solvers/static_solver.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

const double spacing = 0.01;

// a 9 x 3 x 3 bar clamped at x = 0 with a tip load in -y (N)
Model cantilever(double tip_force, double hourglass = 0.05) {
  MaterialParams m;
  m.young = 1e5;
  m.poisson = 0.4;
  m.hourglass = hourglass;
  KernelParams k;
  Model model = build_model(test::jittered_box(9, 3, 3, spacing, 0.0), m, k);
  FixedGroup clamp;
  clamp.name = "clamp";
  for (index_t i = 0; i < model.n_points; ++i) {
    if (model.X(0, i) < 1e-9) {
      model.fixed[i] = 1;
      clamp.points.push_back(i);
    }
    if (model.X(0, i) > 8 * spacing - 1e-9) model.f_ext(1, i) = -tip_force / 9;
  }
  model.fixed_groups.push_back(clamp);
  return model;
}

double out_of_balance(const Model& model, const Points& u) {
  Workspace ws(model, 1);
  compute_internal_forces(model, u, ws);
  return relative_residual(model, ws.f_int);
}

TEST(StaticSolver, FindsTheEquilibriumAtSmallAndLargeLoads) {
  for (double force : {1e-3, 0.2}) {  // tip deflection ~1% and ~40% of the length
    const Model model = cantilever(force);
    State state = State::at_rest(model);
    Workspace ws(model, 2);
    NewtonSolver newton(model);
    NewtonSettings settings;
    const StaticStats stats = solve_static(model, state, ws, newton, settings);
    ASSERT_TRUE(stats.converged) << stats.failure;
    EXPECT_LE(stats.residual, settings.tolerance);
    EXPECT_LE(out_of_balance(model, state.u), 1e-7);
    EXPECT_GE(stats.load_steps, 1);
    const double tip = state.u(1, model.n_points - 1);
    EXPECT_LT(tip, 0.0);
    if (force < 0.01) {
      EXPECT_LE(stats.iterations, 8);  // Newton on a nearly linear problem
    } else {
      EXPECT_GT(-tip, 0.2 * 8 * spacing);  // geometrically nonlinear regime
    }
    // the supports carry the load
    EXPECT_NEAR(support_reactions(model,
                                  [&] {
                                    Workspace w(model, 1);
                                    compute_internal_forces(model, state.u, w);
                                    return w.f_int;
                                  }())[0]
                    .y(),
                force, 1e-7 * force);
  }
}

TEST(StaticSolver, CutsTheLoadStepWhenNewtonFailsAndReachesTheSameAnswer) {
  const Model model = cantilever(0.2);
  Workspace ws(model, 1);
  NewtonSolver newton(model);
  State full = State::at_rest(model), stepped = State::at_rest(model);
  NewtonSettings settings;
  const StaticStats a = solve_static(model, full, ws, newton, settings);
  settings.max_iterations = 4;  // too few for the full load at once
  const StaticStats b = solve_static(model, stepped, ws, newton, settings);
  ASSERT_TRUE(a.converged);
  ASSERT_TRUE(b.converged) << b.failure << " cutbacks " << b.cutbacks << " steps " << b.load_steps;
  EXPECT_GT(b.cutbacks, 0);
  EXPECT_GT(b.load_steps, 1);
  EXPECT_LE((full.u - stepped.u).norm(), 1e-6 * full.u.norm());
}

TEST(StaticSolver, ReportsFailureInsteadOfLooping) {
  const Model model = cantilever(0.2);
  Workspace ws(model, 1);
  NewtonSolver newton(model);
  State state = State::at_rest(model);
  NewtonSettings settings;
  settings.max_iterations = 1;
  settings.max_cg_iterations = 1;
  const StaticStats stats = solve_static(model, state, ws, newton, settings);
  EXPECT_FALSE(stats.converged);
  EXPECT_NE(stats.failure.find("no equilibrium beyond"), std::string::npos) << stats.failure;
  EXPECT_TRUE(state.u.allFinite());
}

TEST(StaticSolver, RecoversFromACompressedStartWithTheProjectedTangent) {
  // start far from equilibrium in strong compression, where the exact tangent is indefinite
  const Model model = cantilever(1e-3);
  Workspace ws(model, 1);
  NewtonSolver newton(model);
  State reference = State::at_rest(model);
  ASSERT_TRUE(solve_static(model, reference, ws, newton, NewtonSettings{}).converged);
  Points u = test::random_field(model.n_points, 0.05 * spacing, 4);
  u.row(0) += -0.35 * model.X.row(0);
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.fixed[i]) u.col(i).setZero();
  NewtonProblem problem;
  problem.load = &model.f_ext;
  const NewtonStats stats = newton.solve(model, problem, u, ws, NewtonSettings{});
  ASSERT_TRUE(stats.converged) << stats.failure << " residual " << stats.residual << " iterations " << stats.iterations
                               << " projected " << stats.projected;
  EXPECT_GT(stats.projected, 0);
  EXPECT_LE((u - reference.u).norm(), 1e-5 * reference.u.norm());
}

TEST(StaticSolver, HonoursPrescribedDisplacements) {
  // pull the free end of a clamped bar by 1 mm along x: the reaction balances, free points in between
  Model model = cantilever(0.0);
  FixedGroup pull;
  pull.name = "pull";
  pull.displacement = Vec3(1e-3, 0, 0);
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.X(0, i) > 8 * spacing - 1e-9) {
      model.fixed[i] = 1;
      pull.points.push_back(i);
    }
  model.fixed_groups.push_back(pull);
  State state = State::at_rest(model);
  Workspace ws(model, 1);
  NewtonSolver newton(model);
  const StaticStats stats = solve_static(model, state, ws, newton, NewtonSettings{});
  ASSERT_TRUE(stats.converged) << stats.failure;
  for (index_t i : pull.points) EXPECT_EQ(state.u.col(i), pull.displacement);
  compute_internal_forces(model, state.u, ws);
  const std::vector<Vec3> r = support_reactions(model, ws.f_int);
  EXPECT_GT(r[1].x(), 0.0);  // the puller pulls
  EXPECT_NEAR(r[0].x() + r[1].x(), 0.0, 1e-7 * r[1].x());
  // mid-span moves about half-way
  for (index_t i = 0; i < model.n_points; ++i)
    if (std::abs(model.X(0, i) - 4 * spacing) < 1e-9) {
      EXPECT_NEAR(state.u(0, i), 0.5e-3, 0.1e-3);
    }
}

}  // namespace
}  // namespace pointhaptics
