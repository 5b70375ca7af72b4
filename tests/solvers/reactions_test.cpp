// Tests for solvers/reactions: at an equilibrium the supports carry the whole load, group by group, and the
// out-of-balance force is relative to the load.
#include <pointhaptics/solvers/reactions.hpp>

#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>
#include <pointhaptics/solvers/static_solver.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

// a block held at both ends (two groups), pulled down by a load at every free point
Model two_supports() {
  Model model = build_model(test::jittered_box(8, 3, 3, 0.01, 0.1), MaterialParams{}, KernelParams{});
  FixedGroup left, right;
  left.name = "left";
  right.name = "right";
  for (index_t i = 0; i < model.n_points; ++i) {
    if (model.X(0, i) < 0.005) left.points.push_back(i);
    else if (model.X(0, i) > 0.065) right.points.push_back(i);
    else model.f_ext.col(i) = Vec3(0, -1e-3, 0);
  }
  for (const FixedGroup* g : {&left, &right})
    for (index_t i : g->points) model.fixed[i] = 1;
  model.fixed_groups = {left, right};
  return model;
}

TEST(Reactions, TheSupportsCarryTheWholeLoadAtEquilibrium) {
  const Model model = two_supports();
  State state = State::at_rest(model);
  Workspace ws(model, 1);
  // at rest nothing is balanced: the residual is the whole load
  compute_internal_forces(model, state.u, ws);
  EXPECT_NEAR(relative_residual(model, ws.f_int), 1.0, 1e-12);
  StaticSolver solver(model, NewtonSettings{});
  ASSERT_EQ(solver.step(model, state, ws, nullptr).status, StepStatus::CONVERGED);
  compute_internal_forces(model, state.u, ws);
  EXPECT_LT(relative_residual(model, ws.f_int), 1e-7);
  const std::vector<Vec3> reactions = support_reactions(model, ws.f_int);
  ASSERT_EQ(reactions.size(), 2u);
  const Vec3 load = model.f_ext.rowwise().sum();
  EXPECT_LE((reactions[0] + reactions[1] + load).norm(), 1e-7 * load.norm());
  // the block is nearly symmetric: each end carries about half
  EXPECT_NEAR(reactions[0].y(), -0.5 * load.y(), 0.1 * std::abs(load.y()));
}

}  // namespace
}  // namespace pointhaptics
