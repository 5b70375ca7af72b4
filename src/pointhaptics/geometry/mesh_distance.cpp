#include <pointhaptics/geometry/mesh_distance.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

namespace pointhaptics {
namespace {

/// The closest point of triangle (a, b, c) to p, and its feature: 0-2 a corner, 3-5 the edge from corner k - 3
/// to the next, 6 the face (Ericson, Real-Time Collision Detection, 5.1.5).
std::pair<Vec3, int> closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {a, 0};
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {b, 1};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return {a + (d1 / (d1 - d3)) * ab, 3};
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {c, 2};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return {a + (d2 / (d2 - d6)) * ac, 5};
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return {b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b), 4};
  const double denominator = 1.0 / (va + vb + vc);
  return {a + ab * (vb * denominator) + ac * (vc * denominator), 6};
}

}  // namespace

MeshDistance::MeshDistance(const TriangleMesh& mesh) : mesh_(mesh) {
  const std::size_t n_faces = mesh.F.size();
  centroid_.resize(3, static_cast<Eigen::Index>(n_faces));
  face_normal_.resize(n_faces);
  edge_normal_.assign(n_faces, {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()});
  vertex_normal_.assign(static_cast<std::size_t>(mesh.V.cols()), Vec3::Zero());
  std::unordered_map<std::uint64_t, Vec3> edge_sum;  // undirected edge -> the sum of its faces' normals
  auto key = [](index_t a, index_t b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(std::min(a, b))) << 32) | static_cast<std::uint32_t>(std::max(a, b));
  };
  for (std::size_t t = 0; t < n_faces; ++t) {
    const auto& f = mesh.F[t];
    const Vec3 v[3] = {mesh.V.col(f[0]), mesh.V.col(f[1]), mesh.V.col(f[2])};
    centroid_.col(static_cast<Eigen::Index>(t)) = (v[0] + v[1] + v[2]) / 3.0;
    for (const Vec3& corner : v) reach_ = std::max(reach_, (corner - centroid_.col(static_cast<Eigen::Index>(t))).norm());
    const Vec3 n = (v[1] - v[0]).cross(v[2] - v[0]).normalized();
    face_normal_[t] = n;
    for (int k = 0; k < 3; ++k) {
      // (Eigen's vectors start uninitialised: the map's new entries are made zero first)
      edge_sum.try_emplace(key(f[k], f[(k + 1) % 3]), Vec3::Zero()).first->second += n;
      const Vec3 e1 = (v[(k + 1) % 3] - v[k]).normalized(), e2 = (v[(k + 2) % 3] - v[k]).normalized();
      vertex_normal_[static_cast<std::size_t>(f[k])] += std::acos(std::clamp(e1.dot(e2), -1.0, 1.0)) * n;
    }
  }
  for (std::size_t t = 0; t < n_faces; ++t)
    for (int k = 0; k < 3; ++k) edge_normal_[t][k] = edge_sum[key(mesh.F[t][k], mesh.F[t][(k + 1) % 3])];
  tree_ = std::make_unique<KdTree>(centroid_);
}

double MeshDistance::signed_distance(const Vec3& p) const {
  // the closest triangle lies on the closest centroid's triangle or nearer: its centroid is within that
  // distance plus the largest centroid-to-corner distance
  index_t nearest = 0;
  double d2 = 0;
  tree_->index().knnSearch(p.data(), 1, &nearest, &d2);
  const double radius = std::sqrt(d2) + reach_;
  std::vector<std::pair<index_t, double>> found;
  nanoflann::SearchParams params;
  params.sorted = false;
  tree_->index().radiusSearch(p.data(), radius * radius * (1 + 1e-12), found, params);
  double best = std::numeric_limits<double>::infinity();
  Vec3 direction = Vec3::Zero(), normal = Vec3::UnitZ();
  for (const auto& [t, ignored] : found) {
    const auto& f = mesh_.F[static_cast<std::size_t>(t)];
    const auto [q, feature] = closest_on_triangle(p, mesh_.V.col(f[0]), mesh_.V.col(f[1]), mesh_.V.col(f[2]));
    const double d = (p - q).squaredNorm();
    if (d >= best) continue;
    best = d;
    direction = p - q;
    normal = feature < 3 ? vertex_normal_[static_cast<std::size_t>(f[feature])]
             : feature < 6 ? edge_normal_[static_cast<std::size_t>(t)][feature - 3]
                           : face_normal_[static_cast<std::size_t>(t)];
  }
  const double distance = std::sqrt(best);
  return direction.dot(normal) < 0 ? -distance : distance;
}

}  // namespace pointhaptics
