// Tests for solvers/implicit_solver: unconditional stability of backward Euler at dt = 1 ms on the seed's
// 90-point beam from soft to stiff materials, settling on the static solution, and the real-time budget.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/session/scene_builder.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/solvers/implicit_solver.hpp>
#include <pointhaptics/solvers/static_solver.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

#include <fmt/format.h>

namespace pointhaptics {
namespace {

// the seed's beam (scenes/beam_fixed_both_ends.toml): 10 x 3 x 3 points, both ends held, a point load
Model seed_beam(double young, double damping, double load) {
  const std::string text = fmt::format(R"(
[object]
shape = "box"
size = [0.135, 0.03, 0.03]
spacing = 0.015
[material]
young = {}
poisson = 0.4
density = 1000.0
damping = {}
[[fixed]]
box = {{ min = [-1.0, -1.0, -1.0], max = [0.0, 1.0, 1.0] }}
[[fixed]]
box = {{ min = [0.135, -1.0, -1.0], max = [1.0, 1.0, 1.0] }}
[[load]]
kind = "point"
point = 54
force = [0.0, {}, 0.0]
)",
                                       young, damping, load);
  return build_scene_model(parse_scene(text));
}

double total_energy(const Model& model, const State& s) {
  return strain_energy(model, s.u).total() + kinetic_energy(model, s.velocity);
}

class ImplicitStiffness : public ::testing::TestWithParam<double> {};

TEST_P(ImplicitStiffness, FreeVibrationNeverGainsEnergyAtOneMillisecond) {
  const double young = GetParam();
  const Model model = seed_beam(young, 0.0, 0.0);
  ASSERT_EQ(model.n_points, 90);
  State state = State::at_rest(model);
  // a kick of about 1% strain rate per step: v ~ 0.01 * c_p
  const double c_p = std::sqrt((model.lambda + 2 * model.mu) / model.material.density);
  state.velocity = test::random_field(model.n_points, 0.01 * c_p * 1e-1, 31);
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.fixed[i]) state.velocity.col(i).setZero();
  Workspace ws(model, 1);
  NewtonSettings settings;
  settings.tolerance = 1e-9;
  ImplicitSolver solver(model, 1e-3, settings);
  double energy = total_energy(model, state);
  // Newton stops at the model's force floor (1e-9 E L^2, solvers/reactions.hpp): below 1e-15 of the kick's
  // energy (the stiff beams' vibration falls to 1e-30 J within the run) what is left is round-off
  const double resolved = 1e-15 * energy;
  for (int k = 0; k < 200; ++k) {
    const StepReport report = solver.step(model, state, ws, nullptr);
    ASSERT_EQ(report.status, StepStatus::CONVERGED) << "step " << k;
    const double e = total_energy(model, state);
    ASSERT_TRUE(std::isfinite(e));
    // backward Euler dissipates: the energy of a free vibration can only fall
    ASSERT_LE(e, energy * (1 + 1e-6) + resolved) << "step " << k;
    energy = e;
  }
  EXPECT_NEAR(state.time, 0.2, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(YoungsModulus, ImplicitStiffness, ::testing::Values(1e3, 1e4, 1e5, 1e6, 1e7, 1e8),
                         [](const auto& info) { return "E_1e" + std::to_string(std::lround(std::log10(info.param))); });

TEST(ImplicitSolver, DampedBeamSettlesOnTheStaticSolution) {
  for (double young : {1e4, 1e7}) {
    const Model model = seed_beam(young, 50.0, 0.5 * young / 1e5);  // the same strain at every stiffness
    State dynamic = State::at_rest(model), statics = State::at_rest(model);
    Workspace ws(model, 2);
    ImplicitSolver solver(model, 1e-3, NewtonSettings{});
    NewtonSolver newton(model);
    ASSERT_TRUE(solve_static(model, statics, ws, newton, NewtonSettings{}).converged);
    for (int k = 0; k < 1000; ++k) ASSERT_NE(solver.step(model, dynamic, ws, nullptr).status, StepStatus::FAILED);
    EXPECT_LE((dynamic.u - statics.u).norm(), 1e-3 * statics.u.norm()) << "E = " << young;
  }
}

TEST(ImplicitSolver, IterationBudgetKeepsTheStepStable) {
  const Model model = seed_beam(1e8, 20.0, 500.0);
  State state = State::at_rest(model);
  Workspace ws(model, 1);
  NewtonSettings budget;
  budget.max_iterations = 1;
  budget.max_cg_iterations = 20;
  budget.accept_at_budget = true;
  ImplicitSolver solver(model, 1e-3, budget);
  long long cg = 0;
  int at_budget = 0;
  for (int k = 0; k < 300; ++k) {
    const StepReport report = solver.step(model, state, ws, nullptr);
    ASSERT_NE(report.status, StepStatus::FAILED);
    at_budget += report.status == StepStatus::AT_BUDGET;
    cg += report.cg_iterations;
  }
  EXPECT_GT(at_budget, 0);
  EXPECT_LE(cg, 300 * 20);
  EXPECT_TRUE(state.u.allFinite());
  // still heading to the right place: the loaded point moves along the load, not beyond twice the static answer
  State statics = State::at_rest(model);
  NewtonSolver newton(model);
  ASSERT_TRUE(solve_static(model, statics, ws, newton, NewtonSettings{}).converged);
  EXPECT_GT(state.u(1, 54), 0.0);
  EXPECT_LT(state.u(1, 54), 2.0 * statics.u(1, 54));
}

TEST(ImplicitSolver, FailureIsANamedFailureThatKeepsTheState) {
  const Model model = seed_beam(1e5, 0.0, 0.5);
  State state = State::at_rest(model);
  Workspace ws(model, 1);
  NewtonSettings settings;
  settings.max_iterations = 1;
  settings.max_cg_iterations = 1;
  settings.tolerance = 1e-14;
  ImplicitSolver solver(model, 1e-3, settings);
  const StepReport report = solver.step(model, state, ws, nullptr);
  ASSERT_EQ(report.status, StepStatus::FAILED);
  EXPECT_NE(report.failure.find("implicit step at t = 0 s did not converge"), std::string::npos) << report.failure;
  EXPECT_EQ(state.time, 0.0);
  EXPECT_EQ(state.u.norm(), 0.0);
}

}  // namespace
}  // namespace pointhaptics
