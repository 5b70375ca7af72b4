#pragma once
/// @file Bringing an input surface mesh to about the asked edge length: split when far coarser, simplified
/// by vertex clustering when far finer, the change reported; a simplification that would not stay closed
/// and faithful is not made.
#include <pointhaptics/geometry/triangle_mesh.hpp>

#include <string>

namespace pointhaptics {

/// Each triangle split into four at its edges' midpoints (shared midpoints: a closed mesh stays closed; the
/// surface itself does not change).
TriangleMesh subdivide(const TriangleMesh& mesh);

/// Vertex clustering (Rossignac and Borrel): vertices in the same cube of side `cell` merged into the one
/// nearest their mean,
/// triangles left without area dropped, as are pairs of triangles on the same three vertices. May leave a
/// non-manifold or open result where a part is thinner than a cell: check it.
TriangleMesh cluster_vertices(const TriangleMesh& mesh, double cell);

/// The mean edge length of the mesh's triangles.
double mean_edge_length(const TriangleMesh& mesh);

struct Remeshed {
  TriangleMesh mesh;
  std::string change;  ///< what was done, for the summary ("kept", "split twice: ...", ...)
};

/// `mesh` (closed) at about `edge`: split while its mean edge exceeds 2 edge (up to four million triangles); clustered at `edge` when its
/// mean edge is below edge / 4, kept only if the result is closed and manifold and encloses the same volume
/// to 2.5% (else the input is kept, and `change` says why); else as it is.
Remeshed adapt_to_edge(const TriangleMesh& mesh, double edge);

}  // namespace pointhaptics
