#pragma once
/// @file An object's surface as the eye sees and the hand touches it: a closed triangle surface built from
/// the scene's object (its exact boundary for a box, sphere or half-sphere; the input surface for a mesh
/// file) and carried by the points (mechanics/surface_map.hpp).
#include <pointhaptics/core/model.hpp>
#include <pointhaptics/geometry/triangle_mesh.hpp>
#include <pointhaptics/io/scene.hpp>
#include <pointhaptics/mechanics/surface_map.hpp>

#include <string>

namespace pointhaptics {

struct ObjectSurface {
  TriangleMesh mesh;      ///< reference vertices Y and triangles, counter-clockwise seen from outside
  SurfaceMap map;         ///< y = Y + W u
  std::string source;     ///< what it was built from, for the summary ("exact box boundary, edge 3.75 mm", ...)
  index_t cut_faces = 0;  ///< the last cut_faces triangles of mesh.F are the faces of cuts (cut_surface.hpp)
  /// Several bodies (Model::body_start): body k's vertices are [body_vertex_start[k], body_vertex_start[k + 1])
  /// and its triangles [body_face_start[k], body_face_start[k + 1]), each body's surface carried by its own
  /// points only. Both empty: one body.
  std::vector<index_t> body_vertex_start, body_face_start;
};

/// Several bodies' surfaces as one (ObjectSurface::body_vertex_start): `part`, one body's, appended to `joined`
/// as its next body (its vertices, triangles and map rows after the others'; its cut faces counted). Start from
/// an empty ObjectSurface.
void append_body_surface(ObjectSurface& joined, const ObjectSurface& part);
/// Body k's surface alone out of a joined one (vertices and triangles renumbered from 0; the map's rows, over the
/// same model's points, as they are).
ObjectSurface body_surface(const ObjectSurface& joined, index_t k);

/// The surface of a solid known only by its points (a point cloud, a volume image): the half level of their
/// smoothed indicator, the kernel density phi(x) = sum_j V_j w(|x - X_j|, h_j) with the model's kernel,
/// supports and volumes (about 1 inside, 0 outside, 1/2 on a flat boundary), by marching tetrahedra over a
/// grid of `edge` (geometry/marching_tetrahedra.hpp). Throws Error if the grid would exceed `max_nodes`.
TriangleMesh reconstruct_surface(const Model& model, double edge, double max_nodes = 2e8);

/// `mesh` checked closed (Error naming `name` otherwise) and carried by `model`'s points.
ObjectSurface carried_surface(TriangleMesh mesh, std::string source, const Model& model, const std::string& name);

/// The surface of the scene's object over `model`'s points, with edges of about object.surface_edge
/// (default half the spacing): the exact boundary of a box, sphere or half-sphere; a mesh file's own
/// surface as it is (its edges may differ from the asked length: `source` says by how much); for a point
/// cloud or a volume image, reconstruct_surface() of the model's points. Throws Error naming the scene for a
/// surface that is not closed. With several [[object]] tables, every body's surface in the model's order, and
/// an Error naming the two bodies when one's surface starts inside the other's by more than a hundredth of
/// the finer spacing (a point cloud or volume image is then not yet an object: its surface would be
/// reconstructed from every body's points).
ObjectSurface build_object_surface(const Scene& scene, const Model& model);

/// The deformed surface's vertices y = Y + W u.
Points deformed_surface(const ObjectSurface& surface, const Points& u);

}  // namespace pointhaptics
