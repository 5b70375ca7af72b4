// Tests for lod/active_set: the whole selection is the full model, mass and load are kept, absorbed
// points follow exactly for affine fields, sparse points get enough neighbours, held points stay held,
// and a static solve on the active set agrees with the full model near the contact.
#include <pointhaptics/lod/active_set.hpp>
#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/mechanics/tangent.hpp>
#include <pointhaptics/solvers/static_solver.hpp>

#include "support/test_models.hpp"

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

const double s = 0.005;

// a 0.1 x 0.03 x 0.03 m bar (21 x 7 x 7 points), clamped at x = 0
Model bar() {
  Model m = build_model(test::jittered_box(21, 7, 7, s, 0.0), MaterialParams{}, KernelParams{});
  FixedGroup clamp;
  clamp.name = "clamp";
  for (index_t i = 0; i < m.n_points; ++i)
    if (m.X(0, i) < 1e-9) {
      m.fixed[i] = 1;
      clamp.points.push_back(i);
    }
  m.fixed_groups.push_back(clamp);
  return m;
}

Selection select(const Model& m, const Vec3& c, const LodParams& p) {
  std::mt19937_64 rng(p.seed);
  return select_points(m, c, p, rng);
}

LodParams levels() {
  LodParams p;
  p.levels = {{3.0, 6}, {5.0, 8}};
  return p;
}

TEST(ActiveSet, SelectingEverythingGivesTheFullModel) {
  const Model full = bar();
  LodParams p;
  p.k1 = p.k2 = 100.0;
  const ActiveSet a = build_active_set(full, select(full, full.X.col(0), p));
  ASSERT_EQ(a.model.n_points, full.n_points);
  EXPECT_EQ(a.widened, 0);
  const Points u = test::random_field(full.n_points, 0.01 * s, 3);
  Workspace wf(full, 1), wa(a.model, 1);
  compute_internal_forces(full, u, wf);
  compute_internal_forces(a.model, u, wa);
  EXPECT_LE((wf.f_int - wa.f_int).norm(), 1e-10 * wf.f_int.norm());
}

TEST(ActiveSet, KeepsMassAndLoadAndGivesSparsePointsEnoughNeighbours) {
  Model full = bar();
  full.f_ext.row(1).setConstant(-1e-3);  // a load on every point
  const Vec3 c(0.1, 0.03, 0.015);
  const Selection sel = select(full, c, levels());
  LodParams params;
  const ActiveSet a = build_active_set(full, sel, params);
  EXPECT_LT(a.n_selected, full.n_points);
  double mass_bands = 0, mass_active = 0, load_bands = 0, load_active = 0;
  for (index_t i = 0; i < full.n_points; ++i)
    if (sel.band[i] >= 0 || (a.active_of[i] >= 0 && a.active_of[i] < a.n_selected)) {
      mass_bands += full.mass[i];
      load_bands += full.f_ext(1, i);
    }
  for (index_t k = 0; k < a.n_selected; ++k) {
    mass_active += a.model.mass[k];
    load_active += a.model.f_ext(1, k);
  }
  EXPECT_NEAR(mass_active, mass_bands, 1e-12 * mass_bands);
  EXPECT_NEAR(load_active, load_bands, 1e-12 * std::abs(load_bands));
  for (index_t k = 0; k < a.n_selected; ++k) {
    const bool enough = a.model.neighbours.row_size(k) >=
                        std::min<index_t>(params.min_neighbours, full.neighbours.row_size(a.full_of[k]));
    const bool at_limit = a.model.support[k] >= params.max_widening * full.h * (1 - 1e-12);
    EXPECT_TRUE(enough || at_limit) << "active point " << k;
  }
  EXPECT_GT(a.widened, 0);
  // the frozen ring and the clamp are held
  for (index_t k = a.n_selected; k < a.model.n_points; ++k) EXPECT_TRUE(a.model.fixed[k]);
  for (index_t k = 0; k < a.n_selected; ++k) EXPECT_EQ(a.model.fixed[k] != 0, full.fixed[a.full_of[k]] != 0);
}

TEST(ActiveSet, ThePassiveOuterRingOnlyCompletesNeighbourhoodsAndForcesStayExact) {
  const Model full = bar();
  LodParams p;
  p.levels = {{3.0, 4}};
  const ActiveSet a = build_active_set(full, select(full, Vec3(0.06, 0.03, 0.015), p));
  const Model& m = a.model;
  ASSERT_GT(m.n_passive, 0);
  // passive points are held, last, and no simulated point has one as a neighbour
  for (index_t k = m.stencil_end(); k < m.n_points; ++k) {
    EXPECT_TRUE(m.fixed[k]);
    for (index_t e = m.neighbours.begin(k); e < m.neighbours.end(k); ++e)
      EXPECT_GE(m.neighbours.index[e], a.n_selected);
  }
  // the forces on the simulated points are still the exact gradient of the energy, and the tangent the
  // exact derivative of the forces, on 1 and 2 threads
  const Points u = test::random_field(m.n_points, 0.05 * s, 5);
  Workspace w1(m, 1), w2(m, 2);
  compute_internal_forces(m, u, w1);
  compute_internal_forces(m, u, w2);
  EXPECT_LE((w1.f_int - w2.f_int).norm(), 1e-12 * w1.f_int.norm());
  const double eps = 1e-7 * s;
  for (index_t k : {index_t{0}, a.n_selected / 2, a.n_selected - 2, a.n_selected - 1})
    for (int c = 0; c < 3; ++c) {
      Points up = u, down = u;
      up(c, k) += eps;
      down(c, k) -= eps;
      const double dE = (strain_energy(m, up).total() - strain_energy(m, down).total()) / (2 * eps);
      EXPECT_NEAR(-dE, w1.f_int(c, k), 1e-6 * w1.f_int.cwiseAbs().maxCoeff()) << "point " << k << " axis " << c;
    }
  Tangent K;
  K.linearise(m, u, TangentMode::EXACT);
  Points v = test::random_field(m.n_points, 1.0, 9);
  v.rightCols(m.n_points - a.n_selected).setZero();  // held points do not move
  Points Kv(3, m.n_points);
  K.apply(m, v, w1, Kv);
  Points up = u + eps * v, down = u - eps * v;
  compute_internal_forces(m, up, w1);
  const Points f_up = w1.f_int;
  compute_internal_forces(m, down, w1);
  const Points fd = -(f_up - w1.f_int) / (2 * eps);
  const auto free_rows = [&](const Points& P) { return P.leftCols(a.n_selected); };
  EXPECT_LE((free_rows(Kv) - free_rows(fd)).norm(), 1e-5 * free_rows(fd).norm());
}

TEST(ActiveSet, AbsorbedPointsFollowAffineFieldsExactly) {
  const Model full = bar();
  const ActiveSet a = build_active_set(full, select(full, Vec3(0.05, 0.03, 0.015), levels()));
  Mat3 A;
  A << 0.01, 0.002, -0.003, 0.0, -0.02, 0.004, 0.005, 0.001, 0.01;
  State f = State::at_rest(full);
  f.u = A * full.X;
  State active = a.restrict_state(f);
  State back = State::at_rest(full);
  a.prolong_state(active, back);
  for (index_t j = 0; j < full.n_points; ++j)
    if (a.followed.row_size(j) > 0 || (a.active_of[j] >= 0 && a.active_of[j] < a.n_selected)) {
      ASSERT_LE((back.u.col(j) - f.u.col(j)).norm(), 1e-12) << "point " << j;
    }
}

TEST(ActiveSet, NeighbouringAbsorbedPointsMoveTogether) {
  // a slow real-time run with levels of detail diverged (docs/lod.md): each absorbed point followed its
  // nearest selected point alone, so neighbours that followed two different ones moved apart as far as the
  // two points' gradients differed; with the dynamics' ringing a neighbourhood of followers came out
  // inverted, and started inverted (its stress without bound) when a later selection simulated it
  const Model full = bar();
  const ActiveSet a = build_active_set(full, select(full, Vec3(0.05, 0.03, 0.015), levels()));
  // the selected points ringing about a bend: displacements of a tenth of the spacing about it
  State object = State::at_rest(full);
  for (index_t j = 0; j < full.n_points; ++j) object.u.col(j) = Vec3(0.0, -2.0 * std::pow(full.X(0, j), 2), 0.0);
  State active = a.restrict_state(object);
  active.u.leftCols(a.n_selected) += test::random_field(a.n_selected, 0.1 * s, 5);
  a.prolong_state(active, object);
  // the worst neighbourhood, det(I + G), among the simulated points and among the absorbed ones (over their
  // own neighbours in the object)
  double simulated = 1, absorbed = 1;
  for (index_t k = 0; k < a.n_selected; ++k)
    simulated = std::min(simulated, (Mat3::Identity() + displacement_gradient(a.model, active.u, k)).determinant());
  index_t n_absorbed = 0;
  for (index_t j = 0; j < full.stencil_end(); ++j) {
    if (a.followed.row_size(j) == 0) continue;
    ++n_absorbed;
    absorbed = std::min(absorbed, (Mat3::Identity() + displacement_gradient(full, object.u, j)).determinant());
  }
  std::printf("worst neighbourhood, det(I + G): %.3f simulated, %.3f over %d absorbed points\n", simulated, absorbed,
              n_absorbed);
  ASSERT_GT(n_absorbed, 100);
  // measured: 0.542 simulated, 0.461 absorbed; each following its nearest alone: 0.123
  EXPECT_GT(absorbed, 0.75 * simulated);
}

TEST(ActiveSet, PointsNoLongerSimulatedStayWhereTheyWereAndAtRest) {
  // issue 21: a point kept the velocity it had when it left the active set, and a later selection that
  // took it in again brought that velocity back (energy from nowhere)
  const Model full = bar();
  const ActiveSet a = build_active_set(full, select(full, Vec3(0.09, 0.03, 0.015), levels()));
  State f = State::at_rest(full);
  f.u.setConstant(0.001);
  f.velocity.setConstant(0.5);
  const State active = a.restrict_state(f);
  a.prolong_state(active, f);
  index_t unsimulated = 0;
  for (index_t j = 0; j < full.n_points; ++j) {
    if (a.followed.row_size(j) > 0 || a.active_of[j] >= 0) continue;
    ++unsimulated;
    ASSERT_EQ(f.velocity.col(j).norm(), 0.0) << "point " << j;
    ASSERT_EQ(f.u.col(j), Vec3::Constant(0.001)) << "point " << j;
  }
  EXPECT_GT(unsimulated, 0);
}

TEST(ActiveSet, AViscoelasticHistoryGoesWithItsPoints) {
  // issue 17: a simulated point's Prony history comes back to it on the object, and goes to it in the next
  // active set; the rest keep theirs
  Model full = bar();
  full.material.prony = {{0.3, 0.1}};
  const ActiveSet a = build_active_set(full, select(full, Vec3(0.05, 0.03, 0.015), levels()));
  ASSERT_EQ(a.model.material.prony.size(), 1u);
  State f = State::at_rest(full);
  ASSERT_EQ(f.viscous.rows(), 12);
  for (index_t j = 0; j < full.n_points; ++j) f.viscous.col(j).setConstant(static_cast<double>(j));
  State active = a.restrict_state(f);
  ASSERT_EQ(active.viscous.cols(), a.model.n_points);
  for (index_t k = 0; k < a.model.n_points; ++k) ASSERT_EQ(active.viscous(5, k), static_cast<double>(a.full_of[k]));
  active.viscous *= 2;  // the active set's steps changed it
  a.prolong_state(active, f);
  for (index_t j = 0; j < full.n_points; ++j) {
    const bool simulated = a.active_of[j] >= 0;
    ASSERT_EQ(f.viscous(7, j), (simulated ? 2.0 : 1.0) * static_cast<double>(j)) << "point " << j;
  }
}

TEST(ActiveSet, StaticSolveAgreesWithTheFullModelNearTheContact) {
  Model full = bar();
  // a point load at the free end's top edge, the contact
  index_t loaded = 0;
  for (index_t i = 0; i < full.n_points; ++i)
    if ((full.X.col(i) - Vec3(0.1, 0.03, 0.015)).norm() < 1e-9) loaded = i;
  full.f_ext(1, loaded) = -0.02;
  State reference = State::at_rest(full);
  {
    Workspace ws(full, 1);
    NewtonSolver newton(full);
    ASSERT_TRUE(solve_static(full, reference, ws, newton, NewtonSettings{}).converged);
  }
  LodParams p;
  p.k1 = 6.0;  // the free half of the bar fully selected,
  p.k2 = 7.0;
  p.levels = {{20.0, 2}};  // the clamped half at selection weight 0.8
  const Selection sel = select(full, full.X.col(loaded), p);
  const ActiveSet a = build_active_set(full, sel);
  State active = a.restrict_state(State::at_rest(full));
  Workspace ws(a.model, 1);
  NewtonSolver newton(a.model);
  ASSERT_TRUE(solve_static(a.model, active, ws, newton, NewtonSettings{}).converged);
  State lod = State::at_rest(full);
  a.prolong_state(active, lod);
  // displacement error inside T_r1 against the full model
  double err = 0, ref = 0;
  for (index_t i = 0; i < full.n_points; ++i)
    if (sel.band[i] == 0) {
      err = std::max(err, (lod.u.col(i) - reference.u.col(i)).norm());
      ref = std::max(ref, reference.u.col(i).norm());
    }
  RecordProperty("lod_error_inside_tr1", std::to_string(err / ref));
  std::printf("active set: %d of %d points selected (%d widened), max displacement error inside T_r1: %.2f%%\n",
              a.n_selected, full.n_points, a.widened, 100 * err / ref);
  // measured: 13% with the seed's random thinning at weight 0.8 where the bar carries its largest bending
  // moment (11-14% for 8-20 neighbours; 60-90% at weight 0.4): the seed's scheme costs accuracy wherever
  // the coarse region carries load. A guard against regressions, not the goal of issue 5.
  EXPECT_LT(err, 0.2 * ref);
}

}  // namespace
}  // namespace pointhaptics
