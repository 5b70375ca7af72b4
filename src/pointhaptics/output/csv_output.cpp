#include <pointhaptics/output/csv_output.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/output_file.hpp>
#include <pointhaptics/output/vtk_output.hpp>

#include <fmt/format.h>
#include <fmt/os.h>

namespace pointhaptics {

void write_points_csv(const std::string& path, Simulation& sim) {
  const std::vector<VtkArray> arrays = vtk_arrays(sim);  // the same fields as the ParaView frames
  auto field = [&](const std::string& name) -> const std::vector<double>& {
    for (const VtkArray& a : arrays)
      if (a.name == name) return a.values;
    throw Error("csv output: no field " + name);
  };
  const std::vector<double>& vm = field("von_mises");
  const std::vector<double>& w = field("strain_energy_density");
  const std::vector<double>& active = field("active");
  const std::vector<double>& fixed = field("fixed");
  const Model& m = sim.model();
  const State& s = sim.state();
  write_text_file(path, "--csv", [&](TextOutput& out) {
    out.print(
        "index,x_ref,y_ref,z_ref,ux,uy,uz,von_mises,strain_energy_density,active,fixed\n");  // reference positions; current = ref + u
    for (index_t i = 0; i < m.n_points; ++i) {
      const std::size_t k = static_cast<std::size_t>(i);
      out.print("{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{},{}\n", i, m.X(0, i), m.X(1, i),
                m.X(2, i), s.u(0, i), s.u(1, i), s.u(2, i), vm[k], w[k], static_cast<int>(active[k]),
                static_cast<int>(fixed[k]));
    }
  });
}

}  // namespace pointhaptics
