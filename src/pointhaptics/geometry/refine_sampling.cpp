#include <pointhaptics/geometry/refine_sampling.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/core/run_control.hpp>
#include <pointhaptics/geometry/kd_tree.hpp>
#include <pointhaptics/geometry/sampling.hpp>

#include <fmt/format.h>

namespace pointhaptics {

void refine_region(PointCloud& cloud, const Refinement& refinement, const std::function<bool(const Vec3&)>& inside,
                   double support) {
  const double coarse = cloud.spacing, fine = refinement.fine.spacing;
  if (!(fine > 0) || !(fine < coarse))
    throw Error(fmt::format("refine: spacing {} m must be finer than the object's {} m", fine, coarse));
  if (!cloud.held.empty() || cloud.intensity.size() > 0 || cloud.stiffness_scale.size() > 0)
    throw Error("refine: not for objects read from point-cloud or volume files");
  if (cloud.support.size() == 0) cloud.support = Eigen::VectorXd::Constant(cloud.size(), support);

  // which points come (the fine ones in the region) and which stay: the coarse ones outside it that are not
  // closer than 0.75 fine spacings to a fine one. So the seam has no gap: a band emptied of coarse points
  // around the region (half a coarse spacing first) left the seam's few points with large cells and the block
  // 3.5% softer in compression than uniformly sampled (7% without hourglass control).
  std::vector<index_t> added;
  for (index_t i = 0; i < refinement.fine.size(); ++i) {
    if (i % 4096 == 0) throw_if_stop_requested("the refinement");
    if (refinement.contains(refinement.fine.X.col(i), 1e-9 * fine)) added.push_back(i);
  }
  if (added.empty()) throw Error("refine: the region holds no point of the object");
  Points added_X(3, static_cast<index_t>(added.size()));
  for (std::size_t j = 0; j < added.size(); ++j) added_X.col(static_cast<index_t>(j)) = refinement.fine.X.col(added[j]);
  const KdTree fine_tree(added_X);
  std::vector<index_t> kept;
  for (index_t i = 0; i < cloud.size(); ++i) {
    if (i % 4096 == 0) throw_if_stop_requested("the refinement");
    if (refinement.contains(cloud.X.col(i), 1e-9 * fine)) continue;
    index_t nearest;
    double d2;
    fine_tree.index().knnSearch(cloud.X.col(i).data(), 1, &nearest, &d2);
    if (d2 >= 0.75 * 0.75 * fine * fine) kept.push_back(i);
  }
  double changed_volume = 0;  // what the removed points and the kept ones near the region stood for
  for (index_t i = 0; i < cloud.size(); ++i)
    if (refinement.contains(cloud.X.col(i), 3 * coarse)) changed_volume += cloud.volume[i];

  PointCloud out;
  out.spacing = coarse;
  const index_t n = static_cast<index_t>(kept.size() + added.size());
  out.X.resize(3, n);
  out.volume.resize(n);
  out.support.resize(n);
  out.surface.resize(static_cast<std::size_t>(n));
  std::vector<index_t> changed;
  index_t k = 0;
  for (const index_t i : kept) {
    out.X.col(k) = cloud.X.col(i);
    out.volume[k] = cloud.volume[i];
    out.support[k] = cloud.support[i];
    out.surface[static_cast<std::size_t>(k)] = cloud.surface[static_cast<std::size_t>(i)];
    if (refinement.contains(cloud.X.col(i), 3 * coarse)) changed.push_back(k);
    ++k;
  }
  for (const index_t i : added) {
    out.X.col(k) = refinement.fine.X.col(i);
    out.support[k] = support * fine / coarse;
    out.surface[static_cast<std::size_t>(k)] = refinement.fine.surface[static_cast<std::size_t>(i)];
    changed.push_back(k++);
  }

  // clipped Voronoi cells over the changed points' box (grown by a coarse spacing: their cells lie within
  // it), among every point near that box (so the cells split as they do in the whole cloud)
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const index_t i : changed) {
    lo = lo.cwiseMin(out.X.col(i));
    hi = hi.cwiseMax(out.X.col(i));
  }
  lo.array() -= coarse;
  hi.array() += coarse;
  std::vector<index_t> local;
  for (index_t i = 0; i < n; ++i)
    if (((out.X.col(i).array() >= lo.array() - coarse) && (out.X.col(i).array() <= hi.array() + coarse)).all())
      local.push_back(i);
  Points local_X(3, static_cast<index_t>(local.size()));
  for (std::size_t j = 0; j < local.size(); ++j) local_X.col(static_cast<index_t>(j)) = out.X.col(local[j]);
  const Eigen::VectorXd cells = clipped_cell_volumes(local_X, inside, lo, hi, fine, 1.0);
  std::vector<double> local_volume(static_cast<std::size_t>(n), 0.0);
  for (std::size_t j = 0; j < local.size(); ++j)
    local_volume[static_cast<std::size_t>(local[j])] = cells[static_cast<index_t>(j)];
  double sum = 0;
  for (const index_t i : changed) sum += local_volume[static_cast<std::size_t>(i)];
  if (!(sum > 0)) throw Error("refine: the region's points own no volume of the object");
  for (const index_t i : changed) out.volume[i] = local_volume[static_cast<std::size_t>(i)] * changed_volume / sum;
  cloud = std::move(out);
}

}  // namespace pointhaptics
