#pragma once
/// @file Building the static Model from a sampled body, a material and a kernel.
#include <pointhaptics/core/model.hpp>
#include <pointhaptics/core/point_cloud.hpp>
#include <pointhaptics/mechanics/stencil.hpp>  // max_moment_condition

#include <cstdint>
#include <vector>

namespace pointhaptics {

/// Build the model: h, neighbours, volumes and masses, M_i (seed Eq. 11) with its conditioning check,
/// d_ij and d_ii (Eq. 10), and the hourglass coefficients. All points are free and unloaded; the
/// scene builder adds boundary conditions and loads before the model is used.
/// Throws Error on invalid parameters or coincident points.
/// `point_materials` and `material_of` (optional, Model's): the points' own materials, which may change
/// young, poisson, density and model; at most max_point_materials of them.
Model build_model(const PointCloud& cloud, const MaterialParams& material, const KernelParams& kernel,
                  std::vector<MaterialParams> point_materials = {}, std::vector<std::uint8_t> material_of = {});

/// The most materials one object mixes (its own and its regions'), as energies/material.hpp's table holds.
inline constexpr std::size_t max_point_materials = 32;

/// Throws Error naming `name` if a free point has no neighbour within its support: nothing holds it, it
/// has no strain and the run would report success on nonsense (issue 21). Call once the held points are set.
void check_every_free_point_has_neighbours(const Model& model, const std::string& name);

/// Check material parameters; throws Error naming the first bad one.
void validate_material(const MaterialParams& material);

}  // namespace pointhaptics
