#pragma once
/// @file A simulation's state as a CSV table, one row per point of the object.
#include <pointhaptics/world/simulation.hpp>

#include <string>

namespace pointhaptics {

/// Columns: index, x, y, z (reference, m), ux, uy, uz (m), von_mises (Pa), strain_energy_density (J/m^3),
/// active, fixed (0/1). Throws Error naming the path if it cannot be written.
void write_points_csv(const std::string& path, Simulation& sim);

}  // namespace pointhaptics
