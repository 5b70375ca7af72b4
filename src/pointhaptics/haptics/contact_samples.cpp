#include <pointhaptics/haptics/contact_samples.hpp>

#include <algorithm>
#include <unordered_map>
#include <utility>

namespace pointhaptics {

namespace {

/// The midpoint of a and b, each a combination of the surface's vertices: the mean of the two combinations.
/// Both lie in one of the surface's triangles, so the mean has at most three vertices.
ContactSample midpoint_of(const ContactSample& a, const ContactSample& b) {
  ContactSample out{{0, 0, 0}, {0, 0, 0}};
  int used = 0;
  for (const ContactSample* s : {&a, &b})
    for (int k = 0; k < 3; ++k) {
      if (s->weight[k] == 0) continue;
      int slot = 0;
      while (slot < used && out.vertex[slot] != s->vertex[k]) ++slot;
      if (slot == used) {
        if (used == 3) continue;  // (cannot happen: one triangle's vertices)
        out.vertex[used++] = s->vertex[k];
      }
      out.weight[slot] += 0.5 * s->weight[k];
    }
  for (int k = used; k < 3; ++k) out.vertex[k] = out.vertex[0];
  return out;
}

double longest_edge(const std::vector<Vec3>& V, const std::array<index_t, 3>& t) {
  double longest = 0;
  for (int k = 0; k < 3; ++k) longest = std::max(longest, (V[t[(k + 1) % 3]] - V[t[k]]).norm());
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

ContactSamples contact_samples(const TriangleMesh& mesh, double max_edge) {
  ContactSamples out;
  out.triangles = mesh.F;
  const auto n = static_cast<index_t>(mesh.V.cols());
  // every point so far, the surface's vertices first: its position and its combination of the vertices
  std::vector<Vec3> position(static_cast<std::size_t>(n));
  std::vector<ContactSample> combination(static_cast<std::size_t>(n));
  for (index_t v = 0; v < n; ++v) {
    position[static_cast<std::size_t>(v)] = mesh.V.col(v);
    combination[static_cast<std::size_t>(v)] = ContactSample{{v, v, v}, {1, 0, 0}};
  }
  // an edge's (low, high) ends -> its sample, over all levels: a triangle split after its neighbour finds the
  // sample that neighbour put on their edge
  std::unordered_map<std::uint64_t, index_t> midpoint;
  for (int level = 0; max_edge > 0 && level < max_contact_sample_levels; ++level) {
    // this level's splits, found first: a level that would pass the bound is not made
    std::vector<char> splits(out.triangles.size());
    std::size_t long_triangles = 0;
    for (std::size_t k = 0; k < out.triangles.size(); ++k)
      long_triangles += splits[k] = longest_edge(position, out.triangles[k]) > max_edge;
    const auto points = static_cast<index_t>(position.size());
    if (long_triangles == 0 || points + static_cast<index_t>(3 * long_triangles) > max_contact_vertices) break;
    midpoint.reserve(midpoint.size() + 3 * long_triangles);
    position.reserve(position.size() + 3 * long_triangles);
    combination.reserve(combination.size() + 3 * long_triangles);
    auto sample = [&](index_t a, index_t b) {
      const auto [low, high] = std::minmax(a, b);
      const std::uint64_t edge = static_cast<std::uint64_t>(low) << 32 | static_cast<std::uint32_t>(high);
      const auto [it, fresh] = midpoint.try_emplace(edge, static_cast<index_t>(position.size()));
      if (fresh) {
        position.push_back(0.5 * (position[static_cast<std::size_t>(a)] + position[static_cast<std::size_t>(b)]));
        combination.push_back(
            midpoint_of(combination[static_cast<std::size_t>(a)], combination[static_cast<std::size_t>(b)]));
        out.parents.push_back({low, high});
      }
      return it->second;
    };
    std::vector<std::array<index_t, 3>> split;
    split.reserve(out.triangles.size() + 3 * long_triangles);
    for (std::size_t k = 0; k < out.triangles.size(); ++k) {
      const auto& t = out.triangles[k];
      if (!splits[k]) {
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
    out.triangles = std::move(split);
    out.levels = level + 1;
  }
  const auto samples = static_cast<index_t>(position.size()) - n;
  out.Y.resize(3, samples);
  out.samples.assign(combination.begin() + n, combination.end());
  for (index_t k = 0; k < samples; ++k)
    out.Y.col(k) = position[static_cast<std::size_t>(n) + static_cast<std::size_t>(k)];
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
