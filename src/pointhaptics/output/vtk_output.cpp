#include <pointhaptics/output/vtk_output.hpp>

#include <pointhaptics/mechanics/point_fields.hpp>

#include <cctype>

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

std::vector<VtkSeries> body_vtk_series(const std::string& folder, const Model& model) {
  std::vector<VtkSeries> series;
  if (model.n_bodies() < 2) return series;
  for (const std::string& name : model.body_names) {
    // body_<name>, its name kept to letters, digits, '-' and '_' (a file name on every system; never "frame")
    std::string base = "body_";
    for (const char c : name) base += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' ? c : '_';
    series.emplace_back(folder, base);
  }
  return series;
}

namespace {

// rows [first, last) of each array (points or surface vertices)
std::vector<VtkArray> rows_of(const std::vector<VtkArray>& arrays, index_t first, index_t last) {
  std::vector<VtkArray> out;
  out.reserve(arrays.size());
  for (const VtkArray& a : arrays) {
    const auto begin = a.values.begin() + static_cast<std::ptrdiff_t>(first * a.components);
    const auto end = a.values.begin() + static_cast<std::ptrdiff_t>(last * a.components);
    out.push_back({a.name, a.components, std::vector<double>(begin, end), a.integer});
  }
  return out;
}

}  // namespace

void add_vtk_frame(VtkSeries& series, Simulation& sim, const ObjectSurface* surface, std::vector<VtkSeries>* bodies) {
  std::vector<VtkArray> arrays = vtk_arrays(sim);
  const Points x = sim.model().X + sim.state().u;
  const double time = sim.state().time;
  series.add(time, x, arrays);
  Points vertices;
  std::vector<VtkArray> surface_arrays;
  if (surface) {
    vertices = deformed_surface(*surface, sim.state().u);
    surface_arrays = surface_vtk_arrays(*surface, arrays);
    series.add_surface(vertices, surface->mesh.F, surface_arrays);
  }
  if (!bodies) return;
  const Model& model = sim.model();
  for (std::size_t k = 0; k < bodies->size() && k + 1 < model.body_start.size(); ++k) {
    const index_t first = model.body_start[k], last = model.body_start[k + 1];
    (*bodies)[k].add(time, x.middleCols(first, last - first), rows_of(arrays, first, last));
    if (!surface || k + 1 >= surface->body_vertex_start.size()) continue;
    // its own part of the surface: its vertices, and its triangles renumbered from its first vertex
    const index_t v0 = surface->body_vertex_start[k], v1 = surface->body_vertex_start[k + 1];
    VtkTriangles triangles;
    for (index_t f = surface->body_face_start[k]; f < surface->body_face_start[k + 1]; ++f) {
      const auto& t = surface->mesh.F[static_cast<std::size_t>(f)];
      triangles.push_back({t[0] - v0, t[1] - v0, t[2] - v0});
    }
    (*bodies)[k].add_surface(vertices.middleCols(v0, v1 - v0), triangles, rows_of(surface_arrays, v0, v1));
  }
}

}  // namespace pointhaptics
