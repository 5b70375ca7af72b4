#include <pointhaptics/object_surface.hpp>

#include <pointhaptics/core/run_control.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/marching_tetrahedra.hpp>
#include <pointhaptics/geometry/remesh.hpp>
#include <pointhaptics/geometry/shape_surfaces.hpp>
#include <pointhaptics/io/mesh_file.hpp>
#include <pointhaptics/io/volume_file.hpp>
#include <pointhaptics/mechanics/kernels.hpp>

#include <pointhaptics/scene_builder.hpp>

#include <fmt/format.h>

#include <cmath>

namespace pointhaptics {

TriangleMesh reconstruct_surface(const Model& model, double edge, double max_nodes) {
  if (!(edge > 0) || !std::isfinite(edge))
    throw Error(fmt::format("surface reconstruction: the grid edge must be > 0 (m), got {}", edge));
  const bool own_support = model.support.size() == model.n_points;
  const double h_max = own_support ? model.support.maxCoeff() : model.h;
  // the grid covers the points' supports and one cell more, so the field is 0 on its boundary (closed)
  const Vec3 lo = model.X.rowwise().minCoeff() - Vec3::Constant(h_max + edge);
  const Vec3 hi = model.X.rowwise().maxCoeff() + Vec3::Constant(h_max + edge);
  GridField field;
  field.origin = lo;
  field.cell = edge;
  double total = 1;
  for (int a = 0; a < 3; ++a) total *= std::ceil((hi[a] - lo[a]) / edge) + 1;
  if (!(total <= max_nodes))
    throw Error(
        fmt::format("surface reconstruction: a {:.3g} m grid over the object needs {:.3g} nodes (at most {:.3g}); a "
                    "coarser surface_edge",
                    edge, total, max_nodes));
  for (int a = 0; a < 3; ++a)
    field.nodes[static_cast<std::size_t>(a)] = static_cast<index_t>(std::ceil((hi[a] - lo[a]) / edge)) + 1;
  field.values.assign(static_cast<std::size_t>(total), 0.0);
  const index_t nx = field.nodes[0], ny = field.nodes[1];
  // each point adds its share V_j w(r, h_j) to the nodes within its support
  for (index_t j = 0; j < model.n_points; ++j) {
    throw_if_stop_requested("the surface reconstruction");
    const double h = own_support ? model.support[j] : model.h;
    const Vec3 x = model.X.col(j);
    index_t first[3], last[3];
    for (int a = 0; a < 3; ++a) {
      first[a] = std::max<index_t>(0, static_cast<index_t>(std::ceil((x[a] - h - lo[a]) / edge)));
      last[a] = std::min<index_t>(field.nodes[static_cast<std::size_t>(a)] - 1,
                                  static_cast<index_t>(std::floor((x[a] + h - lo[a]) / edge)));
    }
    for (index_t k = first[2]; k <= last[2]; ++k)
      for (index_t jj = first[1]; jj <= last[1]; ++jj)
        for (index_t i = first[0]; i <= last[0]; ++i) {
          const double r =
              (lo + edge * Vec3(static_cast<double>(i), static_cast<double>(jj), static_cast<double>(k)) - x).norm();
          // the viscosity kernel is infinite at r = 0: a node on a point takes it a little off
          if (r < h)
            field.values[static_cast<std::size_t>(i + nx * (jj + ny * k))] +=
                model.volume[j] * kernel_value(model.kernel.type, std::max(r, 1e-3 * h), h);
        }
  }
  return marching_tetrahedra(field, 0.5);
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
      if (cloud || is_volume_file(o.file)) {
        surface.mesh = reconstruct_surface(model, edge);
        surface.source =
            fmt::format("reconstructed from the {}'s points (the half level of their kernel density), grid {:.3g} mm",
                        cloud ? "point cloud" : "volume image", 1e3 * edge);
        break;
      }
      TriangleMesh input = read_mesh(o.file);
      check_closed_manifold(input, o.file);
      Remeshed remeshed = adapt_to_edge(input, edge);
      surface.mesh = std::move(remeshed.mesh);
      surface.source = fmt::format("the input surface {} ({} mm asked): {}", o.file, 1e3 * edge, remeshed.change);
      break;
    }
  }
  return carried_surface(std::move(surface.mesh), std::move(surface.source), model,
                         fmt::format("{}: the object's surface", scene.path));
}

ObjectSurface carried_surface(TriangleMesh mesh, std::string source, const Model& model, const std::string& name) {
  check_closed_manifold(mesh, name);
  ObjectSurface surface;
  surface.map = build_surface_map(model, mesh.V);
  surface.mesh = std::move(mesh);
  surface.source = std::move(source);
  return surface;
}

Points deformed_surface(const ObjectSurface& surface, const Points& u) {
  Points y;
  carry_surface(surface.map, surface.mesh.V, u, y);
  return y;
}

}  // namespace pointhaptics
