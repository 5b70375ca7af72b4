// Tests for cut_surface: a block's surface split by a cut all the way through gains the two faces of the cut
// (twice the section's area), stays closed (its enclosed volume is the block's), and each side's vertices are
// carried by that side's points only, so pulling the pieces apart moves each side rigidly and opens the gap
// (the unsplit surface spans it); a slit gains faces of twice its area carried by the points on their side;
// no sheet, or one outside the object, changes nothing; random sheets give a finite surface whose rows sum to 1.
#include <pointhaptics/surface/cut_surface.hpp>
#include <pointhaptics/geometry/shape_surfaces.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/mechanics/cut.hpp>
#include <pointhaptics/session/scene_builder.hpp>

#include <gtest/gtest.h>

#include <limits>
#include <random>

namespace pointhaptics {
namespace {

struct Block {
  Scene scene;
  Model model;
  ObjectSurface whole;
  Vec3 lo, hi;
};

Block block() {
  Block b;
  b.scene = parse_scene(
      "[object]\nshape = \"box\"\nsize = [0.06, 0.03, 0.03]\nspacing = 0.005\n[material]\nyoung = 1e5\npoisson = 0.3\n");
  b.model = build_scene_model(b.scene);
  b.whole = build_object_surface(b.scene, b.model);
  b.lo = b.whole.mesh.V.rowwise().minCoeff();
  b.hi = b.whole.mesh.V.rowwise().maxCoeff();
  return b;
}

/// The sweep of an edge along y (beyond the block's width) in the plane x = x_cut, from z = z_from down to z_to.
BladeSweep plane(const Block& b, double x_cut, double z_from, double z_to) {
  const double y0 = b.lo.y() - 0.01, y1 = b.hi.y() + 0.01;
  return BladeSweep{Vec3(x_cut, y0, z_from), Vec3(x_cut, y1, z_from), Vec3(x_cut, y0, z_to), Vec3(x_cut, y1, z_to)};
}

std::vector<SheetTriangle> sheets_of(const BladeSweep& s) {
  return {SheetTriangle{s.a0, s.b0, s.b1}, SheetTriangle{s.a0, s.b1, s.a1}};
}

double cut_face_area(const ObjectSurface& s) {
  double area = 0;
  for (std::size_t t = s.mesh.F.size() - static_cast<std::size_t>(s.cut_faces); t < s.mesh.F.size(); ++t) {
    const auto& f = s.mesh.F[t];
    area += 0.5 * (s.mesh.V.col(f[1]) - s.mesh.V.col(f[0])).cross(s.mesh.V.col(f[2]) - s.mesh.V.col(f[0])).norm();
  }
  return area;
}

TEST(CutSurface, ACutThroughGainsTwoFacesStaysClosedAndEachSideFollowsItsOwnPoints) {
  Block b = block();
  const double x_cut = b.lo.x() + 0.0262;  // between lattice planes
  const BladeSweep sweep = plane(b, x_cut, b.hi.z() + 0.01, b.lo.z() - 0.01);
  ASSERT_GT(cut(b.model, b.model.X, sweep).severed_pairs, 0);
  const std::vector<SheetTriangle> sheets = sheets_of(sweep);
  const ObjectSurface split = split_surface(b.whole, b.model, sheets);

  const double section = (b.hi.y() - b.lo.y()) * (b.hi.z() - b.lo.z());
  EXPECT_GT(split.cut_faces, 0);
  // (the grid the faces are cut into clips the section's corners by a chord: 0.4% here)
  EXPECT_NEAR(cut_face_area(split), 2 * section, 0.01 * section);
  const double volume = (b.hi - b.lo).prod();
  EXPECT_NEAR(enclosed_volume(split.mesh), volume, 1e-9 * volume);
  EXPECT_EQ(split.map.n_vertices(), split.mesh.V.cols());
  EXPECT_EQ(split.source.find("dropped"), std::string::npos) << split.source;

  // the pieces pulled 5 mm apart: every vertex moves with its own side, rigidly
  const double d = 0.005;
  Points u(3, b.model.n_points);
  for (index_t j = 0; j < b.model.n_points; ++j) u.col(j) = Vec3((b.model.X(0, j) > x_cut ? d : -d), 0, 0);
  const Points y = deformed_surface(split, u);
  double worst = 0;
  for (Eigen::Index v = 0; v < y.cols(); ++v) {
    const Vec3 moved = y.col(v) - split.mesh.V.col(v);
    worst = std::max(worst, std::min((moved - Vec3(d, 0, 0)).norm(), (moved + Vec3(d, 0, 0)).norm()));
  }
  EXPECT_LT(worst, 1e-9);
  // closed and apart: the two pieces' volumes, nothing spanning the gap
  EXPECT_NEAR(enclosed_volume(TriangleMesh{y, split.mesh.F}), volume, 1e-3 * volume);
  // the uncut surface's vertices near the cut mix both sides: it stretches across the gap
  const Points y_whole = deformed_surface(b.whole, u);
  EXPECT_GT(enclosed_volume(TriangleMesh{y_whole, b.whole.mesh.F}), volume + 0.5 * 2 * d * section);
}

TEST(CutSurface, ASlitGainsFacesOfTwiceItsAreaCarriedByThePointsOnTheirSide) {
  Block b = block();
  const double x_cut = b.lo.x() + 0.0262, depth = 0.5 * (b.hi.z() - b.lo.z());
  const BladeSweep sweep = plane(b, x_cut, b.hi.z() + 0.01, b.hi.z() - depth);
  ASSERT_GT(cut(b.model, b.model.X, sweep).severed_pairs, 0);
  const ObjectSurface split = split_surface(b.whole, b.model, sheets_of(sweep));
  const double slit = (b.hi.y() - b.lo.y()) * depth;
  EXPECT_NEAR(cut_face_area(split), 2 * slit, 0.01 * 2 * slit);
  const double volume = (b.hi - b.lo).prod();
  EXPECT_NEAR(enclosed_volume(split.mesh), volume, 1e-9 * volume);
  // a cut face looks away from its material: its vertices see no point in front of it but below the slit's
  // bottom, where the material is whole
  const double bottom = b.hi.z() - depth;
  int faces = 0;
  for (std::size_t t = split.mesh.F.size() - static_cast<std::size_t>(split.cut_faces); t < split.mesh.F.size();
       ++t, ++faces) {
    const auto& f = split.mesh.F[t];
    const Vec3 normal =
        (split.mesh.V.col(f[1]) - split.mesh.V.col(f[0])).cross(split.mesh.V.col(f[2]) - split.mesh.V.col(f[0]));
    ASSERT_GT(std::abs(normal.normalized().x()), 1 - 1e-9);
    for (const index_t v : f)
      for (index_t e = split.map.points.begin(v); e < split.map.points.end(v); ++e)
        if (normal.dot(b.model.X.col(split.map.points.index[e]) - split.mesh.V.col(v)) > 0) {
          ASSERT_LT(b.model.X(2, split.map.points.index[e]), bottom) << "face " << t;
        }
  }
  EXPECT_GT(faces, 10);
  // and the surface's own vertices beside the slit see no point across it
  for (Eigen::Index v = 0; v < b.whole.mesh.V.cols(); ++v) {
    const Vec3 Y = split.mesh.V.col(v);
    if (Y.z() < bottom) continue;
    for (index_t e = split.map.points.begin(static_cast<index_t>(v)); e < split.map.points.end(static_cast<index_t>(v));
         ++e) {
      const Vec3 X = b.model.X.col(split.map.points.index[e]);
      if ((Y.x() - x_cut) * (X.x() - x_cut) < 0) {
        ASSERT_LT(X.z(), bottom) << v;
      }
    }
  }
}

TEST(CutSurface, NoSheetOrOneOutsideTheObjectChangesNothing) {
  const Block b = block();
  const ObjectSurface same = split_surface(b.whole, b.model, {});
  EXPECT_EQ(same.mesh.F, b.whole.mesh.F);
  EXPECT_EQ(same.cut_faces, 0);
  const BladeSweep away = plane(b, b.hi.x() + 0.02, b.hi.z() + 0.01, b.lo.z() - 0.01);
  const ObjectSurface outside = split_surface(b.whole, b.model, sheets_of(away));
  EXPECT_EQ(outside.mesh.F, b.whole.mesh.F);
  EXPECT_EQ(outside.cut_faces, 0);
}

TEST(CutSurface, ASheetThatIsNotFiniteSplitsNothing) {
  const Block b = block();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<SheetTriangle> bad{SheetTriangle{Vec3(nan, 0, 0), Vec3(0.01, 0, 0), Vec3(0, 0.01, 0)}};
  const ObjectSurface same = split_surface(b.whole, b.model, bad);
  EXPECT_EQ(same.mesh.F, b.whole.mesh.F);
  EXPECT_TRUE(same.mesh.V.allFinite());
}

TEST(CutSurface, RandomSheetsGiveAFiniteSurfaceCarriedByWeightsThatSumToOne) {
  Block b = block();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-0.2, 1.2);
  std::vector<SheetTriangle> sheets;
  for (int k = 0; k < 40; ++k) {
    SheetTriangle t;
    for (Vec3& p : t) p = b.lo + Vec3(unit(rng), unit(rng), unit(rng)).cwiseProduct(b.hi - b.lo);
    sheets.push_back(t);
    BladeSweep s{t[0], t[1], t[0], t[2]};
    cut(b.model, b.model.X, s);
  }
  const ObjectSurface split = split_surface(b.whole, b.model, sheets);
  EXPECT_TRUE(split.mesh.V.allFinite());
  EXPECT_GT(split.cut_faces, 0);
  for (index_t v = 0; v < split.map.n_vertices(); ++v) {
    double sum = 0;
    for (index_t e = split.map.points.begin(v); e < split.map.points.end(v); ++e) sum += split.map.weight[e];
    if (split.map.points.end(v) > split.map.points.begin(v)) {
      ASSERT_NEAR(sum, 1.0, 1e-8) << v;
    }
  }
  for (const auto& f : split.mesh.F)
    for (const index_t v : f)
      ASSERT_GT(split.map.points.end(v), split.map.points.begin(v)) << "a drawn vertex without points";
  const Points y = deformed_surface(split, Points::Constant(3, b.model.n_points, 0.001));
  EXPECT_TRUE(y.allFinite());
  EXPECT_NEAR((y - split.mesh.V).cwiseAbs().maxCoeff(), 0.001, 1e-9);  // a translation is carried exactly
}

}  // namespace
}  // namespace pointhaptics
