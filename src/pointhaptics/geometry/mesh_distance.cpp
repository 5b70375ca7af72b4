#include <pointhaptics/geometry/mesh_distance.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

namespace pointhaptics {

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

double corner_angle(const std::array<Vec3, 3>& v, int k) {
  const Vec3 e1 = (v[static_cast<std::size_t>((k + 1) % 3)] - v[static_cast<std::size_t>(k)]).normalized();
  const Vec3 e2 = (v[static_cast<std::size_t>((k + 2) % 3)] - v[static_cast<std::size_t>(k)]).normalized();
  return std::acos(std::clamp(e1.dot(e2), -1.0, 1.0));
}

std::optional<SurfaceSide> nearest_surface_within(const Vec3& p, const Points& V,
                                                  const std::vector<std::array<index_t, 3>>& F, double radius) {
  const auto corners = [&](const std::array<index_t, 3>& f) {
    return std::array<Vec3, 3>{V.col(f[0]), V.col(f[1]), V.col(f[2])};
  };
  double best = radius * radius;
  std::size_t nearest = F.size();
  int feature = 0;
  Vec3 point = Vec3::Zero();
  for (std::size_t t = 0; t < F.size(); ++t) {
    const std::array<Vec3, 3> v = corners(F[t]);
    // most triangles are far: their boxes, widened by the radius, miss p
    if (((v[0].cwiseMin(v[1]).cwiseMin(v[2]).array() - radius) > p.array()).any() ||
        ((v[0].cwiseMax(v[1]).cwiseMax(v[2]).array() + radius) < p.array()).any())
      continue;
    const auto [q, f] = closest_on_triangle(p, v[0], v[1], v[2]);
    if ((p - q).squaredNorm() >= best) continue;
    best = (p - q).squaredNorm();
    nearest = t;
    feature = f;
    point = q;
  }
  if (nearest == F.size()) return std::nullopt;
  // the feature's pseudo-normal: the face's normal, the sum of an edge's two faces' normals, or the
  // angle-weighted sum of a corner's faces' normals (those faces are all nearer than the radius)
  const std::array<index_t, 3>& near = F[nearest];
  Vec3 normal = Vec3::Zero();
  int faces = 0;
  // a corner's faces' other corners: each twice when its faces close around it (no allocation: a tool's step
  // asks; a corner of more than 32 faces is taken as not closed)
  std::array<index_t, 64> around{};
  std::size_t n_around = 0;
  for (std::size_t t = 0; t < F.size(); ++t) {
    const std::array<index_t, 3>& f = F[t];
    int shared = 0, corner = -1;
    for (int k = 0; k < 3; ++k) {
      const index_t v = f[static_cast<std::size_t>(k)];
      if (feature >= 3 && feature < 6 &&
          (v == near[static_cast<std::size_t>(feature - 3)] || v == near[static_cast<std::size_t>((feature - 2) % 3)]))
        ++shared;
      if (feature < 3 && v == near[static_cast<std::size_t>(feature)]) corner = k;
    }
    const bool counts = feature == 6 ? t == nearest : feature < 3 ? corner >= 0 : shared == 2;
    if (!counts) continue;
    const std::array<Vec3, 3> v = corners(f);
    const Vec3 n = (v[1] - v[0]).cross(v[2] - v[0]).normalized();
    normal += feature < 3 ? corner_angle(v, corner) * n : n;
    ++faces;
    if (feature < 3 && n_around + 2 <= around.size()) {
      around[n_around++] = f[static_cast<std::size_t>((corner + 1) % 3)];
      around[n_around++] = f[static_cast<std::size_t>((corner + 2) % 3)];
    }
  }
  bool sure = feature == 6 || (feature < 6 && faces == 2);
  if (feature < 3) {
    std::sort(around.begin(), around.begin() + static_cast<std::ptrdiff_t>(n_around));
    sure = n_around >= 6 && n_around == 2 * static_cast<std::size_t>(faces);
    for (std::size_t k = 0; sure && k < n_around; k += 2)
      sure = around[k] == around[k + 1] && (k + 2 >= n_around || around[k + 2] != around[k]);
  }
  const double distance = std::sqrt(best);
  return SurfaceSide{point, (p - point).dot(normal) < 0 ? -distance : distance, sure};
}

MeshDistance::MeshDistance(const TriangleMesh& mesh) : mesh_(mesh) {
  const std::size_t n_faces = mesh.F.size();
  centroid_.resize(3, static_cast<Eigen::Index>(n_faces));
  face_normal_.resize(n_faces);
  edge_normal_.assign(n_faces, {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()});
  vertex_normal_.assign(static_cast<std::size_t>(mesh.V.cols()), Vec3::Zero());
  std::unordered_map<std::uint64_t, Vec3> edge_sum;  // undirected edge -> the sum of its faces' normals
  auto key = [](index_t a, index_t b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(std::min(a, b))) << 32) |
           static_cast<std::uint32_t>(std::max(a, b));
  };
  for (std::size_t t = 0; t < n_faces; ++t) {
    const auto& f = mesh.F[t];
    const Vec3 v[3] = {mesh.V.col(f[0]), mesh.V.col(f[1]), mesh.V.col(f[2])};
    centroid_.col(static_cast<Eigen::Index>(t)) = (v[0] + v[1] + v[2]) / 3.0;
    for (const Vec3& corner : v)
      reach_ = std::max(reach_, (corner - centroid_.col(static_cast<Eigen::Index>(t))).norm());
    const Vec3 n = (v[1] - v[0]).cross(v[2] - v[0]).normalized();
    face_normal_[t] = n;
    for (int k = 0; k < 3; ++k) {
      // (Eigen's vectors start uninitialised: the map's new entries are made zero first)
      edge_sum.try_emplace(key(f[k], f[(k + 1) % 3]), Vec3::Zero()).first->second += n;
      vertex_normal_[static_cast<std::size_t>(f[k])] += corner_angle({v[0], v[1], v[2]}, k) * n;
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
    normal = feature < 3   ? vertex_normal_[static_cast<std::size_t>(f[feature])]
             : feature < 6 ? edge_normal_[static_cast<std::size_t>(t)][feature - 3]
                           : face_normal_[static_cast<std::size_t>(t)];
  }
  const double distance = std::sqrt(best);
  return direction.dot(normal) < 0 ? -distance : distance;
}

}  // namespace pointhaptics
