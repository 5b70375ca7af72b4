#include <pointhaptics/geometry/remesh.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/shape_surfaces.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <unordered_map>

namespace pointhaptics {
namespace {

constexpr std::size_t max_split_triangles = 4'000'000;

}  // namespace

double mean_edge_length(const TriangleMesh& mesh) {
  double sum = 0;
  for (const auto& f : mesh.F)
    for (int k = 0; k < 3; ++k) sum += (mesh.V.col(f[k]) - mesh.V.col(f[(k + 1) % 3])).norm();
  return mesh.F.empty() ? 0.0 : sum / (3.0 * static_cast<double>(mesh.F.size()));
}

TriangleMesh subdivide(const TriangleMesh& mesh) {
  std::vector<Vec3> vertices;
  for (Eigen::Index v = 0; v < mesh.V.cols(); ++v) vertices.push_back(mesh.V.col(v));
  std::map<std::pair<index_t, index_t>, index_t> midpoint;
  auto middle = [&](index_t a, index_t b) {
    const auto key = std::minmax(a, b);
    const auto [it, added] = midpoint.try_emplace({key.first, key.second}, static_cast<index_t>(vertices.size()));
    if (added) vertices.push_back(0.5 * (mesh.V.col(a) + mesh.V.col(b)));
    return it->second;
  };
  TriangleMesh out;
  for (const auto& f : mesh.F) {
    const index_t ab = middle(f[0], f[1]), bc = middle(f[1], f[2]), ca = middle(f[2], f[0]);
    out.F.push_back({f[0], ab, ca});
    out.F.push_back({ab, f[1], bc});
    out.F.push_back({ca, bc, f[2]});
    out.F.push_back({ab, bc, ca});
  }
  out.V.resize(3, static_cast<Eigen::Index>(vertices.size()));
  for (std::size_t v = 0; v < vertices.size(); ++v) out.V.col(static_cast<Eigen::Index>(v)) = vertices[v];
  return out;
}

TriangleMesh cluster_vertices(const TriangleMesh& mesh, double cell) {
  const Vec3 lo = mesh.V.rowwise().minCoeff();
  std::unordered_map<std::uint64_t, index_t> cluster_of_cell;
  std::vector<index_t> cluster(static_cast<std::size_t>(mesh.V.cols()));
  std::vector<Vec3> sum;
  std::vector<int> count;
  for (Eigen::Index v = 0; v < mesh.V.cols(); ++v) {
    const Eigen::Array3d c = ((mesh.V.col(v) - lo) / cell).array().floor();
    const std::uint64_t key = (static_cast<std::uint64_t>(c.x()) << 42) | (static_cast<std::uint64_t>(c.y()) << 21) |
                              static_cast<std::uint64_t>(c.z());
    const auto [it, added] = cluster_of_cell.try_emplace(key, static_cast<index_t>(sum.size()));
    if (added) {
      sum.push_back(Vec3::Zero());
      count.push_back(0);
    }
    cluster[static_cast<std::size_t>(v)] = it->second;
    sum[static_cast<std::size_t>(it->second)] += mesh.V.col(v);
    ++count[static_cast<std::size_t>(it->second)];
  }
  // each cluster at its vertex nearest the cluster's mean: on the input surface (the mean of a curved
  // patch lies inside it, and shrank a sphere by 1.6% at eight input edges per cell)
  TriangleMesh out;
  out.V.resize(3, static_cast<Eigen::Index>(sum.size()));
  std::vector<double> nearest(sum.size(), std::numeric_limits<double>::infinity());
  for (Eigen::Index v = 0; v < mesh.V.cols(); ++v) {
    const auto k = static_cast<std::size_t>(cluster[static_cast<std::size_t>(v)]);
    const double d = (mesh.V.col(v) - sum[k] / count[k]).squaredNorm();
    if (d < nearest[k]) {
      nearest[k] = d;
      out.V.col(static_cast<Eigen::Index>(k)) = mesh.V.col(v);
    }
  }
  // triangles kept once per vertex set; a set seen in both orientations is a collapsed sliver: both dropped
  std::map<std::array<index_t, 3>, std::size_t> seen;
  std::vector<bool> keep;
  for (const auto& f : mesh.F) {
    const std::array<index_t, 3> t = {cluster[static_cast<std::size_t>(f[0])], cluster[static_cast<std::size_t>(f[1])],
                                      cluster[static_cast<std::size_t>(f[2])]};
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    std::array<index_t, 3> sorted = t;
    std::sort(sorted.begin(), sorted.end());
    if (const auto it = seen.find(sorted); it != seen.end()) {
      keep[it->second] = false;
      continue;
    }
    seen.emplace(sorted, out.F.size());
    out.F.push_back(t);
    keep.push_back(true);
  }
  std::size_t w = 0;
  for (std::size_t k = 0; k < out.F.size(); ++k)
    if (keep[k]) out.F[w++] = out.F[k];
  out.F.resize(w);
  return out;
}

Remeshed adapt_to_edge(const TriangleMesh& mesh, double edge) {
  const double before = mean_edge_length(mesh);
  Remeshed r{mesh, "kept as it is"};
  if (before > 2 * edge) {
    int splits = 0;
    // each split halves the edges and quadruples the triangles: at most four million
    while (mean_edge_length(r.mesh) > 2 * edge && 4 * r.mesh.F.size() <= max_split_triangles) {
      r.mesh = subdivide(r.mesh);
      ++splits;
    }
    r.change = fmt::format("split {} time{} (mean edge {:.3g} -> {:.3g} mm, {} triangles{})", splits,
                           splits == 1 ? "" : "s", 1e3 * before, 1e3 * mean_edge_length(r.mesh), r.mesh.F.size(),
                           mean_edge_length(r.mesh) > 2 * edge ? "; stopped at the limit of four million" : "");
  } else if (before < 0.25 * edge) {
    TriangleMesh simpler = cluster_vertices(mesh, edge);
    std::string why;
    try {
      check_closed_manifold(simpler, "the simplified surface");
      const double v0 = enclosed_volume(mesh), v1 = enclosed_volume(simpler);
      // 2.5%: a surface with edges of the asked length is inscribed in a curved one (a sphere of six edges'
      // radius loses 1%), a part thinner than a cell loses far more
      if (!(std::abs(v1 - v0) <= 0.025 * std::abs(v0)))
        why = fmt::format("it would change the enclosed volume by {:.1f}%", 100 * (v1 - v0) / v0);
    } catch (const Error& e) {
      why = e.what();
    }
    if (why.empty()) {
      r.change = fmt::format("simplified by vertex clustering (mean edge {:.3g} -> {:.3g} mm, {} -> {} triangles)",
                             1e3 * before, 1e3 * mean_edge_length(simpler), mesh.F.size(), simpler.F.size());
      r.mesh = std::move(simpler);
    } else {
      r.change = fmt::format(
          "kept as it is (mean edge {:.3g} mm, far finer than asked: simplifying it would not keep it faithful: {})",
          1e3 * before, why);
    }
  }
  return r;
}

}  // namespace pointhaptics
