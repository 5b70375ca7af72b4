#include <pointhaptics/lod/active_set.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/kd_tree.hpp>
#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>

#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <chrono>

namespace pointhaptics {

ActiveSet build_active_set(const Model& full, const Selection& selection, const LodParams& params) {
  const auto start = std::chrono::steady_clock::now();
  if (selection.selected.empty()) throw Error("lod: the selection is empty");
  if (static_cast<index_t>(selection.band.size()) != full.n_points) throw Error("lod: the selection is for another model");
  ActiveSet a;
  const index_t n_full = full.n_points;
  a.active_of.assign(n_full, -1);
  a.follows.assign(n_full, -1);
  a.follow_offset = Points::Zero(3, n_full);
  // the simulated points: the selected ones in the bands; held points selected beyond the bands are
  // held anyway, so they join the frozen ring below where the active set reaches them, and are left out
  // elsewhere (a clamped base far from the contact costs nothing)
  for (index_t i : selection.selected)
    if (selection.band[i] >= 0) {
      a.active_of[i] = static_cast<index_t>(a.full_of.size());
      a.full_of.push_back(i);
    }
  a.n_selected = static_cast<index_t>(a.full_of.size());
  if (a.n_selected == 0) throw Error("lod: no point of the selection lies in its bands");
  const double h = full.h, reach = params.max_widening * h;
  const double candidate_radius = selection.outer_radius + reach;

  // the nearest selected point of every unselected one (a k-d tree over the selected)
  Points selected_X(3, a.n_selected);
  for (index_t k = 0; k < a.n_selected; ++k) selected_X.col(k) = full.X.col(a.full_of[k]);
  const KdTree tree(selected_X);
  std::vector<index_t> absorbed_by(n_full, -1), nearest_of(n_full, -1);
  std::vector<double> nearest_d2(n_full, 0.0);
  // the searches in parallel (each writes its own entries), the bookkeeping after, in index order
  tbb::parallel_for(tbb::blocked_range<index_t>(0, n_full, 1024), [&](const tbb::blocked_range<index_t>& range) {
    for (index_t j = range.begin(); j != range.end(); ++j) {
      if (a.active_of[j] >= 0) continue;
      if (selection.band[j] < 0 && (full.X.col(j) - selection.centre).squaredNorm() > candidate_radius * candidate_radius)
        continue;  // beyond the reach of any selected point
      tree.index().knnSearch(full.X.col(j).data(), 1, &nearest_of[j], &nearest_d2[j]);
    }
  });
  for (index_t j = 0; j < n_full; ++j) {
    const index_t nearest = nearest_of[j];
    const double d2 = nearest_d2[j];
    if (nearest < 0) continue;
    if (selection.band[j] >= 0) {
      absorbed_by[j] = nearest;  // inside the bands: absorbed by, and following, its nearest selected point
      a.follows[j] = nearest;
      a.follow_offset.col(j) = full.X.col(j) - selected_X.col(nearest);
    } else if (d2 < reach * reach) {
      a.active_of[j] = static_cast<index_t>(a.full_of.size());  // the frozen ring
      a.full_of.push_back(j);
    }
  }
  const index_t n = static_cast<index_t>(a.full_of.size());

  // the active cloud: volumes (absorbed ones added), per-point supports
  PointCloud cloud;
  cloud.spacing = full.spacing;
  cloud.X.resize(3, n);
  cloud.volume.resize(n);
  for (index_t k = 0; k < n; ++k) {
    cloud.X.col(k) = full.X.col(a.full_of[k]);
    cloud.volume[k] = full.volume[a.full_of[k]];
  }
  Eigen::VectorXd mass(n), absorbed_volume = Eigen::VectorXd::Zero(n);
  for (index_t k = 0; k < n; ++k) mass[k] = full.mass[a.full_of[k]];
  Points f_ext(3, n);
  for (index_t k = 0; k < n; ++k) f_ext.col(k) = full.f_ext.col(a.full_of[k]);
  for (index_t j = 0; j < n_full; ++j)
    if (absorbed_by[j] >= 0) {
      cloud.volume[absorbed_by[j]] += full.volume[j];
      mass[absorbed_by[j]] += full.mass[j];
      f_ext.col(absorbed_by[j]) += full.f_ext.col(j);
    }
  // widen sparse supports: the smallest h_i in steps of h/4 that reaches min_neighbours active points
  Eigen::VectorXd support = Eigen::VectorXd::Constant(n, h);
  std::vector<char> ring_needed(n, 0);
  {
    const KdTree active_tree(cloud.X);
    std::vector<std::pair<index_t, double>> found;
    nanoflann::SearchParams search;
    search.sorted = false;
    std::vector<index_t> knn_index(static_cast<std::size_t>(params.min_neighbours) + 1);
    std::vector<double> knn_d2(knn_index.size());
    for (index_t k = 0; k < a.n_selected; ++k) {
      // the distance to the needed-th nearest active point (the point itself comes first); a point never
      // needs more neighbours than it had in the full model (surface points have fewer)
      const std::size_t needed =
          static_cast<std::size_t>(std::min<index_t>(params.min_neighbours, full.neighbours.row_size(a.full_of[k]))) + 1;
      const std::size_t got = active_tree.index().knnSearch(cloud.X.col(k).data(), needed, knn_index.data(), knn_d2.data());
      if (got < needed || knn_d2[needed - 1] >= reach * reach) {
        support[k] = reach;
      } else {
        const double r = std::sqrt(knn_d2[needed - 1]);
        double hk = h;
        while (hk <= r * (1 + 1e-9) && hk < reach) hk = std::min(reach, hk + 0.25 * h);
        support[k] = hk;
      }
      a.widened += support[k] > h * (1 + 1e-12);
      // the frozen points this one reaches are the ring that holds the active set
      found.clear();
      active_tree.index().radiusSearch(cloud.X.col(k).data(), support[k] * support[k], found, search);
      for (const auto& [j, d2] : found)
        if (j >= a.n_selected) ring_needed[j] = 1;
    }
    // ... and their own neighbours, so that the ring points next to the active set have the whole
    // neighbourhood (M_i, d_ij) they have in the object; these outer ones are passive (no stencil)
    const std::vector<char> touching = ring_needed;
    for (index_t k = a.n_selected; k < n; ++k) {
      if (!touching[k]) continue;
      found.clear();
      active_tree.index().radiusSearch(cloud.X.col(k).data(), h * h, found, search);
      for (const auto& [j, d2] : found)
        if (j >= a.n_selected && !ring_needed[j]) ring_needed[j] = 2;
    }
  }
  // keep the ring the active set reaches (1), then the passive outer ring (2); drop the other candidates
  std::vector<index_t> order;
  for (char pass : {1, 2})
    for (index_t k = a.n_selected; k < n; ++k)
      if (ring_needed[k] == pass) order.push_back(k);
  for (index_t k = a.n_selected; k < n; ++k)
    if (!ring_needed[k]) a.active_of[a.full_of[k]] = -1;
  const std::vector<index_t> old_full_of = a.full_of;
  const PointCloud old_cloud = cloud;
  const Eigen::VectorXd old_mass = mass, old_support = support;
  const Points old_f_ext = f_ext;
  const index_t kept = a.n_selected + static_cast<index_t>(order.size());
  a.full_of.resize(kept);
  cloud.X.conservativeResize(3, kept);
  cloud.volume.conservativeResize(kept);
  mass.conservativeResize(kept);
  f_ext.conservativeResize(3, kept);
  support.conservativeResize(kept);
  index_t n_passive = 0;
  for (std::size_t r = 0; r < order.size(); ++r) {
    const index_t from = order[r], to = a.n_selected + static_cast<index_t>(r);
    a.full_of[to] = old_full_of[from];
    a.active_of[old_full_of[from]] = to;
    cloud.X.col(to) = old_cloud.X.col(from);
    cloud.volume[to] = old_cloud.volume[from];
    mass[to] = old_mass[from];
    f_ext.col(to) = old_f_ext.col(from);
    support[to] = old_support[from];
    n_passive += ring_needed[from] == 2;
  }
  cloud.support = support;
  MaterialParams material = full.material;
  KernelParams kernel = full.kernel;
  kernel.support = h;
  a.model = build_model(cloud, material, kernel);
  a.model.mass = mass;  // kernel-volume mode included: the region's mass is what it was
  a.model.f_ext = f_ext;
  a.model.n_passive = n_passive;
  // held points: the full model's groups (restricted), and the frozen ring held where it is
  for (index_t k = 0; k < kept; ++k)
    if (k >= a.n_selected || full.fixed[a.full_of[k]]) a.model.fixed[k] = 1;
  for (const FixedGroup& g : full.fixed_groups) {
    FixedGroup sub = g;
    sub.points.clear();
    for (index_t i : g.points)
      if (a.active_of[i] >= 0) sub.points.push_back(a.active_of[i]);
    if (!sub.points.empty()) a.model.fixed_groups.push_back(sub);
  }
  a.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return a;
}

State ActiveSet::restrict_state(const State& full) const {
  State s;
  const index_t n = static_cast<index_t>(full_of.size());
  s.u.resize(3, n);
  s.velocity.resize(3, n);
  for (index_t k = 0; k < n; ++k) {
    s.u.col(k) = full.u.col(full_of[k]);
    s.velocity.col(k) = k < n_selected ? Vec3(full.velocity.col(full_of[k])) : Vec3::Zero();  // the ring is held
  }
  s.time = full.time;
  return s;
}

void ActiveSet::prolong_state(const State& active, State& full) const {
  // the ring too: its held points with a prescribed displacement moved with it
  for (index_t k = 0; k < static_cast<index_t>(full_of.size()); ++k) {
    full.u.col(full_of[k]) = active.u.col(k);
    full.velocity.col(full_of[k]) = active.velocity.col(k);
  }
  // first-order MLS from the followed point: exact for any affine field. Each selected point's gradients
  // once (a point has several followers), into buffers kept for the next call
  gradient_cache_.resize(2 * static_cast<std::size_t>(n_selected));
  tbb::parallel_for(tbb::blocked_range<index_t>(0, n_selected, 256), [&](const tbb::blocked_range<index_t>& range) {
    for (index_t k = range.begin(); k != range.end(); ++k) {
      gradient_cache_[2 * k] = displacement_gradient(model, active.u, k);
      gradient_cache_[2 * k + 1] = displacement_gradient(model, active.velocity, k);
    }
  });
  for (index_t j = 0; j < static_cast<index_t>(follows.size()); ++j) {
    const index_t k = follows[j];
    if (k < 0) {
      // not simulated: it stays where it was left, at rest. A velocity kept from when it was last simulated
      // would come back when a later selection takes it in again: energy from nowhere (issue 21)
      if (active_of[j] < 0) full.velocity.col(j).setZero();
      continue;
    }
    const Vec3 dX = follow_offset.col(j);
    full.u.col(j) = active.u.col(k) + gradient_cache_[2 * k] * dX;
    full.velocity.col(j) = active.velocity.col(k) + gradient_cache_[2 * k + 1] * dX;
  }
  full.time = active.time;
}

}  // namespace pointhaptics
