#include <pointhaptics/session/scene_builder.hpp>

#include <pointhaptics/bodies/join_models.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/core/memory_limit.hpp>
#include <pointhaptics/core/run_control.hpp>
#include <pointhaptics/geometry/refine_sampling.hpp>
#include <pointhaptics/geometry/sampling.hpp>
#include <pointhaptics/io/input_file.hpp>
#include <pointhaptics/io/mesh_file.hpp>
#include <pointhaptics/io/point_cloud_file.hpp>
#include <pointhaptics/io/volume_file.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <optional>

namespace pointhaptics {

namespace {

// the object a message speaks of
std::string the_object(const Scene& scene) {
  return scene.bodies.empty() ? std::string("the object") : fmt::format("object \"{}\"", scene.bodies.front().name);
}

// Whether a [[fixed]], [[load]], [[region]] or [[refine]] naming `object` (empty: none) applies to the scene's
// object: with [[object]] tables, the build sees one body at a time (body_scene)
bool applies(const Scene& scene, const std::string& object) {
  return object.empty() || scene.bodies.empty() || object == scene.bodies.front().name;
}

// the set-up's seconds: per point (sampling, surface, stable step, active set: the 104k-point half-sphere of
// scenes/half_sphere_100k_lod.toml took 7.7 s) and per point per neighbour^1.5 (a pair's work grows with the
// neighbourhood's size: the stencil fits and the tangent products), measured on the 2-core development machine:
// a 0.2 m box at 1 cm with support_factor 6 (904 neighbours, 7.7 s) and 10 (4188 neighbours, 76 s) (issue 52)
constexpr double setup_seconds_per_point = 7e-5;
constexpr double setup_seconds_per_point_neighbour = 3.05e-8;
}  // namespace

ModelEstimate estimate_model(double n_points, const KernelParams& kernel, double spacing) {
  const double ratio = kernel.support > 0 ? kernel.support / spacing : kernel.support_factor;
  ModelEstimate e;
  e.points = n_points;
  e.neighbours_per_point = std::max(0.0, 4.0 / 3.0 * std::numbers::pi * ratio * ratio * ratio - 1);
  e.bytes = 20e6 + n_points * (400 + 50 * e.neighbours_per_point);
  e.setup_seconds =
      n_points * (setup_seconds_per_point + setup_seconds_per_point_neighbour * std::pow(e.neighbours_per_point, 1.5));
  return e;
}

double estimated_points(const Scene& scene) {
  const ObjectSpec& o = scene.object;
  const double s = o.spacing;
  double n = NAN;
  Vec3 lo = o.origin, hi = o.origin;
  switch (o.shape) {
    case ShapeKind::BOX: {
      n = 1;
      for (int a = 0; a < 3; ++a) n *= std::floor(o.size[a] / s + 1e-9) + 1;
      hi = o.origin + o.size;
      break;
    }
    case ShapeKind::SPHERE: n = 4.0 / 3.0 * std::numbers::pi * std::pow(o.radius / s, 3); break;
    case ShapeKind::HALF_SPHERE: n = 2.0 / 3.0 * std::numbers::pi * std::pow(o.radius / s, 3); break;
    case ShapeKind::FILE: return NAN;
  }
  if (o.shape != ShapeKind::BOX) {
    lo.array() -= o.radius;
    hi.array() += o.radius;
  }
  // [[refine]] regions add their fine points: the part of their bounds within the object's, at their spacing (a
  // nested region's counted as if added: an estimate's bound)
  for (const RefineSpec& r : scene.refine) {
    if (!applies(scene, r.object)) continue;
    const Vec3 extent = (r.bounds().max.cwiseMin(hi) - r.bounds().min.cwiseMax(lo)).cwiseMax(0.0);
    n += (extent.array() / r.spacing + 1).prod();
  }
  return n;
}

void check_model_fits(double n_points, const Scene& scene, double max_memory, bool announce_setup) {
  if (!std::isfinite(n_points)) return;
  const bool asked = max_memory > 0;
  const MemoryLimit limit = asked ? MemoryLimit{max_memory, "--max-memory"} : memory_limit();
  const ModelEstimate e = estimate_model(n_points, scene.kernel, scene.object.spacing);
  if (n_points > static_cast<double>(std::numeric_limits<index_t>::max()) / 64 || e.bytes > limit.bytes)
    throw Error(fmt::format(
        "{}:{}: object: {:.3g} points with about {:.0f} neighbours each would need about {:.3g} GB, more than "
        "{} ({:.3g} GB); use a coarser spacing{}",
        scene.path, scene.object.line, n_points, e.neighbours_per_point, e.bytes / 1e9, limit.what, limit.bytes / 1e9,
        asked ? "" : " (or allow more with --max-memory)"));
  if (announce_setup && e.setup_seconds > 2)
    announce(fmt::format("setting up {:.3g} points with about {:.0f} neighbours each: about {}, {:.2g} GB", n_points,
                         e.neighbours_per_point, format_duration(e.setup_seconds), e.bytes / 1e9));
}

bool is_point_cloud_file(const std::string& path) {
  const std::string ext = file_extension(path);
  return ext == ".xyz" || ext == ".csv" || ext == ".txt" || (ext == ".ply" && !ply_has_faces(path));
}

namespace {

// An analytic object's inside test, faces included.
std::function<bool(const Vec3&)> object_inside(const ObjectSpec& o) {
  const double tol = 1e-9 * o.spacing;
  switch (o.shape) {
    case ShapeKind::BOX:
      return [=](const Vec3& p) {
        return ((p - o.origin).array() >= -tol).all() && ((p - o.origin - o.size).array() <= tol).all();
      };
    case ShapeKind::SPHERE: return [=](const Vec3& p) { return (p - o.origin).norm() <= o.radius + tol; };
    case ShapeKind::HALF_SPHERE:
      return [=](const Vec3& p) { return p.y() >= o.origin.y() - tol && (p - o.origin).norm() <= o.radius + tol; };
    case ShapeKind::FILE: break;
  }
  throw Error("object: a file has no analytic inside test");
}

// The object's points at a finer spacing within a region's bounds: the box's lattice keeps points on its faces
// (whole intervals per axis, as sample_box), the balls' is centred as theirs. Volumes are left to refine_region.
PointCloud fine_lattice(const ObjectSpec& o, double spacing, const Aabb& bounds) {
  const Vec3 step = o.shape == ShapeKind::BOX ? box_lattice_step(o.size, spacing) : Vec3::Constant(spacing);
  PointCloud cloud = lattice_inside(o.origin, step, bounds.min, bounds.max, object_inside(o));
  cloud.spacing = spacing;
  return cloud;
}

PointCloud sample_shape(const Scene& scene) {
  const ObjectSpec& o = scene.object;
  switch (o.shape) {
    case ShapeKind::BOX: return sample_box(o.origin, o.size, o.spacing);
    case ShapeKind::SPHERE: return sample_sphere(o.origin, o.radius, o.spacing);
    case ShapeKind::HALF_SPHERE: return sample_half_sphere(o.origin, o.radius, o.spacing);
    case ShapeKind::FILE: {
      // point clouds as they are; surface meshes (and PLY files with faces) volume-sampled at the spacing. A
      // file that is not a regular one (a link to /dev/zero) is refused before anything reads it, whatever its
      // extension (a .ply's header was read for 11.6 s and 4.1 GB: issue 52)
      check_input_file(o.file, "object file");
      if (is_volume_file(o.file)) {
        if (!std::isfinite(o.threshold_low))
          throw Error(
              fmt::format("{}:{}: object.threshold: a volume image needs threshold = [low, high] (the intensities "
                          "to sample)",
                          scene.path, o.line));
        return sample_volume(read_volume(o.file), o.threshold_low, o.threshold_high, o.spacing, o.file);
      }
      if (is_point_cloud_file(o.file)) return read_point_cloud(o.file, o.spacing);
      return sample_mesh_volume(read_mesh(o.file), o.spacing, o.file);
    }
  }
  throw Error("object: unknown shape");
}

}  // namespace

namespace {

// [[refine]] regions must not overlap (each refines the sampling it finds), unless one lies wholly inside the other
// with a finer spacing: a graded refinement (R/16 at the contact inside R/8 around it), which sample_object() makes
// coarsest first (issue 52). The nesting is checked on a lattice over the finer region's bounds
bool lies_inside(const RefineSpec& inner, const RefineSpec& outer) {
  const Vec3 lo = inner.bounds().min, hi = inner.bounds().max;
  const double step = std::max(inner.spacing, (hi - lo).maxCoeff() / 100);
  for (double x = lo.x(); x <= hi.x() + 0.5 * step; x += step)
    for (double y = lo.y(); y <= hi.y() + 0.5 * step; y += step)
      for (double z = lo.z(); z <= hi.z() + 0.5 * step; z += step) {
        const Vec3 p = Vec3(x, y, z).cwiseMin(hi);
        if (inner.contains(p, 0) && !outer.contains(p, 0)) return false;
      }
  return true;
}

// a point of a lattice over the two regions' common bounds, at the finer spacing (at most 100 per axis), in both
std::optional<Vec3> common_point(const RefineSpec& ra, const RefineSpec& rb) {
  const Vec3 lo = ra.bounds().min.cwiseMax(rb.bounds().min), hi = ra.bounds().max.cwiseMin(rb.bounds().max);
  if (!(lo.array() <= hi.array()).all()) return std::nullopt;
  const double step = std::max(std::min(ra.spacing, rb.spacing), (hi - lo).maxCoeff() / 100);
  for (double x = lo.x(); x <= hi.x(); x += step)
    for (double y = lo.y(); y <= hi.y(); y += step)
      for (double z = lo.z(); z <= hi.z(); z += step)
        if (ra.contains(Vec3(x, y, z), 0) && rb.contains(Vec3(x, y, z), 0)) return Vec3(x, y, z);
  return std::nullopt;
}

void check_refine_regions_apart(const Scene& scene) {
  for (std::size_t a = 0; a < scene.refine.size(); ++a)
    for (std::size_t b = a + 1; b < scene.refine.size(); ++b) {
      const RefineSpec &ra = scene.refine[a], &rb = scene.refine[b];
      if (!applies(scene, ra.object) || !applies(scene, rb.object)) continue;
      const std::optional<Vec3> p = common_point(ra, rb);
      if (!p) continue;
      const bool nested =
          (rb.spacing < ra.spacing && lies_inside(rb, ra)) || (ra.spacing < rb.spacing && lies_inside(ra, rb));
      if (!nested)
        throw Error(fmt::format(
            "{}:{}: refine[{}] overlaps refine[{}] (line {}) at ({:.4g}, {:.4g}, {:.4g}): [[refine]] regions must "
            "not overlap unless one lies wholly inside the other with a finer spacing (join them into one)",
            scene.path, rb.line, b, a, ra.line, p->x(), p->y(), p->z()));
    }
}

}  // namespace

PointCloud sample_object(const Scene& scene) {
  const ObjectSpec& o = scene.object;
  check_refine_regions_apart(scene);
  PointCloud cloud = sample_shape(scene);
  // [[refine]]: finer points where a tool presses, each with its own support
  const double support = scene.kernel.support > 0 ? scene.kernel.support : scene.kernel.support_factor * o.spacing;
  // coarsest first: a region nested in another refines what that one made
  std::vector<const RefineSpec*> order;
  for (const RefineSpec& r : scene.refine) order.push_back(&r);
  std::stable_sort(order.begin(), order.end(), [](auto a, auto b) { return a->spacing > b->spacing; });
  for (const RefineSpec* refine : order) {
    const RefineSpec& r = *refine;
    if (!applies(scene, r.object)) continue;
    const double tol = 1e-9 * o.spacing;
    Aabb bounds = r.bounds();
    bounds.min.array() -= tol;
    bounds.max.array() += tol;
    try {
      refine_region(cloud,
                    Refinement{[&r](const Vec3& x, double grow) { return r.contains(x, grow); },
                               fine_lattice(o, r.spacing, bounds)},
                    object_inside(o), support);
    } catch (const Interrupted&) {
      throw;  // a stop, not an error of this table
    } catch (const Error& e) {
      throw Error(fmt::format("{}:{}: {}", scene.path, r.line, e.what()));
    }
  }
  return cloud;
}

namespace {

// a relative tolerance (of a length of the model: its support, or before it is built its spacing) so that a
// region drawn on a face catches the points on it
double region_tolerance(double length) { return 1e-9 * std::max(length, 1e-12); }
double region_tolerance(const Model& model) { return region_tolerance(model.h); }

// the points of X a selector (a [[fixed]] or [[region]] table, a load's box) takes
std::vector<index_t> points_in(const Points& X, const PointSelector& where, double tol) {
  std::vector<index_t> inside;
  for (index_t i = 0; i < X.cols(); ++i)
    if (where.contains(X.col(i), tol)) inside.push_back(i);
  return inside;
}
std::vector<index_t> points_in(const Model& model, const Aabb& box) {
  return points_in(model.X, PointSelector{box, {}, {}}, region_tolerance(model));
}

// [[region]] tables: each point's material, the object's unless a region (the last one that holds it) says
// otherwise; none without regions
void assign_region_materials(const Scene& scene, const Points& X, std::vector<MaterialParams>& materials,
                             std::vector<std::uint8_t>& material_of) {
  const auto own = [&](const RegionSpec& r) { return applies(scene, r.object); };
  const std::size_t regions = static_cast<std::size_t>(std::count_if(scene.regions.begin(), scene.regions.end(), own));
  if (regions == 0) return;
  if (regions + 1 > max_point_materials)
    throw Error(fmt::format("{}:{}: region: {} [[region]] tables in {}; at most {}", scene.path,
                            scene.regions.back().line, regions, the_object(scene), max_point_materials - 1));
  materials = {scene.material};
  material_of.assign(static_cast<std::size_t>(X.cols()), 0);
  const double tol = region_tolerance(scene.object.spacing);
  for (std::size_t k = 0; k < scene.regions.size(); ++k) {
    const RegionSpec& r = scene.regions[k];
    if (!own(r)) continue;
    MaterialParams m = scene.material;
    if (r.model) m.model = *r.model;
    if (r.young) m.young = *r.young;
    if (r.poisson) m.poisson = *r.poisson;
    if (r.density) m.density = *r.density;
    materials.push_back(m);
    const std::vector<index_t> inside = points_in(X, r, tol);
    if (inside.empty())
      throw Error(
          fmt::format("{}:{}: region[{}].{}: holds no point of {}", scene.path, r.line, k, r.key(), the_object(scene)));
    for (const index_t i : inside)
      material_of[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(materials.size() - 1);
  }
}

// [object] stiffness_map: each point's E_i / E from its voxel's intensity (linear between the rows, the end
// values beyond them)
void apply_stiffness_map(const Scene& scene, PointCloud& cloud) {
  const auto& map = scene.object.stiffness_map;
  if (map.empty()) return;
  if (cloud.intensity.size() != cloud.size())
    throw Error(fmt::format(
        "{}:{}: object.stiffness_map: needs a volume image (.nii, .nii.gz, .nrrd, .nhdr) for its intensities",
        scene.path, scene.object.line));
  cloud.stiffness_scale.resize(cloud.size());
  for (index_t i = 0; i < cloud.size(); ++i) {
    const double v = cloud.intensity[i];
    double young = v <= map.front()[0] ? map.front()[1] : map.back()[1];
    for (std::size_t r = 1; r < map.size(); ++r)
      if (v >= map[r - 1][0] && v <= map[r][0]) {
        const double t = (v - map[r - 1][0]) / (map[r][0] - map[r - 1][0]);
        young = map[r - 1][1] + t * (map[r][1] - map[r - 1][1]);
        break;
      }
    cloud.stiffness_scale[i] = young / scene.material.young;
  }
}

}  // namespace

namespace {

// The scene with body k as its one object (its own object and material; the tables that name another body are
// skipped where they are read: applies()).
Scene body_scene(const Scene& scene, std::size_t k) {
  Scene body = scene;
  body.bodies = {scene.bodies[k]};
  body.object = scene.bodies[k].object;
  body.material = scene.bodies[k].material;
  return body;
}

}  // namespace

Model build_scene_model(const Scene& scene, double max_memory) {
  if (scene.bodies.size() > 1) {
    // several bodies: each built alone, then joined (no neighbour list crosses between them)
    std::vector<Model> bodies;
    std::vector<std::string> names;
    for (std::size_t k = 0; k < scene.bodies.size(); ++k) {
      bodies.push_back(build_scene_model(body_scene(scene, k), max_memory));
      names.push_back(scene.bodies[k].name);
    }
    return join_models(std::move(bodies), std::move(names));
  }
  // too big for the machine: refused before anything is allocated (files once they are read)
  // announced from the estimate when there is one (a refinement's fine points take long to sample), else once the
  // file's points are known
  const double estimate = estimated_points(scene);
  check_model_fits(estimate, scene, max_memory, true);
  PointCloud cloud = sample_object(scene);
  apply_stiffness_map(scene, cloud);
  check_model_fits(static_cast<double>(cloud.X.cols()), scene, max_memory, std::isnan(estimate));
  std::vector<MaterialParams> materials;
  std::vector<std::uint8_t> material_of;
  assign_region_materials(scene, cloud.X, materials, material_of);
  Model model = build_model(cloud, scene.material, scene.kernel, std::move(materials), std::move(material_of));

  // held points, one group per [[fixed]] table
  for (size_t k = 0; k < scene.fixed.size(); ++k) {
    const FixedSpec& spec = scene.fixed[k];
    if (!applies(scene, spec.object)) continue;
    FixedGroup group;
    group.name = fmt::format("fixed[{}]", k);
    group.displacement = spec.displacement;
    group.ramp = spec.ramp;
    group.points = points_in(model.X, spec, region_tolerance(model));
    if (group.points.empty())
      throw Error(fmt::format("{}:{}: fixed[{}].{}: holds no point of {}", scene.path, spec.line, k, spec.key(),
                              the_object(scene)));
    for (index_t i : group.points) model.fixed[i] = 1;
    model.fixed_groups.push_back(std::move(group));
  }
  // points a point-cloud file marks as held: held at zero displacement (no [[fixed]] table, so no
  // reaction entry; give them a [[fixed]] box for one)
  for (index_t i = 0; i < static_cast<index_t>(cloud.held.size()); ++i)
    if (cloud.held[static_cast<std::size_t>(i)]) model.fixed[i] = 1;

  // constant external loads
  for (size_t k = 0; k < scene.loads.size(); ++k) {
    const LoadSpec& load = scene.loads[k];
    if (!applies(scene, load.object)) continue;
    switch (load.kind) {
      case LoadKind::GRAVITY:
        for (index_t i = 0; i < model.n_points; ++i) model.f_ext.col(i) += model.mass[i] * load.g;
        break;
      case LoadKind::TRACTION: {
        const std::vector<index_t> loaded = points_in(model, load.box);
        if (loaded.empty())
          throw Error(
              fmt::format("{}:{}: load[{}].box: holds no point of {}", scene.path, load.line, k, the_object(scene)));
        double total_volume = 0;
        for (index_t i : loaded) total_volume += model.volume[i];
        for (index_t i : loaded) model.f_ext.col(i) += load.total * (model.volume[i] / total_volume);
        break;
      }
      case LoadKind::POINT:
        if (load.point >= model.n_points)
          throw Error(fmt::format("{}:{}: load[{}].point: {} is out of range ({} has {} points)", scene.path, load.line,
                                  k, load.point, the_object(scene), model.n_points));
        model.f_ext.col(static_cast<index_t>(load.point)) += load.force;
        break;
    }
  }
  check_every_free_point_has_neighbours(model, scene.path);
  return model;
}

Vec3 scene_lod_contact(const Scene& scene, const Model& model) {
  if (scene.lod.contact.allFinite()) {
    // a contact far from the object (1e300 was accepted) selects nothing sensible
    const Vec3 lo = model.X.rowwise().minCoeff(), hi = model.X.rowwise().maxCoeff();
    const double away = (scene.lod.contact.cwiseMax(lo).cwiseMin(hi) - scene.lod.contact).stableNorm();
    if (!(away <= model.h))
      throw Error(fmt::format(
          "{}:{}: lod.contact: [{:.4g}, {:.4g}, {:.4g}] lies {:.3g} m outside the object's bounding box (at most h = {:.3g} m)",
          scene.path, scene.lod.line, scene.lod.contact.x(), scene.lod.contact.y(), scene.lod.contact.z(), away,
          model.h));
    return scene.lod.contact;
  }
  if (scene.probe.present) {
    const Vec3 lo = model.X.rowwise().minCoeff(), hi = model.X.rowwise().maxCoeff();
    const Vec3 origin = scene.probe.origin.allFinite() ? scene.probe.origin
                                                       : Vec3(0.5 * (lo.x() + hi.x()), hi.y(), 0.5 * (lo.z() + hi.z()));
    return Vec3(origin.x(), std::min(origin.y(), hi.y()), origin.z());
  }
  for (const LoadSpec& l : scene.loads)
    if (l.kind == LoadKind::POINT) return model.X.col(static_cast<index_t>(l.point));
  throw Error(fmt::format("{}:{}: lod.contact: missing (give contact = [x, y, z], a [probe] or one point load)",
                          scene.path, scene.lod.line));
}

}  // namespace pointhaptics
