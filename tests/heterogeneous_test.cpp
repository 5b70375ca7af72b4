// Heterogeneous objects (issue 17, item 4): per-point materials from [[region]] tables. A soft block with a
// stiff spherical inclusion, pressed from above over the inclusion and beside it: the force difference the
// hand should feel, against CalculiX with the same inclusion (its elements whose centres lie in the ball).
#include <pointhaptics/fem/calculix.hpp>
#include <pointhaptics/pointhaptics.hpp>

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

// a 40 x 30 x 40 mm block (E = 1e4 Pa, nu = 0.4), bottom held; a ball of radius 6 mm, ten times stiffer, 12.5 mm
// below the top at x = 10 mm; a square 7.5 mm punch pressed 0.3 mm at x = 10 mm (over it) or x = 30 mm (beside)
const Vec3 size(0.04, 0.03, 0.04), inclusion_centre(0.01, 0.0175, 0.02);
// (centre and radius chosen so that the ball holds as many points, 57, as CalculiX elements, 56: the same volume)
const double inclusion_radius = 0.006, punch_half = 0.00375, depth = 3e-4, spacing = 0.0025;

Aabb punch_box(double x) {
  return {Vec3(x - punch_half, size.y(), size.z() / 2 - punch_half),
          Vec3(x + punch_half, 1, size.z() / 2 + punch_half)};
}

double point_force(double x, bool with_inclusion) {
  Scene s;
  s.path = "inclusion";
  s.object.size = size;
  s.object.spacing = spacing;
  s.material.young = 1e4;
  s.material.poisson = 0.4;
  FixedSpec bottom;
  bottom.box = {Vec3(-1, -1, -1), Vec3(1, 0, 1)};
  s.fixed.push_back(bottom);
  FixedSpec punch;
  punch.box = punch_box(x);
  punch.displacement = Vec3(0, -depth, 0);
  s.fixed.push_back(punch);
  if (with_inclusion) {
    RegionSpec nodule;
    nodule.sphere = SphereRegion{inclusion_centre, inclusion_radius};
    nodule.young = 1e5;
    s.regions.push_back(nodule);
  }
  s.solver.kind = SolverKind::STATIC;
  Simulation sim(build_scene_model(s), s.solver, 2);
  sim.run(0);
  const RunSummary r = sim.summary();
  EXPECT_TRUE(r.converged) << r.failure;
  return -r.reactions[1].y();
}

double fem_force(double x, bool with_inclusion) {
  fem::BoxProblem p;
  p.size = size;
  p.nx = 16, p.ny = 12, p.nz = 16;  // 2.5 mm elements
  p.young = 1e4;
  p.poisson = 0.4;
  p.clamps.push_back({Vec3(-1, -1, -1), Vec3(1, 0, 1)});
  const Aabb b = punch_box(x);
  fem::Prescribed punch;
  punch.region = {b.min, b.max};
  punch.displacement = Vec3(0, -depth, 0);
  p.prescribed.push_back(punch);
  if (with_inclusion) {
    MaterialParams stiff;
    stiff.young = 1e5;
    stiff.poisson = 0.4;
    p.inclusions.push_back({inclusion_centre, inclusion_radius, stiff});
  }
  const fem::Solution sol = fem::solve(p, 2);
  EXPECT_EQ(sol.reactions.size(), 1u);
  return -sol.reactions[0].back().force.y();
}

TEST(Heterogeneous, AStiffInclusionIsFeltAsCalculixFeelsIt) {
  const double over = point_force(0.01, true), beside = point_force(0.03, true), plain = point_force(0.01, false);
  const double fem_over = fem_force(0.01, true), fem_beside = fem_force(0.03, true), fem_plain = fem_force(0.01, false);
  // the punch's footprint is a lattice staircase on both sides, so the forces are compared relative to the same
  // punch on the block without the inclusion: how much stiffer the nodule makes the press
  const double contrast = over / plain, fem_contrast = fem_over / fem_plain;
  const double side = beside / plain, fem_side = fem_beside / fem_plain;
  RecordProperty("contrast", std::to_string(contrast));
  RecordProperty("fem_contrast", std::to_string(fem_contrast));
  EXPECT_GT(contrast, 1.1);  // the nodule is felt (1.21 here; CalculiX 1.17)
  EXPECT_NEAR(contrast, fem_contrast, 0.05 * fem_contrast)
      << "over " << over << " N, plain " << plain << " N; CalculiX " << fem_over << " N, " << fem_plain << " N";
  EXPECT_NEAR(side, fem_side, 0.05 * fem_side) << "beside " << beside << " N; CalculiX " << fem_beside << " N";
  // and the plain block's force itself, footprint and all
  EXPECT_NEAR(plain, fem_plain, 0.25 * fem_plain);
}

}  // namespace
}  // namespace pointhaptics
