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
  TriangleMesh mesh;   ///< reference vertices Y and triangles, counter-clockwise seen from outside
  SurfaceMap map;      ///< y = Y + W u
  std::string source;  ///< what it was built from, for the summary ("exact box boundary, edge 3.75 mm", ...)
};

/// Whether the scene's object has a surface (a box, sphere, half-sphere or surface mesh; point clouds and
/// volume images not yet).
bool has_object_surface(const Scene& scene);

/// The surface of the scene's object over `model`'s points, with edges of about object.surface_edge
/// (default half the spacing). A mesh file's own surface is kept as it is (its edges may differ from the
/// asked length: `source` says by how much). Point clouds and volume images have no surface yet: an Error
/// says so. Throws Error naming the scene for a surface that is not closed.
ObjectSurface build_object_surface(const Scene& scene, const Model& model);

/// The deformed surface's vertices y = Y + W u.
Points deformed_surface(const ObjectSurface& surface, const Points& u);

}  // namespace pointhaptics
