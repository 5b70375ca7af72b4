#pragma once
/// @file The level set of a field sampled on a regular grid as a closed triangle surface, by marching
/// tetrahedra: each grid cell split into six tetrahedra around its main diagonal (Kuhn's subdivision, the
/// same in every cell, so neighbouring cells split their shared faces alike and the surface has no cracks),
/// one or two triangles per tetrahedron the level crosses. Chosen over marching cubes for its four cases
/// instead of 256 (no ambiguous faces, no hand-copied tables), at the price of about twice the triangles.
#include <pointhaptics/geometry/triangle_mesh.hpp>

#include <array>
#include <vector>

namespace pointhaptics {

/// A field on the grid origin + cell * (i, j, k), 0 <= i < nodes[0] ..., by nodes: value(i, j, k) =
/// values[i + nodes[0] (j + nodes[1] k)].
struct GridField {
  Vec3 origin = Vec3::Zero();
  double cell = 1;
  std::array<index_t, 3> nodes{0, 0, 0};
  std::vector<double> values;

  double at(index_t i, index_t j, index_t k) const {
    const auto nx = static_cast<std::size_t>(nodes[0]), ny = static_cast<std::size_t>(nodes[1]);
    return values[static_cast<std::size_t>(i) + nx * (static_cast<std::size_t>(j) + ny * static_cast<std::size_t>(k))];
  }
};

/// The surface {field = level} between the nodes above the level ("inside") and the rest, each triangle
/// counter-clockwise seen from the outside (the side below the level). Closed when the field is below the
/// level on the grid's boundary nodes. Values equal to the level count as below it.
TriangleMesh marching_tetrahedra(const GridField& field, double level);

}  // namespace pointhaptics
