// Tests for geometry/remesh: splitting keeps a closed surface closed and its volume exact; a far finer sphere
// is simplified by vertex clustering, closed and within 1.5% of its volume; a simplification that would break
// a part thinner than a cell is refused and the input kept, saying why; a mesh near the asked edge is kept.
#include <pointhaptics/geometry/remesh.hpp>
#include <pointhaptics/geometry/shape_surfaces.hpp>

#include <gtest/gtest.h>

namespace pointhaptics {
namespace {

TEST(Remesh, SplittingKeepsTheSurfaceClosedAndItsVolume) {
  const TriangleMesh box = box_surface(Vec3::Zero(), Vec3(0.04, 0.02, 0.03), 0.02);
  const TriangleMesh finer = subdivide(box);
  EXPECT_EQ(finer.F.size(), 4 * box.F.size());
  EXPECT_NO_THROW(check_closed_manifold(finer, "split box"));
  EXPECT_NEAR(enclosed_volume(finer), enclosed_volume(box), 1e-18);
  EXPECT_NEAR(mean_edge_length(finer), 0.5 * mean_edge_length(box), 1e-15);
  const Remeshed r = adapt_to_edge(box, 0.002);
  EXPECT_LE(mean_edge_length(r.mesh), 2 * 0.002);
  EXPECT_NE(r.change.find("split"), std::string::npos) << r.change;
  EXPECT_NO_THROW(check_closed_manifold(r.mesh, "adapted box"));
}

TEST(Remesh, AFarFinerSphereIsSimplifiedClosedAndFaithful) {
  const TriangleMesh sphere = sphere_surface(Vec3(0.01, 0.0, 0.0), 0.05, 0.001);
  const Remeshed r = adapt_to_edge(sphere, 0.008);
  EXPECT_NE(r.change.find("simplified"), std::string::npos) << r.change;
  EXPECT_LT(r.mesh.F.size(), sphere.F.size() / 20);
  EXPECT_NO_THROW(check_closed_manifold(r.mesh, "simplified sphere"));
  EXPECT_NEAR(enclosed_volume(r.mesh), enclosed_volume(sphere),
              0.015 * enclosed_volume(sphere));  // inscribed at 8 mm: -1%
  EXPECT_GT(mean_edge_length(r.mesh), 0.5 * 0.008);
}

TEST(Remesh, ASimplificationThatWouldBreakAThinPartIsRefused) {
  // a plate 1 mm thick, finely meshed, asked for 8 mm edges: clustering would flatten it to nothing
  const TriangleMesh plate = box_surface(Vec3::Zero(), Vec3(0.05, 0.001, 0.05), 0.0005);
  const Remeshed r = adapt_to_edge(plate, 0.008);
  EXPECT_NE(r.change.find("kept as it is"), std::string::npos) << r.change;
  EXPECT_EQ(r.mesh.F.size(), plate.F.size());
}

TEST(Remesh, AMeshNearTheAskedEdgeIsKept) {
  const TriangleMesh sphere = sphere_surface(Vec3::Zero(), 0.05, 0.005);
  const Remeshed r = adapt_to_edge(sphere, 0.005);
  EXPECT_EQ(r.change, "kept as it is");
  EXPECT_EQ(r.mesh.F.size(), sphere.F.size());
}

}  // namespace
}  // namespace pointhaptics
