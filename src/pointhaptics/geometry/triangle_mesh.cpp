#include <pointhaptics/geometry/triangle_mesh.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/core/polled_loop.hpp>

#include <fmt/format.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <unordered_map>

namespace pointhaptics {

void check_closed_manifold(const TriangleMesh& mesh, const std::string& name) {
  const index_t nv = static_cast<index_t>(mesh.V.cols());
  if (mesh.F.size() < 4) throw Error(fmt::format("{}: {} triangles cannot bound a solid", name, mesh.F.size()));
  if (!mesh.V.allFinite()) throw Error(fmt::format("{}: a vertex is not finite", name));
  // directed edges: (a, b) -> count; a closed, consistently oriented manifold uses each once, and its
  // reverse once
  std::unordered_map<std::uint64_t, int> directed;
  directed.reserve(3 * mesh.F.size());
  auto key = [](index_t a, index_t b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
  };
  for (std::size_t t = 0; t < mesh.F.size(); ++t) {
    const auto& f = mesh.F[t];
    for (int k = 0; k < 3; ++k)
      if (f[k] < 0 || f[k] >= nv) throw Error(fmt::format("{}: triangle {} names vertex {} of {}", name, t, f[k], nv));
    const Vec3 n = (mesh.V.col(f[1]) - mesh.V.col(f[0])).cross(mesh.V.col(f[2]) - mesh.V.col(f[0]));
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2] || !(n.norm() > 0))
      throw Error(fmt::format("{}: triangle {} is degenerate (no area)", name, t));
    for (int k = 0; k < 3; ++k) ++directed[key(f[k], f[(k + 1) % 3])];
  }
  for (const auto& [k, count] : directed) {
    const index_t a = static_cast<index_t>(k >> 32), b = static_cast<index_t>(k & 0xffffffffu);
    const auto reverse = directed.find(key(b, a));
    const int back = reverse == directed.end() ? 0 : reverse->second;
    const Vec3 at = 0.5 * (mesh.V.col(a) + mesh.V.col(b));
    if (count > 1 || back > 1)
      throw Error(
          fmt::format("{}: not manifold or not consistently oriented: the edge between vertices {} and {} at "
                      "({:.4g}, {:.4g}, {:.4g}) is used {} times one way and {} the other",
                      name, a, b, at.x(), at.y(), at.z(), count, back));
    if (back == 0)
      throw Error(fmt::format(
          "{}: the mesh is open (the edge between vertices {} and {} at ({:.4g}, {:.4g}, {:.4g}) bounds one "
          "triangle): its inside is undefined",
          name, a, b, at.x(), at.y(), at.z()));
  }
}

double winding_number(const TriangleMesh& mesh, const Vec3& p) {
  double sum = 0;
  for (const auto& f : mesh.F) {
    // van Oosterom & Strackee: tan(Omega / 2) = a . (b x c) / (|a||b||c| + (a.b)|c| + (b.c)|a| + (c.a)|b|)
    const Vec3 a = mesh.V.col(f[0]) - p, b = mesh.V.col(f[1]) - p, c = mesh.V.col(f[2]) - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double det = a.dot(b.cross(c));
    const double div = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    sum += 2.0 * std::atan2(det, div);
  }
  return sum / (4.0 * std::numbers::pi);
}

PointCloud sample_mesh_volume(const TriangleMesh& mesh, double spacing, const std::string& name, index_t max_points) {
  if (!(spacing > 0) || !std::isfinite(spacing)) throw Error(fmt::format("{}: spacing must be > 0 (m)", name));
  check_closed_manifold(mesh, name);
  const Vec3 lo = mesh.V.rowwise().minCoeff(), hi = mesh.V.rowwise().maxCoeff();
  // cells of `spacing` covering the box (the last one may stick out), their centres centred in it. A mesh file's
  // single-precision vertices make a 5 cm cube 5.0000001 cells of 1 cm: within 1e-6 a whole number is taken as
  // it (else a sixth cell put the centres on the faces, and a 5 cm cube got 216 points: issue 52)
  const Eigen::Array3d cells = ((hi - lo).array() / spacing * (1 - 1e-6)).ceil().max(1.0);
  const double total = cells.prod();
  if (!(total <= 8.0 * static_cast<double>(max_points)))
    throw Error(fmt::format("{}: a {:.3g} m spacing gives {:.3g} lattice cells: too many (coarser spacing?)", name,
                            spacing, total));
  const index_t nx = static_cast<index_t>(cells.x()), ny = static_cast<index_t>(cells.y()),
                nz = static_cast<index_t>(cells.z());
  const index_t n_cells = nx * ny * nz;
  std::vector<unsigned char> inside(static_cast<std::size_t>(n_cells), 0);
  // centred in the bounding box, so that a box-shaped mesh is sampled symmetrically and no point lies on
  // a face of it (where the winding number is 1/2)
  const Vec3 origin = 0.5 * (lo + hi) - 0.5 * (cells.matrix() - Vec3::Ones()) * spacing;
  auto position = [&](index_t c) {
    const index_t i = c % nx, j = (c / nx) % ny, k = c / (nx * ny);
    return Vec3(origin + spacing * Vec3(i, j, k));
  };
  const double enclosed = enclosed_volume(mesh);
  if (!(enclosed > 0))
    throw Error(
        fmt::format("{}: the mesh encloses a volume of {:.3g} m^3: its triangles face inwards (an inside-out "
                    "mesh; flip their orientation)",
                    name, enclosed));
  parallel_for_polled("the mesh's inside", n_cells, [&](index_t c) {
    inside[static_cast<std::size_t>(c)] = winding_number(mesh, position(c)) > 0.5;
  });
  const auto n = static_cast<index_t>(std::count(inside.begin(), inside.end(), 1));
  if (n == 0)
    throw Error(
        fmt::format("{}: no lattice point of spacing {:.3g} m lies inside the mesh (finer spacing?)", name, spacing));
  if (n > max_points) throw Error(fmt::format("{}: {} points inside: too many (coarser spacing?)", name, n));
  PointCloud cloud;
  cloud.spacing = spacing;
  cloud.X.resize(3, n);
  cloud.volume.resize(n);
  cloud.surface.assign(static_cast<std::size_t>(n), 0);
  std::vector<index_t> cell_of(static_cast<std::size_t>(n));
  index_t k = 0;
  for (index_t c = 0; c < n_cells; ++c)
    if (inside[static_cast<std::size_t>(c)]) {
      cell_of[static_cast<std::size_t>(k)] = c;
      cloud.X.col(k++) = position(c);
    }
  // each point stands for the part of its cell inside the mesh: whole cells inside, the share of 4^3
  // sub-cell centres inside for cells on the surface (a lattice neighbour outside); then all are scaled to the
  // enclosed volume, which the cells whose centre is outside would otherwise miss (issue 52: a 5 cm cube at
  // 1 cm had +73%, a 0.2 m one +16%)
  const auto is_inside = [&](index_t i, index_t j, index_t l) {
    return i >= 0 && j >= 0 && l >= 0 && i < nx && j < ny && l < nz &&
           inside[static_cast<std::size_t>(i + nx * (j + ny * l))];
  };
  constexpr int sub_cells = 4;
  parallel_for_polled("the mesh's cell volumes", n, [&](index_t p) {
    const index_t c = cell_of[static_cast<std::size_t>(p)];
    const index_t i = c % nx, j = (c / nx) % ny, l = c / (nx * ny);
    const bool on_surface = !is_inside(i - 1, j, l) || !is_inside(i + 1, j, l) || !is_inside(i, j - 1, l) ||
                            !is_inside(i, j + 1, l) || !is_inside(i, j, l - 1) || !is_inside(i, j, l + 1);
    cloud.surface[static_cast<std::size_t>(p)] = on_surface;
    double share = 1;
    if (on_surface) {
      int in = 0;
      for (int a = 0; a < sub_cells; ++a)
        for (int b = 0; b < sub_cells; ++b)
          for (int d = 0; d < sub_cells; ++d) {
            const Vec3 offset = (Vec3(a, b, d) + Vec3::Constant(0.5)) / sub_cells - Vec3::Constant(0.5);
            in += winding_number(mesh, position(c) + spacing * offset) > 0.5;
          }
      share = static_cast<double>(in) / (sub_cells * sub_cells * sub_cells);
    }
    // a point stands for at least a sliver of its cell (its centre is inside)
    cloud.volume[p] = std::max(share, 1.0 / (sub_cells * sub_cells * sub_cells)) * spacing * spacing * spacing;
  });
  cloud.volume *= enclosed / cloud.volume.sum();
  return cloud;
}

double enclosed_volume(const TriangleMesh& mesh) {
  // the divergence theorem over the outward-oriented triangles: sum of the signed tetrahedra to the origin,
  // taken about the centroid of the vertices (fewer cancelling digits far from the origin)
  const Vec3 centre = mesh.V.rowwise().mean();
  double six_volume = 0;
  for (const auto& f : mesh.F)
    six_volume += (mesh.V.col(f[0]) - centre).dot((mesh.V.col(f[1]) - centre).cross(mesh.V.col(f[2]) - centre));
  return six_volume / 6;
}

}  // namespace pointhaptics
