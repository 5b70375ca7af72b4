#pragma once
/// @file The points of the surface a tool presses on (issue 16). The contact holds the surface's vertices
/// out of the tool; a tool narrower than the surface's triangles fits between them, so it can pass through
/// a face with no vertex inside it (a 1 mm blade against a face of 3.75 mm edges went through it unfelt).
/// The contact therefore adds samples on the triangles: every edge longer than a bound gets its midpoint,
/// the triangle split in four, again until the edges are short enough (at most max_contact_sample_levels
/// times). A sample lies in one of the surface's triangles, so it is a fixed combination of at most three of
/// the surface's vertices (its barycentric weights) and is carried as that combination of their carried
/// positions: it stays on the triangle the user sees whatever the points do, and its force reaches the
/// points through those vertices' rows of the map (the same virtual work).
#include <pointhaptics/geometry/triangle_mesh.hpp>

#include <array>
#include <cstdint>
#include <vector>

namespace pointhaptics {

/// A sample: sum_k weight[k] x (surface vertex vertex[k]); the weights are >= 0 and sum to 1 (a weight of 0
/// pads a sample on an edge).
struct ContactSample {
  std::array<index_t, 3> vertex{0, 0, 0};
  std::array<double, 3> weight{0, 0, 0};
};

struct ContactSamples {
  Points Y;                            ///< the samples' reference positions (3 x samples)
  std::vector<ContactSample> samples;  ///< each over the surface's vertices
  /// For sample k: the two points it is the midpoint of, numbered the surface's vertices first, then the
  /// samples (both before it): its key (contact_sample_keys()).
  std::vector<std::array<index_t, 2>> parents;
  /// The triangles split, over the same numbering (for the vertices' and samples' shares of the area).
  std::vector<std::array<index_t, 3>> triangles;
  int levels = 0;  ///< how many times a triangle was split at most
};

/// At most this many splits: each multiplies a triangle's samples by four.
inline constexpr int max_contact_sample_levels = 3;
/// A split that would take the contact past this many vertices and samples is not made: every evaluation of
/// the contact carries and tests them all (a 1 mm tool on a 20,000-vertex surface of 2 mm edges would need
/// 320,000).
inline constexpr index_t max_contact_vertices = 250000;

/// The samples of `mesh` that split its triangles until their edges are at most `max_edge` (m) long, or as
/// close as max_contact_sample_levels splits and max_contact_vertices get; none where the edges already are,
/// or with max_edge <= 0 (then `triangles` are the mesh's own).
ContactSamples contact_samples(const TriangleMesh& mesh, double max_edge);

/// Keys that name the same sample on any part of the same surface: vertex v of the surface keeps
/// surface_ids[v] (its id on the whole surface), a sample gets a key made from its parents' keys (symmetric
/// in them, and never one of the surface's ids).
std::vector<std::uint64_t> contact_sample_keys(const std::vector<std::uint64_t>& surface_ids,
                                               const std::vector<std::array<index_t, 2>>& parents);

}  // namespace pointhaptics
