#include <pointhaptics/object_surface.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/shape_surfaces.hpp>
#include <pointhaptics/io/mesh_file.hpp>
#include <pointhaptics/io/volume_file.hpp>

#include <pointhaptics/scene_builder.hpp>

#include <fmt/format.h>

namespace pointhaptics {
namespace {

double mean_edge(const TriangleMesh& mesh) {
  double sum = 0;
  for (const auto& f : mesh.F)
    for (int k = 0; k < 3; ++k) sum += (mesh.V.col(f[k]) - mesh.V.col(f[(k + 1) % 3])).norm();
  return mesh.F.empty() ? 0.0 : sum / (3.0 * static_cast<double>(mesh.F.size()));
}

}  // namespace

bool has_object_surface(const Scene& scene) {
  const ObjectSpec& o = scene.object;
  return o.shape != ShapeKind::FILE || !(is_point_cloud_file(o.file) || is_volume_file(o.file));
}

ObjectSurface build_object_surface(const Scene& scene, const Model& model) {
  const ObjectSpec& o = scene.object;
  const double edge = o.surface_edge > 0 ? o.surface_edge : 0.5 * o.spacing;
  ObjectSurface surface;
  switch (o.shape) {
    case ShapeKind::BOX:
      surface.mesh = box_surface(o.origin, o.size, edge);
      surface.source = fmt::format("the box's exact boundary, edge {:.3g} mm", 1e3 * edge);
      break;
    case ShapeKind::SPHERE:
      surface.mesh = sphere_surface(o.origin, o.radius, edge);
      surface.source = fmt::format("the sphere's exact boundary, edge {:.3g} mm", 1e3 * edge);
      break;
    case ShapeKind::HALF_SPHERE:
      surface.mesh = half_sphere_surface(o.origin, o.radius, edge);
      surface.source = fmt::format("the half-sphere's exact boundary, edge {:.3g} mm", 1e3 * edge);
      break;
    case ShapeKind::FILE: {
      const bool cloud = is_point_cloud_file(o.file);
      if (cloud || is_volume_file(o.file))
        throw Error(fmt::format("{}:{}: object: {} is a {}; its surface would be reconstructed, which is not implemented yet "
                                "(boxes, spheres, half-spheres and surface meshes have one)",
                                scene.path, o.line, o.file, cloud ? "point cloud" : "volume image"));
      surface.mesh = read_mesh(o.file);
      surface.source = fmt::format("the input surface {} as it is ({} triangles, mean edge {:.3g} mm; {:.3g} mm asked)", o.file,
                                   surface.mesh.F.size(), 1e3 * mean_edge(surface.mesh), 1e3 * edge);
      break;
    }
  }
  check_closed_manifold(surface.mesh, fmt::format("{}: the object's surface", scene.path));
  surface.map = build_surface_map(model, surface.mesh.V);
  return surface;
}

Points deformed_surface(const ObjectSurface& surface, const Points& u) {
  Points y;
  carry_surface(surface.map, surface.mesh.V, u, y);
  return y;
}

}  // namespace pointhaptics
