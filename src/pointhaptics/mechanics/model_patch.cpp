#include <pointhaptics/mechanics/model_patch.hpp>

#include <pointhaptics/core/error.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>

namespace pointhaptics {

std::vector<index_t> neighbourhood(const Model& model, const std::vector<index_t>& seeds, int rings) {
  std::vector<char> in(static_cast<std::size_t>(model.n_points), 0);
  std::vector<index_t> found, front;
  for (const index_t i : seeds) {
    if (i < 0 || i >= model.n_points) throw Error(fmt::format("model patch: point {} of {}", i, model.n_points));
    if (!in[static_cast<std::size_t>(i)]) in[static_cast<std::size_t>(i)] = 1, front.push_back(i);
  }
  found = front;
  for (int ring = 0; ring < rings; ++ring) {
    std::vector<index_t> next;
    for (const index_t i : front)
      for (index_t e = model.neighbours.begin(i); e < model.neighbours.end(i); ++e) {
        const index_t j = model.neighbours.index[e];
        if (!in[static_cast<std::size_t>(j)]) in[static_cast<std::size_t>(j)] = 1, next.push_back(j);
      }
    found.insert(found.end(), next.begin(), next.end());
    front = std::move(next);
  }
  std::sort(found.begin(), found.end());
  return found;
}

ModelPatch model_patch(const Model& model, const std::vector<index_t>& free, int held_rings) {
  if (held_rings < 2) throw Error(fmt::format("model patch: {} held rings (at least 2)", held_rings));
  const std::vector<index_t> inner = neighbourhood(model, free, 0);
  // two rings at least: a free point's force comes from the stencils that reach it (one ring), and their hourglass
  // pairs (energies/hourglass.hpp) reach one ring further. The outer ring is passive (Model::n_passive): its
  // stencils hold no free point, and its pairs' terms reach the free points only through the inner ring's
  // gradients, which the inner ring's own stencils carry (a pair's energy is charged from both ends). Each ring
  // is grown from the last (no search is made twice)
  std::vector<std::vector<index_t>> within{inner};  // within[k]: the points at most k rings from the free ones
  for (int ring = 1; ring <= held_rings; ++ring) within.push_back(neighbourhood(model, within.back(), 1));
  ModelPatch patch;
  patch.n_free = static_cast<index_t>(inner.size());
  patch.full_of = inner;
  std::vector<index_t> patch_of(static_cast<std::size_t>(model.n_points), -1);
  for (std::size_t k = 0; k < inner.size(); ++k) patch_of[static_cast<std::size_t>(inner[k])] = static_cast<index_t>(k);
  std::vector<index_t> part_end{patch.n_free};  // the free points, then each ring, each in the model's order
  for (int ring = 1; ring <= held_rings; ++ring) {
    for (const index_t i : within[static_cast<std::size_t>(ring)])
      if (patch_of[static_cast<std::size_t>(i)] < 0) {
        patch_of[static_cast<std::size_t>(i)] = static_cast<index_t>(patch.full_of.size());
        patch.full_of.push_back(i);
      }
    part_end.push_back(static_cast<index_t>(patch.full_of.size()));
  }
  patch.ring_end.assign(part_end.begin() + 1, part_end.end());
  const index_t n = static_cast<index_t>(patch.full_of.size());
  Model& m = patch.model;
  m.n_points = n;
  m.n_passive = part_end[part_end.size() - 1] - part_end[part_end.size() - 2];
  m.spacing = model.spacing;
  m.h = model.h;
  m.extent = model.extent;
  m.kernel = model.kernel;
  m.material = model.material;
  m.lambda = model.lambda;
  m.mu = model.mu;
  m.point_materials = model.point_materials;
  auto rows = [&](const Eigen::VectorXd& v) {
    if (v.size() != model.n_points) return Eigen::VectorXd();
    Eigen::VectorXd out(n);
    for (index_t k = 0; k < n; ++k) out[k] = v[patch.full_of[static_cast<std::size_t>(k)]];
    return out;
  };
  auto columns = [&](const Points& p) {
    Points out(3, n);
    for (index_t k = 0; k < n; ++k) out.col(k) = p.col(patch.full_of[static_cast<std::size_t>(k)]);
    return out;
  };
  m.X = columns(model.X);
  m.d_self = columns(model.d_self);
  m.f_ext = model.f_ext.cols() == model.n_points ? columns(model.f_ext) : Points::Zero(3, n);
  m.volume = rows(model.volume);
  m.mass = rows(model.mass);
  m.support = rows(model.support);
  m.stiffness_scale = rows(model.stiffness_scale);
  m.stiffness_volume = rows(model.stiffness_volume);
  m.hg_diagonal = rows(model.hg_diagonal);
  m.fixed.assign(static_cast<std::size_t>(n), 1);
  for (index_t k = 0; k < patch.n_free; ++k)
    m.fixed[static_cast<std::size_t>(k)] =
        model.fixed[static_cast<std::size_t>(patch.full_of[static_cast<std::size_t>(k)])];
  if (!model.material_of.empty())
    for (const index_t i : patch.full_of) m.material_of.push_back(model.material_of[static_cast<std::size_t>(i)]);
  // the pairs within the patch, each row sorted by the patch's index: the free points and each ring are numbered
  // in the model's order, so a row (in the model's order) is sorted by taking its free neighbours, then its first
  // ring's, and so on
  auto part_of = [&](index_t k) {
    return static_cast<std::size_t>(std::upper_bound(part_end.begin(), part_end.end(), k) - part_end.begin());
  };
  std::vector<index_t> pair_of;  // patch pair -> the model's
  m.neighbours.offset.assign(1, 0);
  m.neighbours.index.reserve(static_cast<std::size_t>(n) *
                             static_cast<std::size_t>(model.neighbours.row_size(patch.full_of[0]) + 1));
  // (patch neighbour, model pair) per part of a row
  std::vector<std::vector<std::array<index_t, 2>>> parts(part_end.size());
  for (index_t k = 0; k < n; ++k) {
    const index_t i = patch.full_of[static_cast<std::size_t>(k)];
    for (index_t e = model.neighbours.begin(i); e < model.neighbours.end(i); ++e)
      if (const index_t l = patch_of[static_cast<std::size_t>(model.neighbours.index[e])]; l >= 0)
        parts[part_of(l)].push_back({l, e});
    for (std::vector<std::array<index_t, 2>>& part : parts) {
      for (const auto& [l, e] : part) {
        m.neighbours.index.push_back(l);
        pair_of.push_back(e);
      }
      part.clear();
    }
    m.neighbours.offset.push_back(static_cast<index_t>(m.neighbours.index.size()));
  }
  const index_t pairs = static_cast<index_t>(pair_of.size());
  m.d.resize(3, pairs);
  m.hg_coef.resize(model.hg_coef.size() == model.n_pairs() ? pairs : 0);
  m.reverse_pair.resize(static_cast<std::size_t>(pairs));
  if (!model.severed.empty()) m.severed.resize(static_cast<std::size_t>(pairs));
  for (index_t p = 0; p < pairs; ++p) {
    const index_t e = pair_of[static_cast<std::size_t>(p)];
    m.d.col(p) = model.d.col(e);
    if (m.hg_coef.size()) m.hg_coef[p] = model.hg_coef[e];
    if (!m.severed.empty()) m.severed[static_cast<std::size_t>(p)] = model.severed[static_cast<std::size_t>(e)];
  }
  // a pair's reverse: the rows are sorted and the neighbourhoods symmetric, so going through the rows in order,
  // the next unvisited entry of row l is k's (a cursor per row, not an array over the model's pairs per call)
  std::vector<index_t> cursor(m.neighbours.offset.begin(), m.neighbours.offset.end() - 1);
  for (index_t k = 0; k < n; ++k)
    for (index_t p = m.neighbours.begin(k); p < m.neighbours.end(k); ++p)
      m.reverse_pair[static_cast<std::size_t>(p)] = cursor[static_cast<std::size_t>(m.neighbours.index[p])]++;
  return patch;
}

}  // namespace pointhaptics
