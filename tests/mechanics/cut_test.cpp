// Tests for mechanics/cut.hpp: a blade severs exactly the pairs its swept surface crosses, the cut object's
// forces are the exact gradient of its energy, the incremental refit equals one made in one go, the hourglass
// diagonal stays the exact second difference of the energy, and a cut through makes two pieces.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/mechanics/cut.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>

#include "support/energy_differences.hpp"
#include "support/test_models.hpp"

#include <gtest/gtest.h>

#include <random>

namespace pointhaptics {
namespace {

constexpr double spacing = 0.01;

Model block(double hourglass = 0.5) {
  MaterialParams m;
  m.model = MaterialModel::NEO_HOOKEAN;
  m.young = 1e5;
  m.poisson = 0.4;
  m.hourglass = hourglass;
  return build_model(test::jittered_box(6, 4, 4, spacing, 0.0), m, KernelParams{});
}

/// A blade edge along y at height z = -1 cm swept up to z = 5 cm, in the plane x = `x` (between lattice planes);
/// it reaches y up to `y_end`.
BladeSweep plane_sweep(double x, double y_end) {
  BladeSweep s;
  s.a0 = Vec3(x, -0.01, -0.01);
  s.b0 = Vec3(x, y_end, -0.01);
  s.a1 = Vec3(x, -0.01, 0.05);
  s.b1 = Vec3(x, y_end, 0.05);
  return s;
}

Points forces(const Model& model, const Points& u) {
  Workspace ws(model, 1);
  compute_internal_forces(model, u, ws);
  return ws.f_int;
}

TEST(Cut, ABladeThroughTheObjectSeversExactlyTheCrossingPairsAndMakesTwoPieces) {
  Model model = block();
  const double x_cut = 0.025;
  index_t expected = 0;  // pairs i < j with the points on either side of the plane
  for (index_t i = 0; i < model.n_points; ++i)
    for (index_t e = model.neighbours.begin(i); e < model.neighbours.end(i); ++e) {
      const index_t j = model.neighbours.index[e];
      expected += j > i && (model.X(0, i) < x_cut) != (model.X(0, j) < x_cut);
    }
  ASSERT_GT(expected, 0);
  const std::int64_t regularised_before = model.diagnostics.regularised_neighbourhoods;
  const CutReport report = cut(model, model.X, plane_sweep(x_cut, 0.05));
  EXPECT_EQ(report.severed_pairs, expected);
  EXPECT_EQ(model.diagnostics.severed_pairs, expected);
  for (index_t i = 0; i < model.n_points; ++i)
    for (index_t e = model.neighbours.begin(i); e < model.neighbours.end(i); ++e) {
      const bool across = (model.X(0, i) < x_cut) != (model.X(0, model.neighbours.index[e]) < x_cut);
      ASSERT_EQ(model.severed[e] != 0, across);
      if (across) {
        ASSERT_EQ(model.d.col(e).norm(), 0.0);
        ASSERT_EQ(model.hg_coef[e], 0.0);
      }
    }
  // the stencils next to the cut are one-sided now, but half a neighbourhood still fits a gradient
  EXPECT_EQ(model.diagnostics.regularised_neighbourhoods - regularised_before, report.regularised);
  std::vector<index_t> piece_of;
  EXPECT_EQ(connected_pieces(model, piece_of), 2);
  for (index_t i = 0; i < model.n_points; ++i) EXPECT_EQ(piece_of[i], model.X(0, i) < x_cut ? 0 : 1);
  // a second pass of the same blade finds nothing left to cut
  EXPECT_EQ(cut(model, model.X, plane_sweep(x_cut, 0.05)).severed_pairs, 0);
  // the same cut as triangles (a cut's sheets, levels of detail carry cuts by them): the same pairs, each once
  // (reported as i < j), in the uncut model; none left in the cut one
  const Model uncut = block();
  const BladeSweep s = plane_sweep(x_cut, 0.05);
  const std::array<std::array<Vec3, 3>, 2> sheets{{{s.a0, s.b0, s.b1}, {s.a0, s.b1, s.a1}}};
  const std::vector<index_t> by_sheets = pairs_crossing_triangles(uncut, uncut.X, sheets);
  EXPECT_EQ(static_cast<index_t>(by_sheets.size()), expected);
  for (const index_t e : by_sheets) ASSERT_EQ(model.severed[e], 1);
  EXPECT_TRUE(pairs_crossing_triangles(model, model.X, sheets).empty());
  Model again = block();
  const CutReport listed = sever_pairs(again, by_sheets);
  EXPECT_EQ(static_cast<index_t>(listed.severed.size()), expected);
  for (const auto& [i, j] : listed.severed) ASSERT_LT(i, j);
}

TEST(Cut, AnExplicitSimulationsCutDropsTheHourglassDiagonalAndChangesNothingElse) {
  Model kept = block(), dropped = block();
  const CutReport a = cut(kept, kept.X, plane_sweep(0.025, 0.02));
  const CutReport b = cut(dropped, dropped.X, plane_sweep(0.025, 0.02), false);
  EXPECT_EQ(a.severed_pairs, b.severed_pairs);
  EXPECT_EQ(kept.hg_diagonal.size(), kept.n_points);
  EXPECT_EQ(dropped.hg_diagonal.size(), 0);
  EXPECT_EQ(kept.d, dropped.d);
  EXPECT_EQ(kept.d_self, dropped.d_self);
  EXPECT_EQ(kept.hg_coef, dropped.hg_coef);
  // a later cut of the dropped one does not bring it back half-made
  cut(dropped, dropped.X, plane_sweep(0.035, 0.05));
  EXPECT_EQ(dropped.hg_diagonal.size(), 0);
}

TEST(Cut, APartialSlitKeepsOnePieceAndCutsOnlyWhereTheBladeWent) {
  Model model = block();
  const CutReport report = cut(model, model.X, plane_sweep(0.025, 0.015));  // y from -1 to 1.5 cm of 0..3 cm
  EXPECT_GT(report.severed_pairs, 0);
  std::vector<index_t> piece_of;
  EXPECT_EQ(connected_pieces(model, piece_of), 1);
  for (index_t i = 0; i < model.n_points; ++i)
    for (index_t e = model.neighbours.begin(i); e < model.neighbours.end(i); ++e)
      if (model.severed[e]) {
        const index_t j = model.neighbours.index[e];
        // the crossing point lies in the swept rectangle: at y <= 1.5 cm
        const double t = (0.025 - model.X(0, i)) / (model.X(0, j) - model.X(0, i));
        EXPECT_LE(model.X(1, i) + t * (model.X(1, j) - model.X(1, i)), 0.015 + 1e-12);
      }
}

TEST(Cut, ForcesAfterCutsAreTheExactGradientOfTheCutObjectsEnergy) {
  Model model = block();
  cut(model, model.X, plane_sweep(0.025, 0.015));
  BladeSweep oblique;  // a second, slanted blade
  oblique.a0 = Vec3(-0.01, 0.012, -0.01);
  oblique.b0 = Vec3(0.06, 0.022, -0.01);
  oblique.a1 = Vec3(-0.01, 0.012, 0.025);
  oblique.b1 = Vec3(0.06, 0.022, 0.025);
  EXPECT_GT(cut(model, model.X, oblique).severed_pairs, 0);
  for (double scale : {0.02, 0.2}) {
    const Points u = test::random_field(model.n_points, scale * spacing, 17);
    const Points f = forces(model, u);
    ASSERT_TRUE(f.allFinite());
    const Points f_fd = test::forces_by_differences(model, u, 1e-5 * scale * spacing);
    EXPECT_LT((f - f_fd).norm() / f.norm(), 1e-6) << "displacement scale " << scale << " x spacing";
  }
}

TEST(Cut, CuttingInStepsEqualsCuttingAtOnceAndKeepsTheHourglassDiagonalExact) {
  Model at_once = block(), in_steps = block();
  const std::vector<index_t> pairs = pairs_crossing(at_once, at_once.X, plane_sweep(0.025, 0.05));
  sever_pairs(at_once, pairs);
  const std::size_t half = pairs.size() / 2;
  sever_pairs(in_steps, {pairs.begin(), pairs.begin() + static_cast<std::ptrdiff_t>(half)});
  sever_pairs(in_steps, {pairs.begin() + static_cast<std::ptrdiff_t>(half), pairs.end()});
  EXPECT_LT((at_once.d - in_steps.d).norm(), 1e-12 * at_once.d.norm());
  EXPECT_LT((at_once.d_self - in_steps.d_self).norm(), 1e-12 * at_once.d_self.norm());
  EXPECT_LT((at_once.hg_coef - in_steps.hg_coef).norm(), 1e-12 * at_once.hg_coef.norm());
  EXPECT_LT((at_once.hg_diagonal - in_steps.hg_diagonal).norm(), 1e-9 * at_once.hg_diagonal.norm());
  EXPECT_EQ(at_once.diagnostics.regularised_neighbourhoods, in_steps.diagnostics.regularised_neighbourhoods);
  // the hourglass energy is quadratic: its second difference along one coordinate is the diagonal's entry
  const double h = 1e-4;
  for (const index_t m : {index_t{0}, index_t{14}, index_t{33}, index_t{50}, at_once.n_points - 1})
    for (int a = 0; a < 3; ++a) {
      Points u = Points::Zero(3, at_once.n_points);
      u(a, m) = h;
      const double plus = strain_energy(at_once, u).hourglass;
      u(a, m) = -h;
      const double minus = strain_energy(at_once, u).hourglass;
      EXPECT_NEAR((plus + minus) / (h * h), at_once.hg_diagonal[m], 1e-9 * at_once.hg_diagonal[m]) << "point " << m;
    }
}

TEST(Cut, AThousandRandomCutsNeverMakeNaNNorGrowTheModel) {
  Model model = block();
  const index_t pairs_before = model.n_pairs();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> where(-0.005, 0.055);
  index_t severed = 0;
  for (int k = 0; k < 1000; ++k) {
    BladeSweep s;
    s.a0 = Vec3(where(rng), where(rng), where(rng));
    s.b0 = Vec3(where(rng), where(rng), where(rng));
    s.a1 = s.a0 + 0.01 * Vec3(where(rng), where(rng), where(rng)) / 0.055;
    s.b1 = s.b0 + 0.01 * Vec3(where(rng), where(rng), where(rng)) / 0.055;
    severed += cut(model, model.X, s).severed_pairs;
  }
  EXPECT_GT(severed, 0);
  EXPECT_EQ(model.n_pairs(), pairs_before);
  EXPECT_EQ(model.severed.size(), static_cast<std::size_t>(pairs_before));
  EXPECT_EQ(model.diagnostics.severed_pairs, severed);
  EXPECT_TRUE(model.d.allFinite());
  EXPECT_TRUE(model.hg_coef.allFinite());
  EXPECT_TRUE(forces(model, test::random_field(model.n_points, 0.1 * spacing)).allFinite());
  EXPECT_THROW(sever_pairs(model, {model.n_pairs()}), Error);
  EXPECT_THROW(sever_pairs(model, {-1}), Error);
}

}  // namespace
}  // namespace pointhaptics
