#include <pointhaptics/haptics/contact_samples.hpp>

#include <algorithm>
#include <map>
#include <utility>

namespace pointhaptics {

namespace {

/// The mean of rows a and b of `map`, merged by point (points in increasing order).
void append_mean_row(SurfaceMap& map, index_t a, index_t b, std::vector<std::pair<index_t, double>>& scratch) {
  scratch.clear();
  for (const index_t v : {a, b})
    for (index_t e = map.points.begin(v); e < map.points.end(v); ++e) scratch.emplace_back(map.points.index[e], 0.5 * map.weight[e]);
  std::sort(scratch.begin(), scratch.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  for (std::size_t k = 0; k < scratch.size(); ++k) {
    if (k > 0 && scratch[k].first == scratch[k - 1].first) {
      map.weight.back() += scratch[k].second;
      continue;
    }
    map.points.index.push_back(scratch[k].first);
    map.weight.push_back(scratch[k].second);
  }
  map.points.offset.push_back(static_cast<index_t>(map.points.index.size()));
}

double longest_edge(const Points& V, const std::array<index_t, 3>& t) {
  double longest = 0;
  for (int k = 0; k < 3; ++k) longest = std::max(longest, (V.col(t[(k + 1) % 3]) - V.col(t[k])).norm());
  return longest;
}

// splitmix64's finaliser: spreads a pair's keys over 64 bits
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

}  // namespace

ContactSamples contact_samples(const TriangleMesh& mesh, const SurfaceMap& map, double max_edge) {
  ContactSamples out{mesh, map, {}, 0};
  if (!(max_edge > 0)) return out;
  std::vector<std::pair<index_t, double>> scratch;
  std::vector<Vec3> added;  // the samples' reference positions, appended to V at the end of each level
  // an edge's (low, high) ends -> its sample, over all levels: a triangle split after its neighbour finds the
  // sample that neighbour put on their edge
  std::map<std::pair<index_t, index_t>, index_t> midpoint;
  for (int level = 0; level < max_contact_sample_levels; ++level) {
    const index_t before = static_cast<index_t>(out.mesh.V.cols());
    auto sample = [&](index_t a, index_t b) {
      const auto key = std::minmax(a, b);
      const auto [it, fresh] = midpoint.try_emplace({key.first, key.second}, before + static_cast<index_t>(added.size()));
      if (fresh) {
        added.push_back(0.5 * (out.mesh.V.col(a) + out.mesh.V.col(b)));
        out.parents.push_back({key.first, key.second});
        append_mean_row(out.map, key.first, key.second, scratch);
      }
      return it->second;
    };
    // this level's splits, counted first: a level that would pass the bound is not made
    std::size_t long_triangles = 0;
    for (const auto& t : out.mesh.F) long_triangles += longest_edge(out.mesh.V, t) > max_edge;
    if (long_triangles == 0 || before + static_cast<index_t>(3 * long_triangles) > max_contact_vertices) break;
    std::vector<std::array<index_t, 3>> split;
    split.reserve(out.mesh.F.size() + 3 * long_triangles);
    for (const auto& t : out.mesh.F) {
      if (longest_edge(out.mesh.V, t) <= max_edge) {
        split.push_back(t);
        continue;
      }
      const index_t ab = sample(t[0], t[1]), bc = sample(t[1], t[2]), ca = sample(t[2], t[0]);
      // four triangles, counter-clockwise as their parent
      split.push_back({t[0], ab, ca});
      split.push_back({ab, t[1], bc});
      split.push_back({ca, bc, t[2]});
      split.push_back({ab, bc, ca});
    }
    if (added.empty()) break;
    out.mesh.V.conservativeResize(3, before + static_cast<index_t>(added.size()));
    for (std::size_t k = 0; k < added.size(); ++k) out.mesh.V.col(before + static_cast<index_t>(k)) = added[k];
    added.clear();
    out.mesh.F = std::move(split);
    out.levels = level + 1;
  }
  return out;
}

std::vector<std::uint64_t> contact_sample_keys(const std::vector<std::uint64_t>& surface_ids,
                                               const std::vector<std::array<index_t, 2>>& parents) {
  std::vector<std::uint64_t> keys = surface_ids;
  keys.reserve(surface_ids.size() + parents.size());
  constexpr std::uint64_t sample_bit = 1ULL << 63;  // the surface's ids are below it
  for (const auto& [a, b] : parents) {
    const auto [low, high] = std::minmax(keys[static_cast<std::size_t>(a)], keys[static_cast<std::size_t>(b)]);
    keys.push_back(sample_bit | (mix(low ^ mix(high)) >> 1));
  }
  return keys;
}

}  // namespace pointhaptics
