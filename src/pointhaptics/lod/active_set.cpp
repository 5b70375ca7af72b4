#include <pointhaptics/lod/active_set.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/kd_tree.hpp>
#include <pointhaptics/mechanics/deformation.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>

#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace pointhaptics {

namespace {

// The active points before the model is built: their cloud (volumes with the absorbed ones added), masses,
// loads and supports, one column per active point (selected first, then the ring's candidates).
struct ActiveCloud {
  PointCloud cloud;
  Eigen::VectorXd mass, support;
  Points f_ext;
};

// Phase 1, the simulated points: the selected ones in the bands. Held points selected beyond the bands are
// held anyway, so they join the frozen ring (phase 2) where the active set reaches them, and are left out
// elsewhere (a clamped base far from the contact costs nothing).
void take_selected(const Selection& selection, ActiveSet& a) {
  for (index_t i : selection.selected)
    if (selection.band[i] >= 0) {
      a.active_of[i] = static_cast<index_t>(a.full_of.size());
      a.full_of.push_back(i);
    }
  a.n_selected = static_cast<index_t>(a.full_of.size());
  if (a.n_selected == 0) throw Error("lod: no point of the selection lies in its bands");
}

// How many selected points an absorbed point's displacement is blended from (the nearest of them absorbs it).
constexpr int followed_count = 5;

// Phase 2, every unselected point by its nearest selected ones (a k-d tree over the selected): inside the
// bands it is absorbed by the nearest and follows the nearest few (ActiveSet::followed); beyond them, within
// the widest support, it is a candidate for the frozen ring. Returns, per object point, the selected point
// that absorbs it (-1: none).
std::vector<index_t> absorb_and_find_ring(const Model& full, const Selection& selection, const LodParams& params,
                                          ActiveSet& a) {
  const index_t n_full = full.n_points;
  const double reach = params.max_widening * full.h;
  const double candidate_radius = selection.outer_radius + reach;
  Points selected_X(3, a.n_selected);
  for (index_t k = 0; k < a.n_selected; ++k) selected_X.col(k) = full.X.col(a.full_of[k]);
  const KdTree tree(selected_X);
  constexpr std::size_t m = followed_count;
  std::vector<index_t> nearest_of(m * static_cast<std::size_t>(n_full), -1);
  std::vector<double> nearest_d2(m * static_cast<std::size_t>(n_full), 0.0);
  std::vector<unsigned char> found(static_cast<std::size_t>(n_full), 0);
  // the searches in parallel (each writes its own entries), the bookkeeping after, in index order
  tbb::parallel_for(tbb::blocked_range<index_t>(0, n_full, 1024), [&](const tbb::blocked_range<index_t>& range) {
    for (index_t j = range.begin(); j != range.end(); ++j) {
      if (a.active_of[j] >= 0) continue;
      if (selection.band[j] < 0 &&
          (full.X.col(j) - selection.centre).squaredNorm() > candidate_radius * candidate_radius)
        continue;  // beyond the reach of any selected point
      const std::size_t at = m * static_cast<std::size_t>(j);
      found[j] = static_cast<unsigned char>(tree.index().knnSearch(full.X.col(j).data(), selection.band[j] >= 0 ? m : 1,
                                                                   &nearest_of[at], &nearest_d2[at]));
    }
  });
  std::vector<index_t> absorbed_by(n_full, -1);
  a.followed.offset.assign(static_cast<std::size_t>(n_full) + 1, 0);
  for (index_t j = 0; j < n_full; ++j) {
    const std::size_t at = m * static_cast<std::size_t>(j);
    if (found[j] > 0 && selection.band[j] >= 0) {
      absorbed_by[j] = nearest_of[at];
      // weights (1 - r / r_m)^2 within the distance r_m to the last one found: they fall to zero there, so
      // the blend changes continuously from point to point (a point's nearest selected one alone jumps
      // between neighbours that follow different points, and with their gradients told apart by the
      // dynamics a neighbourhood of followers could come out inverted, to start inverted when a later
      // selection simulates it)
      const auto follow = [&](index_t k, double w) {
        a.followed.index.push_back(k);
        a.followed_weight.push_back(w);
        a.followed_offset.push_back(full.X.col(j) - selected_X.col(k));
      };
      const double r_last = std::sqrt(nearest_d2[at + found[j] - 1]);
      double sum = 0;
      const std::size_t first = a.followed_weight.size();
      for (std::size_t q = 0; q < found[j]; ++q) {
        const double w = r_last > 0 ? std::pow(1 - std::sqrt(nearest_d2[at + q]) / r_last, 2) : 0.0;
        if (w <= 0) continue;
        follow(nearest_of[at + q], w);
        sum += w;
      }
      if (sum > 0) {
        for (std::size_t e = first; e < a.followed_weight.size(); ++e) a.followed_weight[e] /= sum;
      } else {  // as far from each: the nearest alone
        follow(nearest_of[at], 1.0);
      }
    } else if (found[j] > 0 && nearest_d2[at] < reach * reach) {
      a.active_of[j] = static_cast<index_t>(a.full_of.size());  // a ring candidate
      a.full_of.push_back(j);
    }
    a.followed.offset[static_cast<std::size_t>(j) + 1] = a.followed.n_entries();
  }
  return absorbed_by;
}

// Phase 3, the active points' cloud: each keeps its own volume, mass and load and adds those of the points
// it absorbs (the active set keeps the region's mass and load).
ActiveCloud gather_cloud(const Model& full, const ActiveSet& a, const std::vector<index_t>& absorbed_by) {
  const index_t n = static_cast<index_t>(a.full_of.size());
  ActiveCloud c;
  c.cloud.spacing = full.spacing;
  c.cloud.X.resize(3, n);
  c.cloud.volume.resize(n);
  c.mass.resize(n);
  c.f_ext.resize(3, n);
  for (index_t k = 0; k < n; ++k) {
    c.cloud.X.col(k) = full.X.col(a.full_of[k]);
    c.cloud.volume[k] = full.volume[a.full_of[k]];
    c.mass[k] = full.mass[a.full_of[k]];
    c.f_ext.col(k) = full.f_ext.col(a.full_of[k]);
  }
  for (index_t j = 0; j < full.n_points; ++j)
    if (absorbed_by[j] >= 0) {
      c.cloud.volume[absorbed_by[j]] += full.volume[j];
      c.mass[absorbed_by[j]] += full.mass[j];
      c.f_ext.col(absorbed_by[j]) += full.f_ext.col(j);
    }
  c.support = Eigen::VectorXd::Constant(n, full.h);
  return c;
}

// Phase 4, sparse supports widened: the smallest h_i in steps of h/4 that reaches min_neighbours active
// points (never more than the point had in the object; at most max_widening h). Returns per active point
// whether the ring is needed there: 1 for ring points a selected point's support reaches, 2 for their own
// neighbours (passive: neighbours only, so that the ring points next to the active set have the whole
// neighbourhood, M_i and d_ij, they have in the object), 0 for candidates not needed.
std::vector<char> widen_supports(const Model& full, const LodParams& params, ActiveSet& a, ActiveCloud& c) {
  const index_t n = static_cast<index_t>(a.full_of.size());
  const double h = full.h, reach = params.max_widening * h;
  std::vector<char> ring_needed(n, 0);
  const KdTree active_tree(c.cloud.X);
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
    const std::size_t got =
        active_tree.index().knnSearch(c.cloud.X.col(k).data(), needed, knn_index.data(), knn_d2.data());
    if (got < needed || knn_d2[needed - 1] >= reach * reach) {
      c.support[k] = reach;
    } else {
      const double r = std::sqrt(knn_d2[needed - 1]);
      double hk = h;
      while (hk <= r * (1 + 1e-9) && hk < reach) hk = std::min(reach, hk + 0.25 * h);
      c.support[k] = hk;
    }
    a.widened += c.support[k] > h * (1 + 1e-12);
    found.clear();
    active_tree.index().radiusSearch(c.cloud.X.col(k).data(), c.support[k] * c.support[k], found, search);
    for (const auto& [j, d2] : found)
      if (j >= a.n_selected) ring_needed[j] = 1;
  }
  const std::vector<char> touching = ring_needed;
  for (index_t k = a.n_selected; k < n; ++k) {
    if (!touching[k]) continue;
    found.clear();
    active_tree.index().radiusSearch(c.cloud.X.col(k).data(), h * h, found, search);
    for (const auto& [j, d2] : found)
      if (j >= a.n_selected && !ring_needed[j]) ring_needed[j] = 2;
  }
  return ring_needed;
}

// Phase 5, the ring kept: the points the active set reaches (1), then the passive outer ring (2), in that
// order after the selected points; the other candidates dropped. Returns the number of passive points.
index_t keep_needed_ring(const std::vector<char>& ring_needed, ActiveSet& a, ActiveCloud& c) {
  const index_t n = static_cast<index_t>(a.full_of.size());
  std::vector<index_t> order;
  for (char pass : {1, 2})
    for (index_t k = a.n_selected; k < n; ++k)
      if (ring_needed[k] == pass) order.push_back(k);
  for (index_t k = a.n_selected; k < n; ++k)
    if (!ring_needed[k]) a.active_of[a.full_of[k]] = -1;
  const std::vector<index_t> old_full_of = a.full_of;
  const ActiveCloud old = c;
  const index_t kept = a.n_selected + static_cast<index_t>(order.size());
  a.full_of.resize(kept);
  c.cloud.X.conservativeResize(3, kept);
  c.cloud.volume.conservativeResize(kept);
  c.mass.conservativeResize(kept);
  c.f_ext.conservativeResize(3, kept);
  c.support.conservativeResize(kept);
  index_t n_passive = 0;
  for (std::size_t r = 0; r < order.size(); ++r) {
    const index_t from = order[r], to = a.n_selected + static_cast<index_t>(r);
    a.full_of[to] = old_full_of[from];
    a.active_of[old_full_of[from]] = to;
    c.cloud.X.col(to) = old.cloud.X.col(from);
    c.cloud.volume[to] = old.cloud.volume[from];
    c.mass[to] = old.mass[from];
    c.f_ext.col(to) = old.f_ext.col(from);
    c.support[to] = old.support[from];
    n_passive += ring_needed[from] == 2;
  }
  return n_passive;
}

// Phase 6, the active model: built from the cloud like any model, with the region's masses and loads, the
// ring held where it is, and the object's held groups restricted to the active points.
void build_model_of(const Model& full, ActiveCloud& c, index_t n_passive, ActiveSet& a) {
  c.cloud.support = c.support;
  if (full.stiffness_scale.size()) {  // the object's stiffness map, for the active points
    c.cloud.stiffness_scale.resize(static_cast<Eigen::Index>(a.full_of.size()));
    for (std::size_t k = 0; k < a.full_of.size(); ++k)
      c.cloud.stiffness_scale[static_cast<Eigen::Index>(k)] = full.stiffness_scale[a.full_of[k]];
  }
  KernelParams kernel = full.kernel;
  kernel.support = full.h;
  std::vector<std::uint8_t> material_of;  // the object's per-point materials, for the active points
  if (!full.material_of.empty())
    for (const index_t i : a.full_of) material_of.push_back(full.material_of[i]);
  a.model = build_model(c.cloud, full.material, kernel, full.point_materials, std::move(material_of));
  a.model.mass = c.mass;  // kernel-volume mode included: the region's mass is what it was
  a.model.f_ext = c.f_ext;
  a.model.n_passive = n_passive;
  const index_t kept = static_cast<index_t>(a.full_of.size());
  for (index_t k = 0; k < kept; ++k)
    if (k >= a.n_selected || full.fixed[a.full_of[k]]) a.model.fixed[k] = 1;
  for (const FixedGroup& g : full.fixed_groups) {
    FixedGroup sub = g;
    sub.points.clear();
    for (index_t i : g.points)
      if (a.active_of[i] >= 0) sub.points.push_back(a.active_of[i]);
    if (!sub.points.empty()) a.model.fixed_groups.push_back(sub);
  }
}

}  // namespace

ActiveSet build_active_set(const Model& full, const Selection& selection, const LodParams& params) {
  const auto start = std::chrono::steady_clock::now();
  if (selection.selected.empty()) throw Error("lod: the selection is empty");
  if (static_cast<index_t>(selection.band.size()) != full.n_points)
    throw Error("lod: the selection is for another model");
  ActiveSet a;
  a.active_of.assign(full.n_points, -1);
  a.centre = selection.centre;
  a.core_radius = selection.core_radius;
  take_selected(selection, a);
  const std::vector<index_t> absorbed_by = absorb_and_find_ring(full, selection, params, a);
  ActiveCloud cloud = gather_cloud(full, a, absorbed_by);
  const std::vector<char> ring_needed = widen_supports(full, params, a, cloud);
  const index_t n_passive = keep_needed_ring(ring_needed, a, cloud);
  build_model_of(full, cloud, n_passive, a);
  a.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return a;
}

CutReport cut_as_object(ActiveSet& a, const Model& full, std::span<const std::array<Vec3, 3>> sheets,
                        bool keep_hourglass_diagonal) {
  std::vector<index_t> pairs = pairs_crossing_triangles(a.model, a.model.X, sheets);
  if (!full.severed.empty()) {
    // the object's points that lost a pair; an active pair between two of them is looked up in the object
    const Csr& object = full.neighbours;
    std::vector<char> lost(static_cast<std::size_t>(full.n_points), 0);
    for (index_t i = 0; i < full.n_points; ++i)
      for (index_t e = object.begin(i); e < object.end(i) && !lost[i]; ++e) lost[i] = full.severed[e];
    const Csr& nbr = a.model.neighbours;
    for (index_t k = 0; k < a.model.n_points; ++k) {
      const index_t i = a.full_of[k];
      if (!lost[i]) continue;
      for (index_t e = nbr.begin(k); e < nbr.end(k); ++e) {
        const index_t j = a.full_of[nbr.index[e]];
        if (nbr.index[e] < k || !lost[j]) continue;
        for (index_t f = object.begin(i); f < object.end(i); ++f)
          if (object.index[f] == j) {
            if (full.severed[f]) pairs.push_back(e);
            break;
          }
      }
    }
  }
  if (pairs.empty()) return {};
  return sever_pairs(a.model, pairs, keep_hourglass_diagonal);
}

State ActiveSet::restrict_state(const State& full) const {
  State s;
  const index_t n = static_cast<index_t>(full_of.size());
  s.u.resize(3, n);
  s.velocity.resize(3, n);
  s.viscous.resize(full.viscous.rows(), full.viscous.rows() ? n : 0);
  for (index_t k = 0; k < n; ++k) {
    s.u.col(k) = full.u.col(full_of[k]);
    if (s.viscous.rows()) s.viscous.col(k) = full.viscous.col(full_of[k]);  // the history of a point goes with it
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
    if (full.viscous.rows() && full.viscous.rows() == active.viscous.rows())
      full.viscous.col(full_of[k]) = active.viscous.col(k);
  }
  // first-order MLS from each followed point, blended: exact for any affine field. Each selected point's gradients
  // once (a point has several followers), into buffers kept for the next call
  gradient_cache_.resize(2 * static_cast<std::size_t>(n_selected));
  tbb::parallel_for(tbb::blocked_range<index_t>(0, n_selected, 256), [&](const tbb::blocked_range<index_t>& range) {
    for (index_t k = range.begin(); k != range.end(); ++k) {
      gradient_cache_[2 * k] = displacement_gradient(model, active.u, k);
      gradient_cache_[2 * k + 1] = displacement_gradient(model, active.velocity, k);
    }
  });
  for (index_t j = 0; j < followed.n_rows(); ++j) {
    if (followed.row_size(j) == 0) {
      // not simulated: it stays where it was left, at rest. A velocity kept from when it was last simulated
      // would come back when a later selection takes it in again: energy from nowhere (issue 21)
      if (active_of[j] < 0) full.velocity.col(j).setZero();
      continue;
    }
    Vec3 u = Vec3::Zero(), v = Vec3::Zero();
    for (index_t e = followed.begin(j); e < followed.end(j); ++e) {
      const index_t k = followed.index[e];
      const double w = followed_weight[static_cast<std::size_t>(e)];
      const Vec3& dX = followed_offset[static_cast<std::size_t>(e)];
      u += w * (active.u.col(k) + gradient_cache_[2 * k] * dX);
      v += w * (active.velocity.col(k) + gradient_cache_[2 * k + 1] * dX);
    }
    full.u.col(j) = u;
    full.velocity.col(j) = v;
  }
  full.time = active.time;
}

}  // namespace pointhaptics
