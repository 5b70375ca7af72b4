#pragma once
/// @file Sampling of simple solids into points with tributary (cell) volumes.
#include <pointhaptics/core/point_cloud.hpp>

#include <functional>

namespace pointhaptics {

/// A vertex grid over the box [origin, origin + size] that includes its faces. Each axis gets
/// round(size / spacing) intervals (at least 1), so the grid spacing per axis is size / intervals.
/// Volumes are grid cells halved once per boundary direction (face 1/2, edge 1/4, corner 1/8), so
/// they sum to the box's volume exactly.
PointCloud sample_box(const Vec3& origin, const Vec3& size, double spacing);

/// The points of the lattice origin + (i, j, k) * step (per axis) in [lo, hi] for which inside() holds, with
/// surface flags (a point whose lattice neighbour along an axis is outside); no volumes.
PointCloud lattice_inside(const Vec3& origin, const Vec3& step, const Vec3& lo, const Vec3& hi,
                          const std::function<bool(const Vec3&)>& inside);

/// sample_box's lattice step per axis: the size over round(size / spacing) intervals (at least 1).
Vec3 box_lattice_step(const Vec3& size, double spacing);

/// Grid points (spacing apart, one at the centre) inside the ball; volumes are cells clipped to the
/// ball (see clipped_cell_volumes) and sum to 4/3 pi r^3.
PointCloud sample_sphere(const Vec3& centre, double radius, double spacing);

/// The upper half ball y >= centre.y (flat face down, on a grid plane); volumes sum to 2/3 pi r^3.
PointCloud sample_half_sphere(const Vec3& centre, double radius, double spacing);

/// Volume owned by each point: the body (inside(p) true) is sampled by a fine grid of `refinement`^3
/// cells per spacing^3 inside [lo, hi], each fine cell is given to its nearest point (a clipped Voronoi
/// cell), and the result is rescaled so that the volumes sum to exact_volume.
Eigen::VectorXd clipped_cell_volumes(const Points& X, const std::function<bool(const Vec3&)>& inside, const Vec3& lo,
                                     const Vec3& hi, double spacing, double exact_volume, int refinement = 6);

}  // namespace pointhaptics
