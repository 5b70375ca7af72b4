// Tests for object_surface and io/mesh_file's writer: every shape of a scene gets its closed surface at the
// asked edge length, carried by the model's points; a mesh file keeps its own surface, split toward the asked
// edge; a point cloud gets
// one reconstructed; surfaces written as STL, PLY and OBJ read back closed and unchanged (to single
// precision); the deformed surface follows the points; a sampled sphere's reconstruction lies within a
// fraction of a spacing of the sphere.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/remesh.hpp>
#include <pointhaptics/geometry/sampling.hpp>
#include <pointhaptics/geometry/shape_surfaces.hpp>
#include <pointhaptics/io/mesh_file.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>
#include <pointhaptics/surface/object_surface.hpp>
#include <pointhaptics/session/scene_builder.hpp>

#include "support/test_scenes.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace pointhaptics {
namespace {

std::string temp(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("ph_surface_" + name)).string();
}

TEST(ObjectSurface, EveryShapeGetsItsClosedSurfaceAtTheAskedEdge) {
  const std::string material = "\n[material]\nyoung = 1e5\npoisson = 0.3\n";
  for (const std::string object : {"shape = \"box\"\nsize = [0.06, 0.03, 0.03]\nspacing = 0.0075",
                                   "shape = \"sphere\"\nradius = 0.03\nspacing = 0.0075\nsurface_edge = 0.005",
                                   "shape = \"half_sphere\"\nradius = 0.03\nspacing = 0.0075"}) {
    const Scene scene = parse_scene("[object]\n" + object + material);
    const Model model = build_scene_model(scene);
    const ObjectSurface surface = build_object_surface(scene, model);
    EXPECT_NO_THROW(check_closed_manifold(surface.mesh, object));
    EXPECT_GT(enclosed_volume(surface.mesh), 0) << object;
    const double asked = scene.object.surface_edge > 0 ? scene.object.surface_edge : 0.5 * scene.object.spacing;
    EXPECT_GT(mean_edge_length(surface.mesh), 0.6 * asked) << object;
    EXPECT_LT(mean_edge_length(surface.mesh), 1.3 * asked) << object;
    EXPECT_EQ(surface.map.n_vertices(), surface.mesh.V.cols());
    EXPECT_FALSE(surface.source.empty());
    // at rest the surface is its reference
    EXPECT_EQ((deformed_surface(surface, Points::Zero(3, model.n_points)) - surface.mesh.V).norm(), 0.0);
  }
}

TEST(ObjectSurface, AMeshFileIsBroughtToTheAskedEdgeAndAPointCloudGetsOneReconstructed) {
  const std::string mesh_path = temp("cube.stl");
  write_mesh(mesh_path, box_surface(Vec3::Zero(), Vec3(0.04, 0.04, 0.04), 0.02), "test");
  const Scene scene = parse_scene("[object]\nshape = \"file\"\nfile = \"" + mesh_path + "\"\nspacing = 0.008\n");
  const ObjectSurface surface = build_object_surface(scene, build_scene_model(scene));
  // the file's 48 triangles (edges of about 23 mm) split twice toward the 4 mm asked
  EXPECT_EQ(surface.mesh.F.size(), 48u * 16);
  EXPECT_NE(surface.source.find("split 2 times"), std::string::npos) << surface.source;
  EXPECT_NEAR(enclosed_volume(surface.mesh), 0.04 * 0.04 * 0.04,
              1e-6 * 0.04 * 0.04 * 0.04);  // the STL's single precision

  const std::string cloud_path = temp("cloud.xyz");
  {
    std::ofstream cloud(cloud_path);
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        for (int k = 0; k < 4; ++k) cloud << 0.01 * i << ' ' << 0.01 * j << ' ' << 0.01 * k << '\n';
  }
  const Scene cloud_scene = parse_scene("[object]\nshape = \"file\"\nfile = \"" + cloud_path + "\"\nspacing = 0.01\n");
  const ObjectSurface reconstructed = build_object_surface(cloud_scene, build_scene_model(cloud_scene));
  EXPECT_NO_THROW(check_closed_manifold(reconstructed.mesh, "cloud"));
  EXPECT_NE(reconstructed.source.find("reconstructed"), std::string::npos) << reconstructed.source;
}

/// Distances of the surface's vertices to the sphere (centre c, radius R): RMS and largest.
std::pair<double, double> distances_to_sphere(const TriangleMesh& mesh, const Vec3& c, double R) {
  double sum = 0, worst = 0;
  for (Eigen::Index v = 0; v < mesh.V.cols(); ++v) {
    const double d = std::abs((mesh.V.col(v) - c).norm() - R);
    sum += d * d;
    worst = std::max(worst, d);
  }
  return {std::sqrt(sum / static_cast<double>(mesh.V.cols())), worst};
}

TEST(ReconstructSurface, ASampledSphereComesBackCloseToTheSphereAtTwoSpacings) {
  // the sphere's points as a cloud would give them (lattice points, cell volumes): the half level of their
  // kernel density against the true sphere, in spacings (docs/surface.md quotes these)
  const Vec3 c(0.01, 0.0, -0.02);
  const double R = 0.04;
  for (double spacing : {0.008, 0.004}) {
    const Model model = build_model(sample_sphere(c, R, spacing), MaterialParams{}, KernelParams{});
    const TriangleMesh mesh = reconstruct_surface(model, 0.5 * spacing);
    EXPECT_NO_THROW(check_closed_manifold(mesh, "reconstructed sphere"));
    EXPECT_GT(enclosed_volume(mesh), 0);
    const auto [rms, worst] = distances_to_sphere(mesh, c, R);
    std::printf("reconstructed sphere, spacing %.3g m: RMS %.3f, max %.3f spacings from the sphere\n", spacing,
                rms / spacing, worst / spacing);
    EXPECT_LT(rms, 0.25 * spacing) << spacing;
    EXPECT_LT(worst, 0.5 * spacing) << spacing;
  }
  EXPECT_THROW(reconstruct_surface(build_model(sample_sphere(c, R, 0.008), MaterialParams{}, KernelParams{}), 1e-6),
               Error);
}

TEST(WriteMesh, StlPlyAndObjReadBackClosedAndUnchanged) {
  const TriangleMesh sphere = sphere_surface(Vec3(0.01, 0.02, -0.03), 0.05, 0.01);
  for (const std::string ext : {".stl", ".ply", ".obj", ".STL"}) {
    const std::string path = temp("sphere" + ext);
    write_mesh(path, sphere, "test");
    const TriangleMesh back = read_mesh(path);
    EXPECT_NO_THROW(check_closed_manifold(back, path));
    ASSERT_EQ(back.F.size(), sphere.F.size()) << ext;
    ASSERT_EQ(back.V.cols(), sphere.V.cols()) << ext;
    EXPECT_NEAR(enclosed_volume(back), enclosed_volume(sphere), 1e-6 * enclosed_volume(sphere)) << ext;
  }
  EXPECT_THROW(write_mesh(temp("sphere.xyz"), sphere, "--surface"), Error);
  EXPECT_THROW(write_mesh("/no/such/folder/s.stl", sphere, "--surface"), Error);
}

TEST(ObjectSurface, FollowsTheBentCantilever) {
  // the cantilever solved statically: its surface's lowest vertex sits where its lowest point does
  const Scene scene = parse_scene(test::cantilever_scene("static"));
  const Model model = build_scene_model(scene);
  const ObjectSurface surface = build_object_surface(scene, model);
  Points u(3, model.n_points);
  // the bending of a cantilever, affine in each cross-section: u_y = -c x^2 (3 L - x), u_x = c' y x (2 L - x)
  // (a smooth field, not affine: the surface follows it to the MLS interpolation error)
  const double L = 0.15, c = 0.002 / (2 * L * L * L);
  for (index_t i = 0; i < model.n_points; ++i) {
    const double x = model.X(0, i), y = model.X(1, i) - 0.015;
    u.col(i) = Vec3(-3 * c * y * x * (2 * L - x), -c * x * x * (3 * L - x), 0);
  }
  const Points y = deformed_surface(surface, u);
  double worst = 0;
  for (Eigen::Index v = 0; v < y.cols(); ++v) {
    const double x = surface.mesh.V(0, v), yy = surface.mesh.V(1, v) - 0.015;
    const Vec3 exact = surface.mesh.V.col(v) + Vec3(-3 * c * yy * x * (2 * L - x), -c * x * x * (3 * L - x), 0);
    worst = std::max(worst, (y.col(v) - exact).norm());
  }
  EXPECT_LT(worst, 0.01 * 0.002);  // 1% of the tip deflection
}

}  // namespace
}  // namespace pointhaptics
