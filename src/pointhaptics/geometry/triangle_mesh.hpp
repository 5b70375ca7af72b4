#pragma once
/// @file Closed triangle meshes as solids: the checks that make "inside" meaningful, the generalised
/// winding number, and volume sampling on a lattice.
#include <pointhaptics/core/point_cloud.hpp>

#include <array>
#include <string>
#include <vector>

namespace pointhaptics {

struct TriangleMesh {
  Points V;                               ///< vertices, m  (3 x n_vertices)
  std::vector<std::array<index_t, 3>> F;  ///< triangles, counter-clockwise seen from outside
};

/// Throws Error (naming `name`) unless the mesh bounds a solid: at least 4 triangles, finite vertices,
/// valid indices, no degenerate triangle, and every edge shared by exactly two triangles that use it in
/// opposite directions (closed, manifold, consistently oriented). The message says which edge fails.
void check_closed_manifold(const TriangleMesh& mesh, const std::string& name);

/// The generalised winding number of the mesh at p (Jacobson et al. 2013): the triangles' signed solid
/// angles / 4 pi; 1 inside a closed outward-oriented mesh, 0 outside, robust to small defects.
double winding_number(const TriangleMesh& mesh, const Vec3& p);

/// The volume a closed, outward-oriented mesh encloses (divergence theorem; m^3, negative for an inside-out one).
double enclosed_volume(const TriangleMesh& mesh);

/// The points of a lattice of `spacing` (cell centres, centred in the bounding box) whose winding
/// number exceeds 1/2, each standing for the part of its cell inside the mesh, the volumes summing to
/// enclosed_volume(). Throws Error (naming `name`) if the mesh fails check_closed_manifold, is inside out,
/// holds no lattice point (spacing too coarse for it), or would hold more than `max_points`.
PointCloud sample_mesh_volume(const TriangleMesh& mesh, double spacing, const std::string& name,
                              index_t max_points = 20'000'000);

}  // namespace pointhaptics
