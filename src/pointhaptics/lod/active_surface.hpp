#pragma once
/// @file The part of an object's surface that a level-of-detail active set carries (issue 16: the probe
/// touches the surface with levels of detail too). A vertex stays when the point that carries most of it in
/// the object is in the active model (selected, or in the frozen ring around them) or absorbed by a selected
/// one (so a thinned band leaves no hole); the kept vertices are
/// carried by the active model's own moving least squares (its points, with their widened supports where
/// the selection thinned them: build_surface_map), as the absorbed points follow the selected ones. The
/// triangles among kept vertices stay. The selection is centred on the contact and reaches bands beyond the
/// probe, so what is left out is far from the tool.
#include <pointhaptics/geometry/triangle_mesh.hpp>
#include <pointhaptics/lod/active_set.hpp>
#include <pointhaptics/mechanics/surface_map.hpp>

#include <limits>
#include <vector>

namespace pointhaptics {

struct ActiveSurface {
  TriangleMesh mesh;               ///< the kept vertices and the triangles among them
  SurfaceMap map;                  ///< over the active model's points (its own moving least squares)
  std::vector<index_t> vertex_of;  ///< kept vertex -> the object surface's vertex
};

/// With a tool's reach (its radius plus half its length, m), only the vertices within 2 T_r2 + 2 reach of the
/// selection's contact point (reference configuration): the probe stays within half a support of it until the
/// next selection, and a part of the whole surface (the 100k half-sphere's bands reach the whole object) made
/// the contact carry every vertex of it at each evaluation, four times the point spheres' step.
ActiveSurface restrict_surface(const TriangleMesh& mesh, const SurfaceMap& map, const ActiveSet& active,
                               double reach = std::numeric_limits<double>::infinity());

}  // namespace pointhaptics
