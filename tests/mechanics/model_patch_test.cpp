// Tests for mechanics/model_patch: a patch's tangent, its ring held, is the model's tangent restricted to the
// patch's free points (the same products to rounding, after cuts and with the hourglass penalty), and the
// explicit stable step of a patch around a place is no shorter than the whole model's (its modes interlace),
// and is the whole model's when the patch takes in every point.
#include <pointhaptics/mechanics/cut.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>
#include <pointhaptics/mechanics/model_patch.hpp>
#include <pointhaptics/mechanics/tangent.hpp>
#include <pointhaptics/solvers/explicit_solver.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

#include <random>

namespace pointhaptics {
namespace {

Model cut_block() {
  MaterialParams m;
  m.model = MaterialModel::NEO_HOOKEAN;
  m.young = 1e5;
  m.poisson = 0.4;
  m.hourglass = 0.5;
  Model model = build_model(test::jittered_box(8, 5, 5, 0.01, 0.2), m, KernelParams{});
  // a slit from the top into the middle of the block
  const BladeSweep slit{Vec3(0.035, 0.06, -0.01), Vec3(0.035, 0.06, 0.06), Vec3(0.035, 0.02, -0.01),
                        Vec3(0.035, 0.02, 0.06)};
  EXPECT_GT(cut(model, model.X, slit).severed_pairs, 0);
  return model;
}

TEST(ModelPatch, ItsTangentWithTheRingHeldIsTheModelsRestrictedToItsFreePoints) {
  const Model model = cut_block();
  const std::vector<index_t> free = neighbourhood(model, {17, 123}, 1);
  const ModelPatch patch = model_patch(model, free);
  ASSERT_EQ(patch.n_free, static_cast<index_t>(free.size()));
  EXPECT_GT(patch.model.n_points, patch.n_free);
  EXPECT_LT(patch.model.n_points, model.n_points);
  std::mt19937 rng(5);
  std::normal_distribution<double> noise;
  Points du = Points::Zero(3, model.n_points), du_patch = Points::Zero(3, patch.model.n_points);
  for (index_t k = 0; k < patch.n_free; ++k) {
    du_patch.col(k) = Vec3(noise(rng), noise(rng), noise(rng));
    du.col(patch.full_of[static_cast<std::size_t>(k)]) = du_patch.col(k);
  }
  Workspace ws(model, 1), ws_patch(patch.model, 1);
  Tangent K, K_patch;
  K.linearise(model, Points::Zero(3, model.n_points), TangentMode::EXACT, &ws);
  K_patch.linearise(patch.model, Points::Zero(3, patch.model.n_points), TangentMode::EXACT, &ws_patch);
  Points out(3, model.n_points), out_patch(3, patch.model.n_points);
  K.apply(model, du, ws, out);
  K_patch.apply(patch.model, du_patch, ws_patch, out_patch);
  double largest = 0, error = 0;
  for (index_t k = 0; k < patch.n_free; ++k) {
    largest = std::max(largest, out.col(patch.full_of[static_cast<std::size_t>(k)]).norm());
    error = std::max(error, (out.col(patch.full_of[static_cast<std::size_t>(k)]) - out_patch.col(k)).norm());
  }
  EXPECT_GT(largest, 0);
  EXPECT_LT(error, 1e-12 * largest);
  // its pairs: rows sorted, each pair's reverse the model's pair's reverse, the outer ring passive
  const Csr& rows = patch.model.neighbours;
  for (index_t k = 0; k < patch.model.n_points; ++k)
    for (index_t p = rows.begin(k); p < rows.end(k); ++p) {
      if (p + 1 < rows.end(k)) {
        ASSERT_LT(rows.index[p], rows.index[p + 1]);
      }
      const index_t r = patch.model.reverse_pair[static_cast<std::size_t>(p)];
      ASSERT_EQ(rows.index[r], k);
      ASSERT_EQ(patch.model.reverse_pair[static_cast<std::size_t>(r)], p);
    }
  EXPECT_GT(patch.model.n_passive, 0);
  EXPECT_LT(patch.model.n_passive, patch.model.n_points - patch.n_free);
}

TEST(ModelPatch, ALocalStableStepIsNoShorterThanTheWholeModelsAndIsItOverTheWholeModel) {
  const Model model = cut_block();
  const double whole = stable_time_step(model, 0.8, 60);
  // around the slit, where its one-sided stencils are
  std::vector<index_t> slit_points;
  for (index_t e = 0; e < model.n_pairs(); ++e)
    if (model.severed[static_cast<std::size_t>(e)]) slit_points.push_back(model.neighbours.index[e]);
  for (const int rings : {1, 2}) {
    const double local = local_stable_time_step(model, slit_points, rings, 0.8, 40);
    EXPECT_GE(local, 0.999 * whole) << rings;
    std::printf("rings %d: local %.5g s, whole %.5g s\n", rings, local, whole);
  }
  // rings enough to take in the whole block: the whole model's step
  EXPECT_NEAR(local_stable_time_step(model, slit_points, 20, 0.8, 60), whole, 0.01 * whole);
}

}  // namespace
}  // namespace pointhaptics
