#include <pointhaptics/geometry/sampling.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/core/run_control.hpp>

#include <pointhaptics/geometry/kd_tree.hpp>
#include <oneapi/tbb/combinable.h>
#include <oneapi/tbb/parallel_for.h>

#include <array>
#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>

namespace pointhaptics {
namespace {

void check_spacing(double spacing, double extent) {
  if (!(spacing > 0) || !std::isfinite(spacing))
    throw Error(fmt::format("sampling: spacing must be positive and finite, got {:.3g}", spacing));
  if (extent / spacing > 2000)
    throw Error(
        fmt::format("sampling: spacing {:.3g} m is too fine for a body of {:.3g} m (more than 2000 points per axis)",
                    spacing, extent));
  // coarser than the body itself: a handful of points, or points that coincide to round-off
  if (spacing > extent)
    throw Error(fmt::format("sampling: spacing {:.3g} m is larger than the body ({:.3g} m): no interior to simulate",
                            spacing, extent));
}

// grid points spacing apart, one at `centre`, for which inside() holds
PointCloud grid_inside(const Vec3& centre, double radius, double spacing,
                       const std::function<bool(const Vec3&)>& inside) {
  const Vec3 reach = Vec3::Constant(radius);
  return lattice_inside(centre, Vec3::Constant(spacing), centre - reach, centre + reach, inside);
}

}  // namespace

PointCloud lattice_inside(const Vec3& origin, const Vec3& step, const Vec3& lo, const Vec3& hi,
                          const std::function<bool(const Vec3&)>& inside) {
  std::array<long, 3> first{}, last{};
  for (int a = 0; a < 3; ++a) {
    first[a] = static_cast<long>(std::floor((lo[a] - origin[a]) / step[a] - 1e-9));
    last[a] = static_cast<long>(std::ceil((hi[a] - origin[a]) / step[a] + 1e-9));
  }
  std::vector<Vec3> kept;
  for (long a = first[0]; a <= last[0]; ++a)
    for (long b = first[1]; b <= last[1]; ++b)
      for (long c = first[2]; c <= last[2]; ++c) {
        const Vec3 p =
            origin + Vec3(static_cast<double>(a), static_cast<double>(b), static_cast<double>(c)).cwiseProduct(step);
        if (inside(p)) kept.push_back(p);
      }
  PointCloud cloud;
  cloud.spacing = step.maxCoeff();
  cloud.X.resize(3, static_cast<Eigen::Index>(kept.size()));
  for (size_t i = 0; i < kept.size(); ++i) cloud.X.col(static_cast<Eigen::Index>(i)) = kept[i];
  // a point is on the surface when one of its 6 lattice neighbours is outside
  cloud.surface.assign(kept.size(), 0);
  for (size_t i = 0; i < kept.size(); ++i)
    for (int axis = 0; axis < 3; ++axis)
      for (int sign : {-1, 1}) {
        Vec3 q = kept[i];
        q[axis] += sign * step[axis];
        if (!inside(q)) cloud.surface[i] = 1;
      }
  return cloud;
}

Vec3 box_lattice_step(const Vec3& size, double spacing) {
  Vec3 step;
  for (int a = 0; a < 3; ++a) step[a] = size[a] / std::max(1, static_cast<int>(std::lround(size[a] / spacing)));
  return step;
}

PointCloud sample_box(const Vec3& origin, const Vec3& size, double spacing) {
  if (!(size.array() > 0).all() || !size.allFinite() || !origin.allFinite())
    throw Error("sampling: box size must be positive and finite");
  check_spacing(spacing, size.maxCoeff());
  const Vec3 step = box_lattice_step(size, spacing);
  std::array<int, 3> n{};  // points per axis
  for (int a = 0; a < 3; ++a) n[a] = static_cast<int>(std::lround(size[a] / step[a])) + 1;
  PointCloud cloud;
  cloud.spacing = spacing;
  const Eigen::Index count = static_cast<Eigen::Index>(n[0]) * n[1] * n[2];
  cloud.X.resize(3, count);
  cloud.volume.resize(count);
  cloud.surface.assign(count, 0);
  // x varies fastest: neighbours in memory are neighbours in space
  Eigen::Index p = 0;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i, ++p) {
        const std::array<int, 3> ijk{i, j, k};
        double v = 1.0;
        bool on_surface = false;
        for (int a = 0; a < 3; ++a) {
          const bool at_end = ijk[a] == 0 || ijk[a] == n[a] - 1;
          // a one-point axis (never: intervals >= 1) would own the full extent
          v *= step[a] * (at_end ? 0.5 : 1.0);
          on_surface |= at_end;
          // the last point of an axis lands exactly on the far face
          cloud.X(a, p) = ijk[a] == n[a] - 1 ? origin[a] + size[a] : origin[a] + ijk[a] * step[a];
        }
        cloud.volume[p] = v;
        cloud.surface[p] = on_surface;
      }
  return cloud;
}

Eigen::VectorXd clipped_cell_volumes(const Points& X, const std::function<bool(const Vec3&)>& inside, const Vec3& lo,
                                     const Vec3& hi, double spacing, double exact_volume, int refinement) {
  const index_t n = static_cast<index_t>(X.cols());
  Eigen::VectorXd volume = Eigen::VectorXd::Zero(n);
  if (n == 0) return volume;
  const KdTree tree(X);
  const double fine = spacing / refinement;
  std::array<int, 3> cells{};
  for (int a = 0; a < 3; ++a) cells[a] = std::max(1, static_cast<int>(std::ceil((hi[a] - lo[a]) / fine)));
  const double cell_volume = fine * fine * fine;
  // cells counted per point: whole numbers, so the threads' partial counts sum to the same whatever their
  // order (summed volumes differed from run to run in the last digit)
  tbb::combinable<std::vector<std::int64_t>> partial(
      [n] { return std::vector<std::int64_t>(static_cast<std::size_t>(n), 0); });
  Progress progress("the points' cell volumes", cells[2]);
  tbb::parallel_for(0, cells[2], [&](int k) {
    auto& local = partial.local();
    for (int j = 0; j < cells[1]; ++j) {
      throw_if_stop_requested("the points' cell volumes");
      for (int i = 0; i < cells[0]; ++i) {
        const Vec3 c = lo + fine * Vec3(i + 0.5, j + 0.5, k + 0.5);
        if (!inside(c)) continue;
        index_t nearest;
        double d2;
        tree.index().knnSearch(c.data(), 1, &nearest, &d2);
        ++local[static_cast<std::size_t>(nearest)];
      }
    }
    progress.advance();
  });
  std::vector<std::int64_t> count(static_cast<std::size_t>(n), 0);
  partial.combine_each([&](const std::vector<std::int64_t>& c) {
    for (std::size_t p = 0; p < count.size(); ++p) count[p] += c[p];
  });
  for (index_t p = 0; p < n; ++p) volume[p] = static_cast<double>(count[static_cast<std::size_t>(p)]) * cell_volume;
  const double total = volume.sum();
  if (total > 0) volume *= exact_volume / total;
  return volume;
}

PointCloud sample_sphere(const Vec3& centre, double radius, double spacing) {
  if (!(radius > 0) || !std::isfinite(radius) || !centre.allFinite())
    throw Error("sampling: sphere radius must be positive and finite");
  check_spacing(spacing, 2 * radius);
  const double r2 = radius * radius * (1 + 1e-12);
  auto inside = [&](const Vec3& p) { return (p - centre).squaredNorm() <= r2; };
  PointCloud cloud = grid_inside(centre, radius, spacing, inside);
  const Vec3 extent = Vec3::Constant(radius);
  cloud.volume = clipped_cell_volumes(cloud.X, inside, centre - extent, centre + extent, spacing,
                                      4.0 / 3.0 * std::numbers::pi * radius * radius * radius);
  return cloud;
}

PointCloud sample_half_sphere(const Vec3& centre, double radius, double spacing) {
  if (!(radius > 0) || !std::isfinite(radius) || !centre.allFinite())
    throw Error("sampling: half-sphere radius must be positive and finite");
  check_spacing(spacing, 2 * radius);
  const double r2 = radius * radius * (1 + 1e-12);
  const double floor_y = centre.y() - 1e-12 * radius;
  auto inside = [&](const Vec3& p) { return p.y() >= floor_y && (p - centre).squaredNorm() <= r2; };
  PointCloud cloud = grid_inside(centre, radius, spacing, inside);
  const Vec3 lo = centre - Vec3(radius, 0, radius), hi = centre + Vec3::Constant(radius);
  cloud.volume =
      clipped_cell_volumes(cloud.X, inside, lo, hi, spacing, 2.0 / 3.0 * std::numbers::pi * radius * radius * radius);
  return cloud;
}

}  // namespace pointhaptics
