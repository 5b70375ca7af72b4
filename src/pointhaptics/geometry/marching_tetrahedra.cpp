#include <pointhaptics/geometry/marching_tetrahedra.hpp>

#include <pointhaptics/core/run_control.hpp>

#include <algorithm>
#include <unordered_map>

namespace pointhaptics {
namespace {

// A cube's corners by bits (x = 1, y = 2, z = 4) and its six tetrahedra: the paths from corner 0 to corner 7
// along the axes in every order (Kuhn), so every tetrahedron has the main diagonal 0-7 as an edge.
constexpr int tetrahedra[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};

}  // namespace

TriangleMesh marching_tetrahedra(const GridField& field, double level) {
  TriangleMesh mesh;
  std::vector<Vec3> vertices;
  // plain names, not a structured binding: clang 14 (the fuzz build) cannot capture one in a lambda
  const index_t nx = field.nodes[0], ny = field.nodes[1], nz = field.nodes[2];
  // in 64 bits: a grid's node count may pass 2^31 where no index along one axis does
  auto node_index = [&](index_t i, index_t j, index_t k) {
    return static_cast<std::uint64_t>(i) +
           static_cast<std::uint64_t>(nx) *
               (static_cast<std::uint64_t>(j) + static_cast<std::uint64_t>(ny) * static_cast<std::uint64_t>(k));
  };
  auto position = [&](std::uint64_t node) {
    // the node's grid indices (integer division on purpose), then its place
    const auto i = static_cast<index_t>(node % static_cast<std::uint64_t>(nx));
    const auto j = static_cast<index_t>((node / static_cast<std::uint64_t>(nx)) % static_cast<std::uint64_t>(ny));
    const auto k = static_cast<index_t>(node / (static_cast<std::uint64_t>(nx) * static_cast<std::uint64_t>(ny)));
    return Vec3(field.origin +
                field.cell * Vec3(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k)));
  };
  auto value = [&](std::uint64_t node) { return field.values[node]; };
  // one vertex per crossed grid edge, shared by every tetrahedron around it
  std::unordered_map<std::uint64_t, index_t> vertex_of_edge;
  const std::uint64_t n_nodes = static_cast<std::uint64_t>(nx) * ny * nz;
  auto crossing = [&](std::uint64_t inside, std::uint64_t outside) {
    const std::uint64_t key = inside * n_nodes + outside;
    const auto [it, added] = vertex_of_edge.try_emplace(key, static_cast<index_t>(vertices.size()));
    if (added) {
      const double a = value(inside), b = value(outside);  // a > level >= b
      // kept off the outside node: a node at the level is shared by several crossed edges, whose vertices
      // would coincide and make triangles without area
      const double t = std::min((a - level) / (a - b), 1 - 1e-6);
      vertices.push_back(position(inside) + t * (position(outside) - position(inside)));
    }
    return it->second;
  };
  // the triangle (p, q, r) facing away from the inside point `toward`
  auto add = [&](index_t p, index_t q, index_t r, const Vec3& inside_point) {
    const Vec3 n = (vertices[static_cast<std::size_t>(q)] - vertices[static_cast<std::size_t>(p)])
                       .cross(vertices[static_cast<std::size_t>(r)] - vertices[static_cast<std::size_t>(p)]);
    if (n.dot(vertices[static_cast<std::size_t>(p)] - inside_point) >= 0) mesh.F.push_back({p, q, r});
    else mesh.F.push_back({p, r, q});
  };
  for (index_t k = 0; k + 1 < nz; ++k)
    for (index_t j = 0; j + 1 < ny; ++j) {
      throw_if_stop_requested("the surface reconstruction");
      for (index_t i = 0; i + 1 < nx; ++i) {
        std::uint64_t corner[8];
        int above = 0;
        for (int c = 0; c < 8; ++c) {
          corner[c] = node_index(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
          above += value(corner[c]) > level;
        }
        if (above == 0 || above == 8) continue;
        for (const auto& tet : tetrahedra) {
          std::uint64_t in[4], out[4];
          int n_in = 0, n_out = 0;
          for (const int c : tet) (value(corner[c]) > level ? in[n_in++] : out[n_out++]) = corner[c];
          if (n_in == 0 || n_out == 0) continue;
          Vec3 inside_point = Vec3::Zero();
          for (int a = 0; a < n_in; ++a) inside_point += position(in[a]) / n_in;
          if (n_in == 1 || n_out == 1) {  // one corner apart: a triangle across its three edges
            const bool lone_inside = n_in == 1;
            index_t v[3];
            for (int a = 0; a < 3; ++a) v[a] = lone_inside ? crossing(in[0], out[a]) : crossing(in[a], out[0]);
            add(v[0], v[1], v[2], inside_point);
          } else {  // two and two: a quadrilateral, in order around it
            const index_t a = crossing(in[0], out[0]), b = crossing(in[0], out[1]), c = crossing(in[1], out[1]),
                          d = crossing(in[1], out[0]);
            add(a, b, c, inside_point);
            add(a, c, d, inside_point);
          }
        }
      }
    }
  mesh.V.resize(3, static_cast<Eigen::Index>(vertices.size()));
  for (std::size_t v = 0; v < vertices.size(); ++v) mesh.V.col(static_cast<Eigen::Index>(v)) = vertices[v];
  return mesh;
}

}  // namespace pointhaptics
