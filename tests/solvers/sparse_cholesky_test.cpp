// Tests for solvers/sparse_cholesky and Newton's Cholesky preconditioner: the factor solves the assembled
// tangent over the free points, refuses a matrix that is not positive definite, and as a preconditioner it
// gives the block-Jacobi solution with far fewer CG iterations, lagging across implicit steps. The same for the
// two-level preconditioner (solvers/coarse_correction.hpp), whose coarse level is such a factor.
#include <pointhaptics/core/run_control.hpp>
#include <pointhaptics/mechanics/tangent.hpp>
#include <pointhaptics/session/scene_builder.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/solvers/coarse_correction.hpp>
#include <pointhaptics/solvers/implicit_solver.hpp>
#include <pointhaptics/solvers/sparse_cholesky.hpp>
#include <pointhaptics/solvers/static_solver.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <future>
#include <thread>

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

// CHOLMOD cannot be interrupted: a long analysis or factorisation runs on a thread of its own, which a stop
// leaves behind (core/stoppable_call.hpp). The factor is then unanalysed, and analysed again on demand.
TEST(SparseCholesky, AStopRequestEndsALongAnalysisOrFactorisationAndLeavesItUnanalysed) {
  struct ClearStop {
    ~ClearStop() { clear_stop_request(); }
  } clear;
  const Model model = cantilever(1e5, 0.004);  // 2432 points, 3 GFlop a factorisation: CHOLMOD runs apart
  const TangentMatrix K = tangent_at_rest(model);
  SparseCholesky chol;
  request_stop();
  EXPECT_THROW(chol.analyse(model, K), Interrupted);
  EXPECT_FALSE(chol.analysed_for(model));
  clear_stop_request();
  chol.analyse(model, K);
  ASSERT_TRUE(chol.factorise(K));
  const double factorise_s = chol.stats().factorise_s;
  ASSERT_GT(chol.stats().factorisation_flops, 1e9);
  // a stop requested a tenth of the way into a factorisation is honoured long before its end
  using Clock = std::chrono::steady_clock;
  const auto delay = std::chrono::duration<double>(factorise_s / 10);
  const auto start = Clock::now();
  std::thread stopper([delay] {
    std::this_thread::sleep_for(delay);
    request_stop();
  });
  EXPECT_THROW(chol.factorise(K), Interrupted);
  const double honoured_s = std::chrono::duration<double>(Clock::now() - start).count();
  stopper.join();
  EXPECT_LT(honoured_s, factorise_s / 2) << "a full factorisation takes " << factorise_s << " s";
  EXPECT_FALSE(chol.factorised());
  EXPECT_FALSE(chol.analysed_for(model));
  clear_stop_request();
  // and it serves again as before
  chol.analyse(model, K);
  ASSERT_TRUE(chol.factorise(K));
  const Points b = Points::Random(3, model.n_points);
  Points x(3, model.n_points);
  chol.solve(b, x);
  EXPECT_TRUE(x.allFinite());
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

// |K z - r| over the free points, relative to |r|
double solve_error(const Model& model, const TangentMatrix& K, const Points& r, const Points& z) {
  Points Kz;
  multiply(K, z, Kz);
  double error = 0, scale = 0;
  for (index_t i = 0; i < model.n_points; ++i) {
    if (model.fixed[i]) continue;
    error = std::max(error, (Kz.col(i) - r.col(i)).norm());
    scale = std::max(scale, r.col(i).norm());
  }
  return error / scale;
}

// A worker held back until the test lets it go (at the end at the latest, and never more than a minute: the
// factor's destructor joins the worker).
struct Gate {
  std::promise<void> open;
  std::shared_future<void> opened = open.get_future().share();
  bool is_open = false;
  std::shared_ptr<std::atomic<bool>> timed_out = std::make_shared<std::atomic<bool>>(false);
  std::function<void()> hold() {
    return [f = opened, t = timed_out] {
      if (f.wait_for(std::chrono::minutes(1)) == std::future_status::timeout) *t = true;
    };
  }
  void release() {
    if (!is_open) open.set_value();
    is_open = true;
  }
  ~Gate() { release(); }
};

TEST(SparseCholesky, FactorisesInTheBackgroundWhileTheOldFactorServes) {
  const Model model = cantilever(1e5, 0.015);
  const TangentMatrix K1 = tangent_at_rest(model);
  TangentMatrix K2 = K1;
  // another positive definite matrix of the same pattern: K1 plus a mass-like diagonal
  for (index_t i = 0; i < model.n_points; ++i)
    Eigen::Map<Mat3>(K2.values.data() + 9 * static_cast<std::size_t>(K2.diagonal[i])).diagonal().array() += 1e3;
  Gate gate;
  SparseCholesky chol;
  chol.before_background_factorisation = gate.hold();
  chol.analyse(model, K1);
  ASSERT_TRUE(chol.factorise(K1));
  const Points r = test::random_field(model.n_points, 1.0, 7);
  Points z(3, model.n_points), z1(3, model.n_points);
  chol.solve(r, z1);
  ASSERT_LT(solve_error(model, K1, r, z1), 1e-9);
  EXPECT_FALSE(chol.background_pending());
  EXPECT_FALSE(chol.take_background()) << "nothing pending";

  ASSERT_TRUE(chol.factorise_in_background(K2));
  EXPECT_GT(chol.stats().background_bytes, 0.5 * chol.stats().factor_bytes) << "the worker's own copy of L";
  EXPECT_TRUE(chol.background_pending());
  EXPECT_FALSE(chol.background_ready()) << "held back by the test";
  EXPECT_FALSE(chol.factorise_in_background(K2)) << "one background factorisation at a time";
  // the old factor serves meanwhile, unchanged
  chol.solve(r, z);
  EXPECT_EQ((z - z1).norm(), 0.0);
  EXPECT_TRUE(chol.factorised());

  gate.release();
  ASSERT_TRUE(chol.take_background());  // waits for the worker
  EXPECT_FALSE(chol.background_pending());
  chol.solve(r, z);
  EXPECT_LT(solve_error(model, K2, r, z), 1e-9) << "the new factor is in use";
  EXPECT_GT(solve_error(model, K1, r, z), 1e-6);
  EXPECT_EQ(chol.stats().factorisations, 2);
  EXPECT_EQ(chol.stats().background_factorisations, 1);

  // a matrix that is not positive definite: refused, and the factor in use is kept
  TangentMatrix bad = K1;
  index_t free = 0;
  while (model.fixed[free]) ++free;
  Eigen::Map<Mat3>(bad.values.data() + 9 * static_cast<std::size_t>(bad.diagonal[free])) *= -1.0;
  ASSERT_TRUE(chol.factorise_in_background(bad));
  EXPECT_FALSE(chol.take_background());
  Points z_after(3, model.n_points);
  chol.solve(r, z_after);
  EXPECT_EQ((z_after - z).norm(), 0.0);
  EXPECT_EQ(chol.stats().background_factorisations, 1);

  // and again (the worker refactorises the factor it swapped out): K1's own solution
  ASSERT_TRUE(chol.factorise_in_background(K1));
  ASSERT_TRUE(chol.take_background());
  chol.solve(r, z);
  EXPECT_LT((z - z1).norm(), 1e-12 * z1.norm());

  // a new analysis drops a background factorisation that was not taken up
  ASSERT_TRUE(chol.factorise_in_background(K2));
  chol.analyse(model, K1);
  EXPECT_FALSE(chol.background_pending());
  EXPECT_EQ(chol.stats().background_bytes, 0.0);
}

// `steps` implicit steps of 1 ms of the cantilever at E = 1e8 Pa pushed by a tip load that turns (so the tangent
// keeps changing), refactorised after any CG solve of more than one iteration (many refactorisations):
// where it runs, and the state reached
struct RefactorRun {
  long long cg = 0, factorisations = 0, background = 0;
  Points u;
};
RefactorRun turning_load(int steps, Refactorisation where, bool real_time,
                         const std::function<void(int, ImplicitSolver&)>& before_step = {}) {
  Model model = cantilever(1e8);
  const Points load = model.f_ext;
  NewtonSettings settings;
  settings.tolerance = 1e-6;
  settings.preconditioner = Preconditioner::CHOLESKY;
  settings.refactor_iterations = 1;
  settings.refactorisation = where;
  settings.real_time = real_time;
  ImplicitSolver solver(model, 1e-3, settings);
  State state = State::at_rest(model);
  Workspace ws(model, 1);  // one thread: the worker is the only other (and TSan sees no TBB)
  RefactorRun run;
  for (int step = 0; step < steps; ++step) {
    const double angle = 0.05 * step;  // the tip load turns in the x-y plane, ten times larger
    for (index_t i = 0; i < model.n_points; ++i)
      model.f_ext.col(i) = 10.0 * Vec3(-std::sin(angle) * load(1, i), std::cos(angle) * load(1, i), 0.0);
    if (before_step) before_step(step, solver);
    const StepReport report = solver.step(model, state, ws, nullptr);
    EXPECT_EQ(report.status, StepStatus::CONVERGED) << report.failure;
    if (report.status != StepStatus::CONVERGED) break;
    run.cg += report.cg_iterations;
    run.factorisations += report.factorisations;
    run.background += report.background_factorisations;
  }
  run.u = state.u;
  return run;
}

TEST(CholeskyPreconditioner, RefactorisesInTheBackgroundReproducibly) {
  const RefactorRun in_place = turning_load(40, Refactorisation::IN_PLACE, false);
  const RefactorRun background = turning_load(40, Refactorisation::BACKGROUND, false);
  const RefactorRun again = turning_load(40, Refactorisation::BACKGROUND, false);
  ASSERT_GT(in_place.factorisations, 5) << "the test needs refactorisations";
  EXPECT_EQ(in_place.background, 0);
  // the first factor is made in place, the rest in the background, each taken up at the next step's start
  EXPECT_GT(background.background, 5);
  EXPECT_EQ(background.background, background.factorisations - 1);
  EXPECT_LT((background.u - in_place.u).norm(), 1e-4 * in_place.u.norm());
  // an older factor for the rest of a step costs some CG iterations, not many
  EXPECT_LT(background.cg, 3 * in_place.cg);
  // taken up at the same points whatever the worker's speed: the same run twice
  EXPECT_EQ(again.cg, background.cg);
  EXPECT_EQ(again.factorisations, background.factorisations);
  EXPECT_EQ((again.u - background.u).norm(), 0.0);
  // "auto" outside real time: in place
  const RefactorRun automatic = turning_load(40, Refactorisation::AUTO, false);
  EXPECT_EQ(automatic.background, 0);
  EXPECT_EQ(automatic.cg, in_place.cg);
}

TEST(CholeskyPreconditioner, AutomaticallyInTheBackgroundOnlyInRealTimeWithACoreToSpare) {
  NewtonSettings settings;
  settings.preconditioner = Preconditioner::CHOLESKY;
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  EXPECT_FALSE(settings.refactor_in_background(1)) << "auto: not outside real time";
  settings.real_time = true;
  EXPECT_FALSE(settings.refactor_in_background(cores)) << "auto: no core of its own";
  EXPECT_FALSE(settings.refactor_in_background(cores - 1)) << "auto: the haptic loop has the last one";
  EXPECT_EQ(settings.refactor_in_background(std::max(1, cores - 2)), cores >= 3) << "one simulation thread at least";
  settings.refactorisation = Refactorisation::BACKGROUND;
  EXPECT_TRUE(settings.refactor_in_background(cores));
  settings.real_time = false;
  EXPECT_TRUE(settings.refactor_in_background(cores)) << "asked for: also outside real time (reproducibly)";
  settings.refactorisation = Refactorisation::IN_PLACE;
  settings.real_time = true;
  EXPECT_FALSE(settings.refactor_in_background(1));
  settings.refactorisation = Refactorisation::BACKGROUND;
  settings.preconditioner = Preconditioner::TWO_LEVEL;
  EXPECT_FALSE(settings.refactor_in_background(1)) << "only the Cholesky preconditioner refactorises";
}

TEST(CholeskyPreconditioner, InRealTimeStepsGoOnWhileTheWorkerFactorises) {
  Gate gate;
  int held_steps = 0, started_at = -1;
  const RefactorRun run = turning_load(40, Refactorisation::BACKGROUND, true, [&](int step, ImplicitSolver& solver) {
    SparseCholesky& chol = solver.newton().cholesky();
    if (step == 0) chol.before_background_factorisation = gate.hold();
    if (chol.background_pending() && started_at < 0) started_at = step;
    // the worker is held for 20 steps after it got its first job: every one of them is stepped with the
    // factor there was
    if (started_at >= 0 && step < started_at + 20) {
      EXPECT_FALSE(chol.background_ready());
      ++held_steps;
    }
    if (started_at >= 0 && step == started_at + 20) {
      gate.release();
      // let it finish, then the next Newton iteration takes it up
      for (int k = 0; k < 10000 && !chol.background_ready(); ++k)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      EXPECT_TRUE(chol.background_ready());
    }
  });
  EXPECT_GE(started_at, 0) << "a refactorisation was asked for";
  EXPECT_EQ(held_steps, 20);
  EXPECT_GE(run.background, 1) << "taken up once released";
  EXPECT_FALSE(*gate.timed_out) << "the worker was released by the test, not by its time-out";
  const RefactorRun in_place = turning_load(40, Refactorisation::IN_PLACE, false);
  EXPECT_LT((run.u - in_place.u).norm(), 1e-4 * in_place.u.norm());
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
