// Tests for solvers/sparse_cholesky and Newton's Cholesky preconditioner: the factor solves the assembled
// tangent over the free points, refuses a matrix that is not positive definite, and as a preconditioner it
// gives the block-Jacobi solution with far fewer CG iterations, lagging across implicit steps. The same for the
// two-level preconditioner (solvers/coarse_correction.hpp), whose coarse level is such a factor.
#include <pointhaptics/mechanics/tangent.hpp>
#include <pointhaptics/scene_builder.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/solvers/coarse_correction.hpp>
#include <pointhaptics/solvers/implicit_solver.hpp>
#include <pointhaptics/solvers/sparse_cholesky.hpp>
#include <pointhaptics/solvers/static_solver.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

#include <fmt/format.h>

namespace pointhaptics {
namespace {

// the seed's cantilever at 7.5 mm (scenes/cantilever_static.toml): 525 points, clamped at x = 0, a tip traction
Model cantilever(double young, double spacing = 0.0075) {
  const std::string text = fmt::format(R"(
[object]
shape = "box"
size = [0.15, 0.03, 0.03]
spacing = {}
[material]
young = {}
poisson = 0.4
density = 1000.0
damping = 20.0
[[fixed]]
box = {{ min = [-1.0, -1.0, -1.0], max = [0.0, 1.0, 1.0] }}
[[load]]
kind = "traction"
box = {{ min = [0.15, -1.0, -1.0], max = [1.0, 1.0, 1.0] }}
total = [0.0, -0.3, 0.0]
)",
                                       spacing, young);
  return build_scene_model(parse_scene(text));
}

TangentMatrix tangent_at_rest(const Model& model) {
  Tangent tangent;
  tangent.linearise(model, Points::Zero(3, model.n_points), TangentMode::PROJECTED);
  TangentMatrix K;
  assemble_tangent(model, tangent, K);
  return K;
}

TEST(SparseCholesky, SolvesTheAssembledTangentOverTheFreePoints) {
  const Model model = cantilever(1e5, 0.015);
  const TangentMatrix K = tangent_at_rest(model);
  SparseCholesky chol;
  EXPECT_FALSE(chol.analysed_for(model));
  chol.analyse(model, K);
  ASSERT_TRUE(chol.analysed_for(model));
  ASSERT_TRUE(chol.factorise(K));
  EXPECT_GT(chol.stats().factor_nonzeros, 0);
  EXPECT_GT(chol.stats().factor_bytes, 0);
  const Points r = test::random_field(model.n_points, 1.0, 5);
  Points z(3, model.n_points);
  chol.solve(r, z);
  // K z = r on the free points (z is zero at the held ones, so their columns of K do not enter)
  Points Kz;
  multiply(K, z, Kz);
  double error = 0, scale = 0;
  for (index_t i = 0; i < model.n_points; ++i) {
    if (model.fixed[i]) {
      EXPECT_EQ(z.col(i).norm(), 0.0);
      continue;
    }
    error = std::max(error, (Kz.col(i) - r.col(i)).norm());
    scale = std::max(scale, r.col(i).norm());
  }
  EXPECT_LT(error, 1e-9 * scale);
}

TEST(SparseCholesky, AModelChangedInPlaceIsAnalysedAgain) {
  Model model = cantilever(1e5, 0.015);
  const TangentMatrix K = tangent_at_rest(model);
  SparseCholesky chol;
  chol.analyse(model, K);
  ASSERT_TRUE(chol.analysed_for(model));
  index_t free = 0;
  while (model.fixed[free]) ++free;
  model.fixed[free] = 1;  // one more held point: other free dofs, another ordering
  EXPECT_FALSE(chol.analysed_for(model));
  const Model other = cantilever(1e5, 0.015);
  EXPECT_FALSE(chol.analysed_for(other));
}

TEST(SparseCholesky, RefusesAMatrixThatIsNotPositiveDefinite) {
  const Model model = cantilever(1e5, 0.015);
  TangentMatrix K = tangent_at_rest(model);
  SparseCholesky chol;
  chol.analyse(model, K);
  ASSERT_TRUE(chol.factorise(K));
  // flip the sign of one free point's diagonal block
  index_t free = 0;
  while (model.fixed[free]) ++free;
  Eigen::Map<Mat3>(K.values.data() + 9 * static_cast<std::size_t>(K.diagonal[free])) *= -1.0;
  EXPECT_FALSE(chol.factorise(K));
  EXPECT_FALSE(chol.factorised());
  // and recovers when the matrix is good again
  Eigen::Map<Mat3>(K.values.data() + 9 * static_cast<std::size_t>(K.diagonal[free])) *= -1.0;
  EXPECT_TRUE(chol.factorise(K));
}

// the static equilibrium with block-Jacobi (k = 0) and with `other` (k = 1): their stats and displacements
void solve_both(const Model& model, Preconditioner other, StaticStats (&stats)[2], Points (&u)[2]) {
  NewtonSettings settings;
  for (int k = 0; k < 2; ++k) {
    settings.preconditioner = k == 0 ? Preconditioner::BLOCK_JACOBI : other;
    State state = State::at_rest(model);
    Workspace ws(model, 2);
    NewtonSolver newton(model);
    stats[k] = solve_static(model, state, ws, newton, settings);
    ASSERT_TRUE(stats[k].converged) << stats[k].failure;
    u[k] = state.u;
  }
}

TEST(CholeskyPreconditioner, GivesTheBlockJacobiEquilibriumInFarFewerIterations) {
  const Model model = cantilever(1e5);
  StaticStats stats[2];
  Points u[2];
  solve_both(model, Preconditioner::CHOLESKY, stats, u);
  EXPECT_EQ(stats[0].factorisations, 0);
  EXPECT_GE(stats[1].factorisations, 1);
  EXPECT_LT((u[1] - u[0]).norm(), 1e-6 * u[0].norm());
  EXPECT_LT(3 * stats[1].cg_iterations, stats[0].cg_iterations);
}

// 50 implicit steps of 1 ms of the cantilever at E = 1e8 Pa (about 75x the explicit stable step, where
// block-Jacobi CG needs ~20 iterations a step) with block-Jacobi (k = 0) and `other` (k = 1): the CG
// iterations, the factorisations of `other` and the displacements
void step_both(Preconditioner other, long long (&cg)[2], long long& factorisations, Points (&u)[2]) {
  const Model model = cantilever(1e8);
  factorisations = 0;
  for (int k = 0; k < 2; ++k) {
    cg[k] = 0;
    NewtonSettings settings;
    settings.tolerance = 1e-6;
    settings.preconditioner = k == 0 ? Preconditioner::BLOCK_JACOBI : other;
    ImplicitSolver solver(model, 1e-3, settings);
    State state = State::at_rest(model);
    Workspace ws(model, 2);
    for (int step = 0; step < 50; ++step) {
      const StepReport report = solver.step(model, state, ws, nullptr);
      ASSERT_EQ(report.status, StepStatus::CONVERGED) << report.failure;
      cg[k] += report.cg_iterations;
      if (k == 1) factorisations += report.factorisations;
      if (k == 1 && other == Preconditioner::CHOLESKY) {
        EXPECT_GT(report.factor_bytes, 0);
      }
    }
    u[k] = state.u;
  }
}

TEST(CholeskyPreconditioner, LagsAcrossStiffImplicitSteps) {
  Points u[2];
  long long cg[2], factorisations;
  step_both(Preconditioner::CHOLESKY, cg, factorisations, u);
  EXPECT_LE(factorisations, 3) << "the factor is reused across steps";
  EXPECT_LT(4 * cg[1], cg[0]);
  EXPECT_LT((u[1] - u[0]).norm(), 1e-4 * u[0].norm());
}

TEST(CoarseCorrection, KeepsAboutTheTargetNumberOfPointsSpreadOverTheObject) {
  const Model model = cantilever(1e5, 0.005);  // 31 x 7 x 7 points
  const std::vector<index_t> coarse = CoarseCorrection::coarse_points(model);
  const double ratio = CoarseCorrection::coarsening(model);
  EXPECT_GE(ratio, 2.0);
  EXPECT_GT(coarse.size(), CoarseCorrection::target_coarse_points / 4);
  EXPECT_LT(coarse.size(), 4 * CoarseCorrection::target_coarse_points);
  EXPECT_TRUE(std::is_sorted(coarse.begin(), coarse.end()));
  EXPECT_EQ(std::adjacent_find(coarse.begin(), coarse.end()), coarse.end());
  // every fine point has a coarse one within a coarse cell's diagonal, and the clamped face has coarse points
  double farthest = 0;
  for (index_t i = 0; i < model.n_points; ++i) {
    double nearest = 1e300;
    for (index_t c : coarse) nearest = std::min(nearest, (model.X.col(i) - model.X.col(c)).norm());
    farthest = std::max(farthest, nearest);
  }
  EXPECT_LE(farthest, std::sqrt(3.0) * ratio * model.spacing);
  EXPECT_TRUE(std::any_of(coarse.begin(), coarse.end(), [&](index_t c) { return model.fixed[c] != 0; }));
}

TEST(TwoLevelPreconditioner, GivesTheBlockJacobiEquilibriumInFarFewerIterations) {
  // CG's slow modes on the cantilever are its bending: block-Jacobi needs ~350 iterations at 5 mm, the
  // coarse level about 85 (and their number hardly grows under refinement, docs/performance.md)
  const Model model = cantilever(1e5, 0.005);
  StaticStats stats[2];
  Points u[2];
  solve_both(model, Preconditioner::TWO_LEVEL, stats, u);
  EXPECT_EQ(stats[1].factorisations, 0) << "the coarse factor is not the fine tangent's";
  EXPECT_LT((u[1] - u[0]).norm(), 1e-6 * u[0].norm());
  EXPECT_LT(3 * stats[1].cg_iterations, stats[0].cg_iterations);
}

TEST(TwoLevelPreconditioner, CutsTheIterationsOfStiffImplicitSteps) {
  Points u[2];
  long long cg[2], factorisations;
  step_both(Preconditioner::TWO_LEVEL, cg, factorisations, u);
  EXPECT_LT(3 * cg[1], cg[0]);
  EXPECT_LT((u[1] - u[0]).norm(), 1e-4 * u[0].norm());
}

}  // namespace
}  // namespace pointhaptics
