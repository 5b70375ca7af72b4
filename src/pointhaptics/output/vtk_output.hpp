#pragma once
/// @file A simulation's state as ParaView frames (io/vtk.hpp): the fields design.md names.
#include <pointhaptics/io/vtk.hpp>
#include <pointhaptics/surface/object_surface.hpp>
#include <pointhaptics/world/simulation.hpp>

namespace pointhaptics {

/// The frame's arrays for the object (all its points, with levels of detail too): `displacement` (m),
/// `cauchy_stress` (Pa, 9 components), `von_mises` (Pa), `strain_energy_density` (J/m^3), `active`
/// (1 where the point is simulated) and `fixed` (1 where held). Points are the current positions X + u.
std::vector<VtkArray> vtk_arrays(Simulation& sim);

/// The surface's arrays: the float arrays of `point_arrays` (vtk_arrays()) carried to its vertices by its
/// map (displacement, cauchy_stress, von_mises, strain_energy_density; each vertex's MLS interpolation of
/// its points' values).
std::vector<VtkArray> surface_vtk_arrays(const ObjectSurface& surface, const std::vector<VtkArray>& point_arrays);

/// With several bodies (Model::body_start), a series per body beside the object's, in the same folder and named
/// for it (`<folder>/body_<name>.pvd`, its name kept to letters, digits, '-' and '_'; ParaView opens each as the
/// body's animation); none with one body.
std::vector<VtkSeries> body_vtk_series(const std::string& folder, const Model& model);

/// Add the simulation's current state to the series at its time; with `surface`, its deformed surface too
/// (part 1 of the time step). With `bodies` (body_vtk_series()), each body's rows of the same arrays and its
/// part of the surface to its own series.
void add_vtk_frame(VtkSeries& series, Simulation& sim, const ObjectSurface* surface = nullptr,
                   std::vector<VtkSeries>* bodies = nullptr);

}  // namespace pointhaptics
