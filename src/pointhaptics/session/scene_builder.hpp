#pragma once
/// @file From a Scene (plain spec) to a Model: sampling, model build, boundary conditions and loads.
#include <pointhaptics/core/model.hpp>
#include <pointhaptics/core/point_cloud.hpp>
#include <pointhaptics/io/scene.hpp>

namespace pointhaptics {

/// What a model of n points will take, estimated before anything is built: neighbours per point from the
/// support (4/3 pi (h / spacing)^3 on a lattice) and bytes (measured: about 400 B per point and 50 B per
/// neighbour pair, model, state and solver scratch together; 2 kB per point at h = 2 spacings) and the
/// set-up's seconds (measured on 2 cores: 7e-5 s per point plus 3e-8 s per point per neighbour^1.5).
struct ModelEstimate {
  double points = 0;
  double neighbours_per_point = 0;
  double bytes = 0;
  double setup_seconds = 0;
};
ModelEstimate estimate_model(double n_points, const KernelParams& kernel, double spacing);
/// The points the scene's object will have, before it is sampled: exact for a box, the volume over
/// spacing^3 for a sphere or half-sphere; NaN for a file (known once read).
double estimated_points(const Scene& scene);
/// Throws Error with the estimate if a model of n points would need more than max_memory bytes (0: the
/// memory this process may still take, memory_limit(), naming the limit that binds): a run too big for the
/// machine is refused before it allocates. A set-up estimated to take more than 2 s is announced
/// (run_control.hpp) with its seconds and bytes.
void check_model_fits(double n_points, const Scene& scene, double max_memory, bool announce_setup = true);

/// Whether an object file is a point cloud (.xyz, .csv, .txt, or a .ply without faces) rather than a surface
/// mesh or a volume image.
bool is_point_cloud_file(const std::string& path);

/// Sample the scene's object into points.
PointCloud sample_object(const Scene& scene);

/// Build the complete static model of a scene: the [[fixed]] groups (in file order) and the constant
/// external loads. A traction's total force is spread over the points in its box in proportion to their
/// volume (on a vertex-grid face this is proportional to each point's share of the face area).
/// Throws Error naming the scene file and line for a box that selects no point or a point index out of range.
/// The object's size and memory are checked first (check_model_fits), against max_memory bytes (0: the
/// memory available now).
Model build_scene_model(const Scene& scene, double max_memory = 0);

/// Where a scene's levels of detail start (reference configuration, m): lod.contact if given; else with a
/// [probe], the point of the object below the probe's origin (the top centre by default; an interactive
/// run then follows the probe); else the point of the scene's one point load.
Vec3 scene_lod_contact(const Scene& scene, const Model& model);

}  // namespace pointhaptics
