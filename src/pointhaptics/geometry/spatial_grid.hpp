#pragma once
/// @file A uniform grid over moving points, rebuilt cheaply every step, for local sphere queries.
#include <pointhaptics/core/types.hpp>

#include <array>
#include <vector>

namespace pointhaptics {

/// Points binned in cubic cells of a fixed size (a hashed grid: cell coordinates are hashed into a
/// fixed table, so the grid needs no bounds and its memory does not grow with the object's extent).
/// rebuild() is one counting sort, O(n) with a small constant and no allocation after the first call;
/// a query visits only the cells a sphere overlaps.
class SpatialGrid {
 public:
  /// cell: the cell edge (m), at least the largest query radius for the best speed.
  explicit SpatialGrid(double cell = 0.01);
  void rebuild(const Points& x);
  /// Calls visit(i) for every point i within `radius` of `centre` (exact distance test).
  template <class Visit>
  void for_each_within(const Points& x, const Vec3& centre, double radius, Visit&& visit) const;
  double cell() const { return cell_; }

 private:
  std::size_t bucket(long long cx, long long cy, long long cz) const;
  double cell_;
  std::vector<index_t> start_, items_, cursor_;  // CSR: bucket b holds items_[start_[b] .. start_[b + 1])
  std::vector<std::size_t> point_bucket_;
  std::vector<std::array<long long, 3>> point_cell_;
};

template <class Visit>
void SpatialGrid::for_each_within(const Points& x, const Vec3& centre, double radius, Visit&& visit) const {
  if (start_.empty() || !centre.allFinite() || !(radius >= 0)) return;
  const Eigen::Array3d lo = ((centre.array() - radius) / cell_).floor(),
                       hi = ((centre.array() + radius) / cell_).floor();
  const double r2 = radius * radius;
  for (long long cz = static_cast<long long>(lo.z()); cz <= static_cast<long long>(hi.z()); ++cz)
    for (long long cy = static_cast<long long>(lo.y()); cy <= static_cast<long long>(hi.y()); ++cy)
      for (long long cx = static_cast<long long>(lo.x()); cx <= static_cast<long long>(hi.x()); ++cx) {
        const std::size_t b = bucket(cx, cy, cz);
        for (index_t k = start_[b]; k < start_[b + 1]; ++k) {
          const index_t i = items_[k];
          // hashing may share a bucket between cells: take only this cell's points, so none is seen twice
          const auto& c = point_cell_[i];
          if (c[0] != cx || c[1] != cy || c[2] != cz) continue;
          if ((x.col(i) - centre).squaredNorm() <= r2) visit(i);
        }
      }
}

}  // namespace pointhaptics
