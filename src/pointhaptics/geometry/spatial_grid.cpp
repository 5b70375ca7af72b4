#include <pointhaptics/geometry/spatial_grid.hpp>

#include <pointhaptics/core/error.hpp>

#include <cmath>

namespace pointhaptics {

namespace {
constexpr std::size_t table_size = 1 << 16;
}

SpatialGrid::SpatialGrid(double cell) : cell_(cell) {
  if (!(cell > 0) || !std::isfinite(cell)) throw Error("spatial grid: the cell size must be positive");
}

std::size_t SpatialGrid::bucket(long long cx, long long cy, long long cz) const {
  // Teschner et al. 2003 spatial hashing
  const auto h = static_cast<unsigned long long>(cx * 73856093LL) ^ static_cast<unsigned long long>(cy * 19349663LL) ^
                 static_cast<unsigned long long>(cz * 83492791LL);
  return static_cast<std::size_t>(h % table_size);
}

void SpatialGrid::rebuild(const Points& x) {
  const index_t n = static_cast<index_t>(x.cols());
  start_.assign(table_size + 1, 0);
  point_bucket_.resize(n);
  point_cell_.resize(n);
  items_.resize(n);
  for (index_t i = 0; i < n; ++i) {
    const Vec3 p = x.col(i);
    // a non-finite point is binned nowhere useful but never crashes the sort
    const Eigen::Array3d c = p.allFinite() ? Eigen::Array3d((p.array() / cell_).floor()) : Eigen::Array3d::Zero();
    point_cell_[i] = {static_cast<long long>(c.x()), static_cast<long long>(c.y()), static_cast<long long>(c.z())};
    point_bucket_[i] = bucket(point_cell_[i][0], point_cell_[i][1], point_cell_[i][2]);
    ++start_[point_bucket_[i] + 1];
  }
  for (std::size_t b = 0; b < table_size; ++b) start_[b + 1] += start_[b];
  cursor_.assign(start_.begin(), start_.end() - 1);
  for (index_t i = 0; i < n; ++i) items_[cursor_[point_bucket_[i]]++] = i;
}

}  // namespace pointhaptics
