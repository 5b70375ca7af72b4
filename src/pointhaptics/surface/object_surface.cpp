#include <pointhaptics/surface/object_surface.hpp>

#include <pointhaptics/core/run_control.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/geometry/marching_tetrahedra.hpp>
#include <pointhaptics/geometry/mesh_distance.hpp>
#include <pointhaptics/geometry/remesh.hpp>
#include <pointhaptics/geometry/shape_surfaces.hpp>
#include <pointhaptics/io/mesh_file.hpp>
#include <pointhaptics/io/volume_file.hpp>
#include <pointhaptics/mechanics/kernels.hpp>

#include <pointhaptics/session/scene_builder.hpp>

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

namespace {

// the object's closed surface, and what it was built from
ObjectSurface object_mesh(const ObjectSpec& o, const Model& model) {
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
  return surface;
}

// a body's surface vertex inside another body by more than a hundredth of the finer spacing: the scene's bodies
// start interpenetrating
void check_bodies_apart(const Scene& scene, const Model& model, const ObjectSurface& surface) {
  const std::size_t n = scene.bodies.size();
  for (std::size_t b = 0; b < n; ++b) {
    TriangleMesh other;
    const index_t v0 = surface.body_vertex_start[b], v1 = surface.body_vertex_start[b + 1];
    other.V = surface.mesh.V.middleCols(v0, v1 - v0);
    for (index_t f = surface.body_face_start[b]; f < surface.body_face_start[b + 1]; ++f) {
      const auto& t = surface.mesh.F[static_cast<std::size_t>(f)];
      other.F.push_back({t[0] - v0, t[1] - v0, t[2] - v0});
    }
    const MeshDistance inside_b(other);
    const double tolerance = 1e-2 * model.spacing;
    for (std::size_t a = 0; a < n; ++a) {
      if (a == b) continue;
      for (index_t v = surface.body_vertex_start[a]; v < surface.body_vertex_start[a + 1]; ++v) {
        const Vec3 y = surface.mesh.V.col(v);
        const double depth = -inside_b.signed_distance(y);
        if (depth > tolerance)
          throw Error(
              fmt::format("{}:{}: object[{}]: \"{}\" starts inside object[{}] \"{}\": its surface at "
                          "[{:.4g}, {:.4g}, {:.4g}] lies {:.3g} m inside it (move one of them)",
                          scene.path, scene.bodies[a].object.line, a, scene.bodies[a].name, b, scene.bodies[b].name,
                          y.x(), y.y(), y.z(), depth));
      }
    }
  }
}

// every body's surface, each carried by its own points
ObjectSurface bodies_surface(const Scene& scene, const Model& model) {
  ObjectSurface joined;
  for (std::size_t k = 0; k < scene.bodies.size(); ++k) {
    const BodySpec& body = scene.bodies[k];
    const std::string name = fmt::format("{}:{}: object[{}] \"{}\"", scene.path, body.object.line, k, body.name);
    if (body.object.shape == ShapeKind::FILE &&
        (is_point_cloud_file(body.object.file) || is_volume_file(body.object.file)))
      throw Error(
          fmt::format("{}: a point cloud or a volume image is not yet one of several objects (its surface "
                      "is reconstructed from the points around it); give a surface mesh or a shape",
                      name));
    ObjectSurface part = object_mesh(body.object, model);
    check_closed_manifold(part.mesh, name + "'s surface");
    const auto own = static_cast<index_t>(k);
    part.map =
        build_surface_map(model, part.mesh.V, nullptr, [&](index_t, index_t j) { return model.body_of(j) == own; });
    append_body_surface(joined, part);
    joined.source += fmt::format("{}\"{}\": {}", k ? "; " : "", body.name, part.source);
  }
  check_bodies_apart(scene, model, joined);
  return joined;
}

}  // namespace

ObjectSurface build_object_surface(const Scene& scene, const Model& model) {
  if (scene.bodies.size() > 1) return bodies_surface(scene, model);
  ObjectSurface surface = object_mesh(scene.object, model);
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

void append_body_surface(ObjectSurface& joined, const ObjectSurface& part) {
  if (joined.body_vertex_start.empty()) {
    joined.mesh.V.resize(3, 0);
    joined.body_vertex_start.push_back(static_cast<index_t>(joined.mesh.V.cols()));
    joined.body_face_start.push_back(static_cast<index_t>(joined.mesh.F.size()));
  }
  const index_t v0 = static_cast<index_t>(joined.mesh.V.cols());
  joined.mesh.V.conservativeResize(3, v0 + part.mesh.V.cols());
  joined.mesh.V.rightCols(part.mesh.V.cols()) = part.mesh.V;
  for (const auto& t : part.mesh.F) joined.mesh.F.push_back({t[0] + v0, t[1] + v0, t[2] + v0});
  const SurfaceMap& map = part.map;
  const index_t e0 = joined.map.points.n_entries();
  for (index_t v = 0; v < map.n_vertices(); ++v) joined.map.points.offset.push_back(e0 + map.points.offset[v + 1]);
  joined.map.points.index.insert(joined.map.points.index.end(), map.points.index.begin(), map.points.index.end());
  joined.map.weight.insert(joined.map.weight.end(), map.weight.begin(), map.weight.end());
  joined.map.widened += map.widened;
  joined.cut_faces += part.cut_faces;
  joined.body_vertex_start.push_back(static_cast<index_t>(joined.mesh.V.cols()));
  joined.body_face_start.push_back(static_cast<index_t>(joined.mesh.F.size()));
}

ObjectSurface body_surface(const ObjectSurface& joined, index_t k) {
  const auto b = static_cast<std::size_t>(k);
  const index_t v0 = joined.body_vertex_start[b], v1 = joined.body_vertex_start[b + 1];
  ObjectSurface part;
  part.mesh.V = joined.mesh.V.middleCols(v0, v1 - v0);
  for (index_t f = joined.body_face_start[b]; f < joined.body_face_start[b + 1]; ++f) {
    const auto& t = joined.mesh.F[static_cast<std::size_t>(f)];
    part.mesh.F.push_back({t[0] - v0, t[1] - v0, t[2] - v0});
  }
  const SurfaceMap& map = joined.map;
  part.map.points.offset.assign(1, 0);
  for (index_t v = v0; v < v1; ++v) {
    for (index_t e = map.points.begin(v); e < map.points.end(v); ++e) {
      part.map.points.index.push_back(map.points.index[static_cast<std::size_t>(e)]);
      part.map.weight.push_back(map.weight[static_cast<std::size_t>(e)]);
    }
    part.map.points.offset.push_back(part.map.points.n_entries());
  }
  return part;
}

}  // namespace pointhaptics
