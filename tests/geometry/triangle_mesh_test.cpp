// Tests for geometry/triangle_mesh and io/mesh_file: winding numbers, volume sampling of closed meshes,
// named errors for open, non-manifold and badly oriented ones, and OBJ, STL and PLY files through assimp
// into a scene.
#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/triangle_mesh.hpp>
#include <pointhaptics/io/mesh_file.hpp>
#include <pointhaptics/pointhaptics.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

namespace pointhaptics {
namespace {

// an axis-aligned box, outward-oriented
TriangleMesh box(const Vec3& lo, const Vec3& hi) {
  TriangleMesh m;
  m.V.resize(3, 8);
  for (int c = 0; c < 8; ++c)
    m.V.col(c) = Vec3(c & 1 ? hi.x() : lo.x(), c & 2 ? hi.y() : lo.y(), c & 4 ? hi.z() : lo.z());
  m.F = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
         {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

// an icosphere (3 subdivisions: 1280 triangles)
TriangleMesh sphere(double r) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3> v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<index_t, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                           {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                           {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                           {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < 3; ++level) {
    std::map<std::pair<index_t, index_t>, index_t> mid;
    auto middle = [&](index_t a, index_t b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back(0.5 * (v[a] + v[b]));
      return mid[key] = static_cast<index_t>(v.size() - 1);
    };
    std::vector<std::array<index_t, 3>> next;
    for (const auto& tri : f) {
      const index_t a = middle(tri[0], tri[1]), b = middle(tri[1], tri[2]), c = middle(tri[2], tri[0]);
      next.insert(next.end(), {{tri[0], a, c}, {tri[1], b, a}, {tri[2], c, b}, {a, b, c}});
    }
    f = next;
  }
  TriangleMesh m;
  m.V.resize(3, static_cast<Eigen::Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) m.V.col(static_cast<Eigen::Index>(i)) = r * v[i].normalized();
  m.F = f;
  return m;
}

std::string error_of(const TriangleMesh& m) {
  try {
    check_closed_manifold(m, "mesh.obj");
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

std::string error_of_sampling(const TriangleMesh& m) {
  try {
    sample_mesh_volume(m, 0.01, "mesh.obj");
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

TEST(TriangleMesh, WindingNumberIsOneInsideAndZeroOutside) {
  const TriangleMesh b = box(Vec3::Zero(), Vec3(0.1, 0.05, 0.02));
  EXPECT_NEAR(winding_number(b, Vec3(0.05, 0.025, 0.01)), 1.0, 1e-12);
  EXPECT_NEAR(winding_number(b, Vec3(0.0999, 0.0001, 0.0199)), 1.0, 1e-9);
  EXPECT_NEAR(winding_number(b, Vec3(0.2, 0.025, 0.01)), 0.0, 1e-12);
  EXPECT_NEAR(winding_number(b, Vec3(-1, 3, 2)), 0.0, 1e-12);
  const TriangleMesh s = sphere(0.03);
  EXPECT_NEAR(winding_number(s, Vec3(0.01, 0.0, 0.005)), 1.0, 1e-9);
  EXPECT_NEAR(winding_number(s, Vec3(0.031, 0.0, 0.0)), 0.0, 1e-3);
}

TEST(TriangleMesh, ClosedMeshesAreVolumeSampled) {
  // a box: exactly its lattice
  const PointCloud b = sample_mesh_volume(box(Vec3::Zero(), Vec3(0.1, 0.05, 0.02)), 0.01, "box");
  EXPECT_EQ(b.size(), 10 * 5 * 2);
  EXPECT_NEAR(b.volume.sum(), 0.1 * 0.05 * 0.02, 1e-12);
  // a sphere: the inscribed polyhedron's volume within a few percent
  const PointCloud s = sample_mesh_volume(sphere(0.03), 0.002, "sphere");
  const double exact = 4.0 / 3.0 * std::numbers::pi * std::pow(0.03, 3);
  EXPECT_NEAR(s.volume.sum(), exact, 0.03 * exact);
  for (index_t i = 0; i < s.size(); ++i) ASSERT_LT(s.X.col(i).norm(), 0.03);
}

// issue 52: a mesh's points stand for the volume it encloses, at any spacing and position, the points at cell
// centres; single-precision vertices (as mesh files have) put no centre on a face
TEST(TriangleMesh, SampledVolumesSumToTheEnclosedVolumeAtAnySpacing) {
  for (const double side : {0.05, 0.2})
    for (const double spacing : {0.01, 0.007, 0.013}) {
      TriangleMesh cube = box(Vec3::Zero(), Vec3::Constant(side));
      cube.V = cube.V.cast<float>().cast<double>();
      const PointCloud c = sample_mesh_volume(cube, spacing, "cube");
      EXPECT_NEAR(c.volume.sum(), side * side * side, 5e-3 * side * side * side) << side << " m at " << spacing;
      for (index_t i = 0; i < c.size(); ++i)
        ASSERT_TRUE((c.X.col(i).array() > 0).all() && (c.X.col(i).array() < side).all()) << c.X.col(i).transpose();
      // a whole number of cells: the points are the cells' centres, each a full cell
      if (std::abs(side / spacing - std::round(side / spacing)) < 1e-9) {
        EXPECT_EQ(c.size(), std::lround(std::pow(side / spacing, 3)));
        EXPECT_NEAR(c.volume.minCoeff(), std::pow(spacing, 3), 1e-6 * std::pow(spacing, 3));  // float vertices
      }
    }
  // off the lattice: a sphere's polyhedron, whose cells on the surface are partly inside
  const TriangleMesh ball = sphere(0.03);
  for (const double spacing : {0.004, 0.006}) {
    const PointCloud s = sample_mesh_volume(ball, spacing, "sphere");
    EXPECT_NEAR(s.volume.sum(), enclosed_volume(ball), 5e-3 * enclosed_volume(ball));
    // no point stands for more than its cell (the scaling to the enclosed volume is a few percent at most)
    EXPECT_LT(s.volume.maxCoeff(), 1.05 * std::pow(spacing, 3));
    EXPECT_LT(s.volume.minCoeff(), 0.9 * std::pow(spacing, 3));  // the surface's cells are partly inside
  }
}

TEST(TriangleMesh, AnInsideOutMeshIsNamed) {
  TriangleMesh inside_out = box(Vec3::Zero(), Vec3::Constant(0.05));
  for (auto& f : inside_out.F) std::swap(f[0], f[1]);
  EXPECT_LT(enclosed_volume(inside_out), 0);
  EXPECT_NE(error_of_sampling(inside_out).find("inside-out"), std::string::npos) << error_of_sampling(inside_out);
}

TEST(TriangleMesh, OpenNonManifoldAndBadlyOrientedMeshesAreNamedErrors) {
  TriangleMesh open = box(Vec3::Zero(), Vec3::Ones());
  open.F.pop_back();
  EXPECT_NE(error_of(open).find("mesh.obj: the mesh is open"), std::string::npos) << error_of(open);
  TriangleMesh doubled = box(Vec3::Zero(), Vec3::Ones());
  doubled.F.push_back(doubled.F.front());
  EXPECT_NE(error_of(doubled).find("not manifold"), std::string::npos) << error_of(doubled);
  TriangleMesh flipped = box(Vec3::Zero(), Vec3::Ones());
  std::swap(flipped.F[3][0], flipped.F[3][1]);
  EXPECT_NE(error_of(flipped).find("not consistently oriented"), std::string::npos) << error_of(flipped);
  TriangleMesh flat = box(Vec3::Zero(), Vec3::Ones());
  flat.F[0] = {0, 0, 1};
  EXPECT_NE(error_of(flat).find("degenerate"), std::string::npos) << error_of(flat);
  TriangleMesh bad = box(Vec3::Zero(), Vec3::Ones());
  bad.F[0][0] = 99;
  EXPECT_NE(error_of(bad).find("names vertex 99"), std::string::npos) << error_of(bad);
  EXPECT_THROW(sample_mesh_volume(box(Vec3::Zero(), Vec3::Ones()), 1e-6, "huge"), Error);  // 1e18 cells
}

std::string write(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / ("ph_mesh_" + name);
  std::ofstream(path) << text;
  return path.string();
}

TEST(MeshFile, ObjStlAndPlyMeshesBecomeSolidsInAScene) {
  const TriangleMesh b = box(Vec3::Zero(), Vec3(0.04, 0.03, 0.02));
  std::ostringstream obj, stl, ply;
  for (Eigen::Index v = 0; v < b.V.cols(); ++v)
    obj << "v " << b.V(0, v) << ' ' << b.V(1, v) << ' ' << b.V(2, v) << '\n';
  for (const auto& f : b.F) obj << "f " << f[0] + 1 << ' ' << f[1] + 1 << ' ' << f[2] + 1 << '\n';
  stl << "solid box\n";
  for (const auto& f : b.F) {
    stl << "facet normal 0 0 0\nouter loop\n";
    for (index_t k : f) stl << "vertex " << b.V(0, k) << ' ' << b.V(1, k) << ' ' << b.V(2, k) << '\n';
    stl << "endloop\nendfacet\n";
  }
  stl << "endsolid box\n";
  ply << "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\nelement face 12\n"
         "property list uchar int vertex_indices\nend_header\n";
  for (Eigen::Index v = 0; v < b.V.cols(); ++v) ply << b.V(0, v) << ' ' << b.V(1, v) << ' ' << b.V(2, v) << '\n';
  for (const auto& f : b.F) ply << "3 " << f[0] << ' ' << f[1] << ' ' << f[2] << '\n';
  for (const auto& [name, text] : {std::pair{"box.obj", obj.str()}, {"box.stl", stl.str()}, {"box.ply", ply.str()}}) {
    const std::string path = write(name, text);
    EXPECT_EQ(read_mesh(path).F.size(), 12u) << name;
    const Scene scene =
        parse_scene("[object]\nshape = \"file\"\nfile = \"" + path + "\"\nspacing = 0.01\n", "mesh.toml");
    const Model m = build_scene_model(scene);
    EXPECT_EQ(m.n_points, 4 * 3 * 2) << name;
  }
  // an open mesh in a file: the scene says why
  std::ostringstream open;
  for (Eigen::Index v = 0; v < b.V.cols(); ++v)
    open << "v " << b.V(0, v) << ' ' << b.V(1, v) << ' ' << b.V(2, v) << '\n';
  for (std::size_t t = 0; t + 1 < b.F.size(); ++t)
    open << "f " << b.F[t][0] + 1 << ' ' << b.F[t][1] + 1 << ' ' << b.F[t][2] + 1 << '\n';
  const std::string path = write("open.obj", open.str());
  try {
    build_scene_model(
        parse_scene("[object]\nshape = \"file\"\nfile = \"" + path + "\"\nspacing = 0.01\n", "open.toml"));
    ADD_FAILURE() << "an open mesh was sampled";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("open.obj: the mesh is open"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_mesh(write("junk.obj", "this is not a mesh\n")), Error);
  EXPECT_THROW(read_mesh("/nonexistent/mesh.stl"), Error);
}

}  // namespace
}  // namespace pointhaptics
