#pragma once
/// @file The signed distance to a closed triangle mesh: negative inside, signed by the angle-weighted
/// pseudo-normal of the closest feature (face, edge or vertex; Baerentzen and Aanaes 2005), which makes the
/// sign exact for a closed, consistently oriented mesh wherever the closest point is.
#include <pointhaptics/geometry/kd_tree.hpp>
#include <pointhaptics/geometry/triangle_mesh.hpp>

#include <array>
#include <memory>
#include <vector>

namespace pointhaptics {

class MeshDistance {
 public:
  /// `mesh` must outlive this and be closed and consistently oriented (check_closed_manifold()).
  explicit MeshDistance(const TriangleMesh& mesh);
  /// The distance from p to the mesh, negative inside.
  double signed_distance(const Vec3& p) const;

 private:
  const TriangleMesh& mesh_;
  Points centroid_;                             ///< of each triangle (the closest one is searched by them)
  std::unique_ptr<KdTree> tree_;                ///< over the centroids
  double reach_ = 0;                            ///< the largest distance from a triangle's centroid to its corners
  std::vector<Vec3> face_normal_;               ///< unit
  std::vector<std::array<Vec3, 3>> edge_normal_;  ///< per triangle, edge k (corner k to k + 1): the sum of its two faces' normals
  std::vector<Vec3> vertex_normal_;             ///< angle-weighted sum of the faces' normals around it
};

}  // namespace pointhaptics
