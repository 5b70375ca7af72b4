#pragma once
/// @file From a Scene (plain spec) to a Model: sampling, model build, boundary conditions and loads.
#include <pointhaptics/core/model.hpp>
#include <pointhaptics/core/point_cloud.hpp>
#include <pointhaptics/io/scene.hpp>

namespace pointhaptics {

/// Sample the scene's object into points.
PointCloud sample_object(const Scene& scene);

/// Build the complete static model of a scene: the [[fixed]] groups (in file order) and the constant
/// external loads. A traction's total force is spread over the points in its box in proportion to their
/// volume (on a vertex-grid face this is proportional to each point's share of the face area).
/// Throws Error naming the scene file and line for a box that selects no point or a point index out of range.
Model build_scene_model(const Scene& scene);

/// Where a scene's levels of detail start (reference configuration, m): lod.contact if given; else with a
/// [probe], the point of the object below the probe's origin (the top centre by default; an interactive
/// run then follows the probe); else the point of the scene's one point load.
Vec3 scene_lod_contact(const Scene& scene, const Model& model);

}  // namespace pointhaptics
