#pragma once
/// @file The signed distance to a closed triangle mesh: negative inside, signed by the angle-weighted
/// pseudo-normal of the closest feature (face, edge or vertex; Baerentzen and Aanaes 2005), which makes the
/// sign exact for a closed, consistently oriented mesh wherever the closest point is.
#include <pointhaptics/geometry/kd_tree.hpp>
#include <pointhaptics/geometry/triangle_mesh.hpp>

#include <array>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

namespace pointhaptics {

/// The closest point of triangle (a, b, c) to p, and its feature: 0-2 a corner, 3-5 the edge from corner k - 3
/// to the next, 6 the face (Ericson, Real-Time Collision Detection, 5.1.5).
std::pair<Vec3, int> closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// The angle of triangle (v[0], v[1], v[2]) at corner k, radians: a vertex's pseudo-normal weighs its faces'
/// normals by it.
double corner_angle(const std::array<Vec3, 3>& v, int k);

/// Where a point is seen from a surface: its nearest point there, and the distance to it, negative inside.
struct SurfaceSide {
  Vec3 point = Vec3::Zero();
  double distance = 0;
  /// The sign is sure: the nearest point is inside a face, or on an edge of two faces, or on a corner whose
  /// faces close around it. Not on a part of a surface (a level of detail's active set carries one) where it
  /// ends: there a point beside the part may be signed inside by the one face it sees.
  bool sure = true;
};

/// The nearest point to p of the triangles F (over vertices V, outward oriented) within `radius` of it, signed
/// by the pseudo-normal of its feature as MeshDistance does, without its set-up: for a surface that moves
/// (a tool's contact carries it every step). Only the triangles within `radius` are seen, so a vertex's or an
/// edge's pseudo-normal is exact when the nearest point is within it (and the surface closed around it: `sure`).
/// nullopt: no triangle within `radius`.
std::optional<SurfaceSide> nearest_surface_within(const Vec3& p, const Points& V,
                                                  const std::vector<std::array<index_t, 3>>& F, double radius);

class MeshDistance {
 public:
  /// `mesh` must outlive this and be closed and consistently oriented (check_closed_manifold()).
  explicit MeshDistance(const TriangleMesh& mesh);
  /// The distance from p to the mesh, negative inside.
  double signed_distance(const Vec3& p) const;

 private:
  const TriangleMesh& mesh_;
  Points centroid_;                ///< of each triangle (the closest one is searched by them)
  std::unique_ptr<KdTree> tree_;   ///< over the centroids
  double reach_ = 0;               ///< the largest distance from a triangle's centroid to its corners
  std::vector<Vec3> face_normal_;  ///< unit
  std::vector<std::array<Vec3, 3>>
      edge_normal_;                  ///< per triangle, edge k (corner k to k + 1): the sum of its two faces' normals
  std::vector<Vec3> vertex_normal_;  ///< angle-weighted sum of the faces' normals around it
};

}  // namespace pointhaptics
