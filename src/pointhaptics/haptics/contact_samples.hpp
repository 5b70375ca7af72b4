#pragma once
/// @file The points of the surface a tool presses on (issue 16). The contact holds the surface's vertices
/// out of the tool; a tool narrower than the surface's triangles fits between them, so it can pass through
/// a face with no vertex inside it (the seed's 15 mm beam, surface edges of 7.5 mm under a 10 mm probe: a
/// deep press spread the vertices apart, the probe went through the top face and the loop gave energy
/// back). The contact therefore adds samples on the triangles: every edge longer than a bound gets its
/// midpoint, the triangle split in four, again until the edges are short enough (at most max_levels times).
/// A sample is carried as the mean of its edge's two ends, so it stays on the surface's triangle whatever
/// the points do: the surface seen and the one felt are the same triangles.
#include <pointhaptics/geometry/triangle_mesh.hpp>
#include <pointhaptics/mechanics/surface_map.hpp>

#include <array>
#include <cstdint>
#include <vector>

namespace pointhaptics {

struct ContactSamples {
  /// The surface's vertices first (in their order), then the samples; F the triangles split (for the
  /// vertices' shares of the area), over these vertices.
  TriangleMesh mesh;
  /// The surface's rows, then each sample's: the mean of its two ends' rows (merged by point).
  SurfaceMap map;
  /// For sample k (vertex n_surface + k): the two vertices it is the midpoint of, both before it.
  std::vector<std::array<index_t, 2>> parents;
  int levels = 0;  ///< how many times a triangle was split at most
};

/// At most this many splits: each multiplies a triangle's samples by four.
inline constexpr int max_contact_sample_levels = 3;
/// A split that would take the contact past this many vertices and samples is not made: every evaluation of
/// the contact carries and tests them all (a 1 mm tool on a 20,000-vertex surface of 2 mm edges would need
/// 320,000).
inline constexpr index_t max_contact_vertices = 250000;

/// The samples of `mesh` (carried by `map`) whose edges are at most `max_edge` (m) long, or as close as
/// max_contact_sample_levels splits and max_contact_vertices get; none where the edges already are, or with
/// max_edge <= 0.
ContactSamples contact_samples(const TriangleMesh& mesh, const SurfaceMap& map, double max_edge);

/// Keys that name the same sample on any part of the same surface: vertex v of the surface keeps
/// surface_ids[v] (its id on the whole surface), a sample gets a key made from its ends' keys (symmetric in
/// them, and never one of the surface's ids).
std::vector<std::uint64_t> contact_sample_keys(const std::vector<std::uint64_t>& surface_ids,
                                               const std::vector<std::array<index_t, 2>>& parents);

}  // namespace pointhaptics
