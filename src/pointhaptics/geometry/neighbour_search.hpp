#pragma once
/// @file Fixed-radius neighbour search in the reference configuration.
#include <pointhaptics/core/csr.hpp>

namespace pointhaptics {

/// Whether two points at squared distance r2 are neighbours for support radius h: r < h, with a
/// relative margin of 1e-9 so that grid points exactly h apart (where every kernel is zero) are
/// excluded whatever the round-off in their coordinates.
inline bool within_support(double r2, double h) { return r2 < h * h * (1.0 - 2e-9); }

/// For every point i, the points j != i within_support of it, sorted by index (nanoflann k-d tree).
Csr radius_neighbours(const Points& X, double h);

/// The same by testing all pairs: O(n^2), for tests.
Csr radius_neighbours_brute_force(const Points& X, double h);
/// With a support radius per point: i and j are neighbours when |X_j - X_i| < max(h_i, h_j), so that
/// neighbourhoods stay symmetric (used by levels of detail, which widen the support of sparse points).
Csr radius_neighbours(const Points& X, const Eigen::VectorXd& support);

/// For each point, the index of the nearest other point (-1 when there is only one point).
std::vector<index_t> nearest_neighbour(const Points& X);

}  // namespace pointhaptics
