#include <pointhaptics/geometry/shape_surfaces.hpp>

#include <pointhaptics/core/error.hpp>

#include <fmt/format.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <unordered_map>

namespace pointhaptics {
namespace {

using Lattice = std::array<index_t, 3>;

/// The surface of the lattice box [0, n0] x [0, n1] x [0, n2]: a vertex at every lattice point on its
/// faces, placed by position(lattice point), two triangles per face cell, counter-clockwise seen from
/// outside (for a map that keeps the cube's orientation).
TriangleMesh lattice_box_surface(const Lattice& n, const std::function<Vec3(const Lattice&)>& position) {
  std::unordered_map<std::uint64_t, index_t> vertex_of;
  std::vector<Vec3> vertices;
  auto vertex = [&](const Lattice& p) {
    const std::uint64_t key = (static_cast<std::uint64_t>(p[0]) << 42) | (static_cast<std::uint64_t>(p[1]) << 21) |
                              static_cast<std::uint64_t>(p[2]);
    const auto [it, added] = vertex_of.try_emplace(key, static_cast<index_t>(vertices.size()));
    if (added) vertices.push_back(position(p));
    return it->second;
  };
  TriangleMesh mesh;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;  // e_b x e_c = e_a
    for (const index_t side : {index_t{0}, n[a]}) {
      for (index_t p = 0; p < n[b]; ++p)
        for (index_t q = 0; q < n[c]; ++q) {
          auto at = [&](index_t dp, index_t dq) {
            Lattice l;
            l[a] = side, l[b] = p + dp, l[c] = q + dq;
            return vertex(l);
          };
          const index_t v00 = at(0, 0), v10 = at(1, 0), v11 = at(1, 1), v01 = at(0, 1);
          if (side == n[a]) {  // outward normal +e_a: (b, c) counter-clockwise
            mesh.F.push_back({v00, v10, v11});
            mesh.F.push_back({v00, v11, v01});
          } else {
            mesh.F.push_back({v00, v11, v10});
            mesh.F.push_back({v00, v01, v11});
          }
        }
    }
  }
  mesh.V.resize(3, static_cast<Eigen::Index>(vertices.size()));
  for (std::size_t v = 0; v < vertices.size(); ++v) mesh.V.col(static_cast<Eigen::Index>(v)) = vertices[v];
  return mesh;
}

index_t intervals(double length, double edge) {
  return std::max<index_t>(1, static_cast<index_t>(std::ceil(length / edge - 1e-9)));
}

void check_edge(double edge, double extent, const char* what) {
  if (!(edge > 0) || !std::isfinite(edge))
    throw Error(fmt::format("{} surface: the edge length must be > 0 (m), got {}", what, edge));
  // a million faces per side is far past what anyone draws or touches
  if (extent / edge > 1e6)
    throw Error(fmt::format("{} surface: an edge of {:.3g} m on a {:.3g} m object is too fine", what, edge, extent));
}

/// The unit direction of a cube sphere's lattice point (n per side): equal angles, u -> tan(pi u / 4).
Vec3 cube_sphere_direction(const Lattice& p, index_t n) {
  Vec3 d;
  for (int a = 0; a < 3; ++a)
    d[a] = std::tan(std::numbers::pi / 4 * (2.0 * static_cast<double>(p[a]) / static_cast<double>(n) - 1));
  return d.normalized();
}

}  // namespace

TriangleMesh box_surface(const Vec3& origin, const Vec3& size, double edge) {
  check_edge(edge, size.maxCoeff(), "box");
  const Lattice n = {intervals(size.x(), edge), intervals(size.y(), edge), intervals(size.z(), edge)};
  return lattice_box_surface(n, [&](const Lattice& p) {
    Vec3 x;
    // the last vertex exactly on the far face
    for (int a = 0; a < 3; ++a)
      x[a] = p[a] == n[a] ? origin[a] + size[a]
                          : origin[a] + size[a] * static_cast<double>(p[a]) / static_cast<double>(n[a]);
    return x;
  });
}

TriangleMesh sphere_surface(const Vec3& centre, double radius, double edge) {
  check_edge(edge, radius, "sphere");
  const index_t n = intervals(std::numbers::pi / 2 * radius, edge);
  return lattice_box_surface({n, n, n},
                             [&](const Lattice& p) { return Vec3(centre + radius * cube_sphere_direction(p, n)); });
}

TriangleMesh half_sphere_surface(const Vec3& centre, double radius, double edge) {
  check_edge(edge, radius, "half-sphere");
  index_t n = intervals(std::numbers::pi / 2 * radius, edge);
  n = std::max<index_t>(2, n + n % 2);  // even: the equator is the lattice's middle layer
  return lattice_box_surface({n, n, n}, [&](const Lattice& p) {
    const Vec3 d = cube_sphere_direction(p, n);
    if (2 * p[1] >= n) return Vec3(centre + radius * Vec3(d.x(), p[1] == n / 2 ? 0.0 : d.y(), d.z()));
    // the lower half onto the plane: polar angle from the bottom pole -> radius, azimuth kept
    const double horizontal = std::hypot(d.x(), d.z());
    if (horizontal == 0) return centre;
    const double rho = radius * std::acos(std::clamp(-d.y(), -1.0, 1.0)) / (std::numbers::pi / 2);
    return Vec3(centre + rho * Vec3(d.x() / horizontal, 0.0, d.z() / horizontal));
  });
}

}  // namespace pointhaptics
