#pragma once
/// @file A simulation's state as ParaView frames (io/vtk.hpp): the fields design.md names.
#include <pointhaptics/io/vtk.hpp>
#include <pointhaptics/simulation.hpp>

namespace pointhaptics {

/// The frame's arrays for the object (all its points, with levels of detail too): `displacement` (m),
/// `cauchy_stress` (Pa, 9 components), `von_mises` (Pa), `strain_energy_density` (J/m^3), `active`
/// (1 where the point is simulated) and `fixed` (1 where held). Points are the current positions X + u.
std::vector<VtkArray> vtk_arrays(Simulation& sim);

/// Add the simulation's current state to the series at its time.
void add_vtk_frame(VtkSeries& series, Simulation& sim);

}  // namespace pointhaptics
