#include <pointhaptics/vtk_output.hpp>

#include <pointhaptics/mechanics/point_fields.hpp>

namespace pointhaptics {

std::vector<VtkArray> vtk_arrays(Simulation& sim) {
  const Model& m = sim.model();
  const State& s = sim.state();
  const index_t n = m.n_points;
  const PointFields f = point_fields(m, s.u);
  std::vector<VtkArray> arrays;
  arrays.push_back({"displacement", 3, std::vector<double>(s.u.data(), s.u.data() + 3 * n), false});
  arrays.push_back(
      {"cauchy_stress", 9, std::vector<double>(f.cauchy_stress.data(), f.cauchy_stress.data() + 9 * n), false});
  arrays.push_back({"von_mises", 1, std::vector<double>(f.von_mises.data(), f.von_mises.data() + n), false});
  arrays.push_back(
      {"strain_energy_density", 1, std::vector<double>(f.energy_density.data(), f.energy_density.data() + n), false});
  VtkArray active{"active", 1, std::vector<double>(static_cast<std::size_t>(n), sim.lod_enabled() ? 0.0 : 1.0), true};
  if (const ActiveSet* a = sim.active_set())
    for (index_t k = 0; k < a->n_selected; ++k) active.values[static_cast<std::size_t>(a->full_of[k])] = 1.0;
  arrays.push_back(std::move(active));
  VtkArray fixed{"fixed", 1, std::vector<double>(static_cast<std::size_t>(n)), true};
  for (index_t i = 0; i < n; ++i) fixed.values[static_cast<std::size_t>(i)] = m.fixed[i] ? 1.0 : 0.0;
  arrays.push_back(std::move(fixed));
  return arrays;
}

std::vector<VtkArray> surface_vtk_arrays(const ObjectSurface& surface, const std::vector<VtkArray>& point_arrays) {
  std::vector<VtkArray> out;
  Eigen::MatrixXd at_vertices;
  for (const VtkArray& a : point_arrays) {
    if (a.integer) continue;  // flags do not interpolate
    const Eigen::Index n = static_cast<Eigen::Index>(a.values.size()) / a.components;
    interpolate_at_surface(surface.map, Eigen::Map<const Eigen::MatrixXd>(a.values.data(), a.components, n),
                           at_vertices);
    out.push_back({a.name, a.components,
                   std::vector<double>(at_vertices.data(), at_vertices.data() + at_vertices.size()), false});
  }
  return out;
}

void add_vtk_frame(VtkSeries& series, Simulation& sim, const ObjectSurface* surface) {
  std::vector<VtkArray> arrays = vtk_arrays(sim);
  const Points x = sim.model().X + sim.state().u;
  series.add(sim.state().time, x, arrays);
  if (surface)
    series.add_surface(deformed_surface(*surface, sim.state().u), surface->mesh.F,
                       surface_vtk_arrays(*surface, arrays));
}

}  // namespace pointhaptics
