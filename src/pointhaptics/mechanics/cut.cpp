#include <pointhaptics/mechanics/cut.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/segment_crossing.hpp>
#include <pointhaptics/mechanics/energies/hourglass.hpp>
#include <pointhaptics/mechanics/stencil.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <utility>

namespace pointhaptics {

namespace {

/// The row (point i) pair e belongs to.
index_t row_of(const Csr& nbr, index_t e) {
  return static_cast<index_t>(std::upper_bound(nbr.offset.begin(), nbr.offset.end(), e) - nbr.offset.begin()) - 1;
}

}  // namespace

std::vector<index_t> pairs_crossing(const Model& model, const Points& x, const BladeSweep& sweep) {
  // a crossing pair has both ends within its length of the sweep: twice the largest support covers pairs
  // stretched to twice their reference length. With an edge reach only crossings within it of the last edge
  // count, so the box around that edge does (a trail swept since the cut began covers ever more points, of
  // which only those near the edge can cut)
  const double reach = 2.0 * (model.support.size() ? model.support.maxCoeff() : model.h);
  const bool near_edge = sweep.edge_reach != std::numeric_limits<double>::infinity();
  const std::array<Vec3, 4> corners{near_edge ? sweep.a1 : sweep.a0, near_edge ? sweep.b1 : sweep.b0, sweep.a1,
                                    sweep.b1};
  Vec3 lo = corners[0], hi = corners[0];
  for (const Vec3& c : corners) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  lo.array() -= reach + (near_edge ? sweep.edge_reach : 0.0);
  hi.array() += reach + (near_edge ? sweep.edge_reach : 0.0);
  auto inside = [&](index_t i) {
    return (x.col(i).array() >= lo.array()).all() && (x.col(i).array() <= hi.array()).all();
  };
  const Csr& nbr = model.neighbours;
  const std::array<CrossingTriangle, 2> swept{CrossingTriangle(sweep.a0, sweep.b0, sweep.b1),
                                              CrossingTriangle(sweep.a0, sweep.b1, sweep.a1)};
  std::vector<index_t> crossing;
  // (no pair leaves a body: its points' range is all the body's pairs)
  const bool one_body = sweep.body >= 0 && !model.body_start.empty();
  const index_t first = one_body ? model.body_start[static_cast<std::size_t>(sweep.body)] : 0;
  const index_t end = one_body ? model.body_start[static_cast<std::size_t>(sweep.body) + 1] : model.n_points;
  for (index_t i = first; i < end; ++i) {
    if (!inside(i)) continue;
    const Vec3 p = x.col(i);
    const std::array<double, 2> side_p{swept[0].side(p), swept[1].side(p)};
    for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) {
      const index_t j = nbr.index[e];
      if (j < i || (!model.severed.empty() && model.severed[e])) continue;
      const Vec3 q = x.col(j);
      std::optional<Vec3> at;
      for (int t = 0; t < 2 && !at; ++t) at = swept[t].crossing(p, q, side_p[t], swept[t].side(q));
      if (at && (sweep.edge_reach == std::numeric_limits<double>::infinity() ||
                 distance_to_segment(*at, sweep.a1, sweep.b1) <= sweep.edge_reach))
        crossing.push_back(e);
    }
  }
  return crossing;
}

std::vector<index_t> pairs_crossing_triangles(const Model& model, const Points& x,
                                              std::span<const std::array<Vec3, 3>> triangles) {
  // a crossing pair has both ends within its length of the triangle: in the reference configuration no pair
  // is longer than the largest support
  const double reach = model.support.size() ? model.support.maxCoeff() : model.h;
  const Csr& nbr = model.neighbours;
  std::vector<index_t> crossing;
  for (const std::array<Vec3, 3>& t : triangles) {
    const CrossingTriangle sheet(t[0], t[1], t[2]);
    const Vec3 lo = t[0].cwiseMin(t[1]).cwiseMin(t[2]).array() - reach,
               hi = t[0].cwiseMax(t[1]).cwiseMax(t[2]).array() + reach;
    for (index_t i = 0; i < model.n_points; ++i) {
      if (!((x.col(i).array() >= lo.array()).all() && (x.col(i).array() <= hi.array()).all())) continue;
      const Vec3 p = x.col(i);
      const double side_p = sheet.side(p);
      for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) {
        const index_t j = nbr.index[e];
        if (j < i || (!model.severed.empty() && model.severed[e])) continue;
        if (sheet.crossing(p, x.col(j), side_p, sheet.side(x.col(j)))) crossing.push_back(e);
      }
    }
  }
  std::sort(crossing.begin(), crossing.end());  // a pair two triangles cross, once
  crossing.erase(std::unique(crossing.begin(), crossing.end()), crossing.end());
  return crossing;
}

CutReport sever_pairs(Model& model, const std::vector<index_t>& pairs, bool keep_hourglass_diagonal) {
  const Csr& nbr = model.neighbours;
  if (model.severed.empty()) model.severed.assign(static_cast<std::size_t>(model.n_pairs()), 0);
  CutReport report;
  // the pairs to sever (both directions) and the stencils that lose them
  std::vector<index_t> newly, stencils;
  for (const index_t e : pairs) {
    if (e < 0 || e >= model.n_pairs())
      throw Error(fmt::format("cut: pair {} does not exist (the model has {})", e, model.n_pairs()));
    if (model.severed[e]) continue;
    const index_t i = row_of(nbr, e), j = nbr.index[e];
    report.severed.push_back({std::min(i, j), std::max(i, j)});
    newly.push_back(e);
    newly.push_back(model.reverse_pair[e]);
    stencils.push_back(i);
    stencils.push_back(j);
  }
  std::sort(newly.begin(), newly.end());
  newly.erase(std::unique(newly.begin(), newly.end()), newly.end());
  if (newly.empty()) return report;
  std::sort(stencils.begin(), stencils.end());
  stencils.erase(std::unique(stencils.begin(), stencils.end()), stencils.end());
  report.cut_points = stencils;
  std::sort(report.severed.begin(), report.severed.end());  // a pair given in both directions, once
  report.severed.erase(std::unique(report.severed.begin(), report.severed.end()), report.severed.end());
  // the pairs whose hourglass terms change: those of the refitted stencils (d changes) and their reverses (k
  // changes with the stencil's weight sum)
  std::vector<std::pair<index_t, index_t>> changed;
  for (const index_t i : stencils)
    for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) {
      changed.emplace_back(i, e);
      changed.emplace_back(nbr.index[e], model.reverse_pair[e]);
    }
  std::sort(changed.begin(), changed.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  changed.erase(std::unique(changed.begin(), changed.end()), changed.end());

  if (!keep_hourglass_diagonal) model.hg_diagonal.resize(0);
  const bool diagonal = model.hg_diagonal.size() == model.n_points;
  if (diagonal) add_hourglass_diagonal(model, changed, -1.0, model.hg_diagonal);
  ModelDiagnostics& diag = model.diagnostics;
  std::vector<double> w;
  auto row_weights = [&](index_t i) {
    w.resize(static_cast<std::size_t>(nbr.row_size(i)));
    for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) w[e - nbr.begin(i)] = pair_weight(model, i, e);
    return w.data();
  };
  for (const index_t i : stencils) {
    const StencilFit before = assess_stencil(model, i, row_weights(i));
    diag.regularised_neighbourhoods -= before.regularised;
    diag.isolated_points -= before.weight_sum == 0;
  }
  for (const index_t e : newly) model.severed[e] = 1;
  report.severed_pairs = static_cast<index_t>(newly.size() / 2);
  diag.severed_pairs += report.severed_pairs;
  for (const index_t i : stencils) {
    const StencilFit after = fit_stencil(model, i, row_weights(i));
    diag.regularised_neighbourhoods += after.regularised;
    diag.isolated_points += after.weight_sum == 0;
    report.regularised += after.regularised;
  }
  report.refitted_stencils = static_cast<index_t>(stencils.size());
  // the weight sums of the changed pairs' ends (every end is the first of some changed pair), each once
  std::vector<std::pair<index_t, double>> weight_sum;
  weight_sum.reserve(changed.size());
  for (const auto& [i, e] : changed) weight_sum.emplace_back(i, 0.0);
  std::sort(weight_sum.begin(), weight_sum.end());
  weight_sum.erase(std::unique(weight_sum.begin(), weight_sum.end(),
                               [](const auto& a, const auto& b) { return a.first == b.first; }),
                   weight_sum.end());
  for (auto& [i, sum] : weight_sum)
    for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) sum += pair_weight(model, i, e);
  auto sum_of = [&](index_t i) {
    return std::lower_bound(weight_sum.begin(), weight_sum.end(), i,
                            [](const auto& a, index_t b) { return a.first < b; })
        ->second;
  };
  for (const auto& [i, e] : changed)
    model.hg_coef[e] = hourglass_coefficient(model, i, e, sum_of(i), sum_of(nbr.index[e]));
  if (diagonal) add_hourglass_diagonal(model, changed, 1.0, model.hg_diagonal);
  return report;
}

double cut_area(const Model& model, index_t severed_pairs) {
  const double s = model.spacing > 0 ? model.spacing : std::cbrt(model.volume.mean());
  return static_cast<double>(severed_pairs) * 4.0 * std::pow(s, 6) / (std::numbers::pi * std::pow(model.h, 4));
}

CutReport cut(Model& model, const Points& x, std::span<const BladeSweep> sweeps, bool keep_hourglass_diagonal) {
  std::vector<index_t> pairs;
  for (const BladeSweep& sweep : sweeps) {
    const std::vector<index_t> crossing = pairs_crossing(model, x, sweep);
    pairs.insert(pairs.end(), crossing.begin(), crossing.end());  // a pair two strips cross is severed once
  }
  return sever_pairs(model, pairs, keep_hourglass_diagonal);
}

index_t connected_pieces(const Model& model, std::vector<index_t>& piece_of) {
  const Csr& nbr = model.neighbours;
  const index_t n = model.n_points;
  // union-find over the unsevered pairs, the smaller root kept so that pieces number by their lowest point
  std::vector<index_t> parent(static_cast<std::size_t>(n));
  std::iota(parent.begin(), parent.end(), index_t{0});
  auto find = [&](index_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (index_t i = 0; i < n; ++i)
    for (index_t e = nbr.begin(i); e < nbr.end(i); ++e) {
      if (!model.severed.empty() && model.severed[e]) continue;
      const index_t a = find(i), b = find(nbr.index[e]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  piece_of.assign(static_cast<std::size_t>(n), -1);
  index_t count = 0;
  for (index_t i = 0; i < n; ++i) {
    const index_t root = find(i);
    if (piece_of[root] < 0) piece_of[root] = count++;
    piece_of[i] = piece_of[root];
  }
  return count;
}

std::vector<index_t> piece_sizes(const Model& model, std::vector<index_t>& piece_of) {
  std::vector<index_t> size(static_cast<std::size_t>(connected_pieces(model, piece_of)), 0);
  for (const index_t p : piece_of) ++size[static_cast<std::size_t>(p)];
  return size;
}

}  // namespace pointhaptics
