#include "experiment_contact.hpp"

#include "plots.hpp"

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/pointhaptics.hpp>

#include <fmt/format.h>
#include <fmt/os.h>

#include <chrono>
#include <cmath>
#include <filesystem>

namespace pointhaptics::experiments {
namespace {

// the block: 80 x 40 x 80 mm, E = 1e5 Pa, nu = 0.3, bottom held; a rigid sphere of radius 10 mm
constexpr double R = 0.01, width = 0.08, height = 0.04, young = 1e5, poisson = 0.3;

Scene block_scene(double spacing) {
  Scene s;
  s.path = "contact-block";
  s.object.size = Vec3(width, height, width);
  s.object.origin = Vec3(-0.5 * width, 0, -0.5 * width);
  s.object.spacing = spacing;
  s.material.young = young;
  s.material.poisson = poisson;
  s.material.density = 1000;
  FixedSpec bottom;
  bottom.box = {Vec3(-1, -1, -1), Vec3(1, 1e-9, 1)};
  s.fixed.push_back(bottom);
  s.solver.kind = SolverKind::STATIC;
  return s;
}

// Hertz: a rigid sphere on an elastic half-space, F = 4/3 E / (1 - nu^2) sqrt(R) d^(3/2)
double hertz(double depth) { return 4.0 / 3.0 * young / (1 - poisson * poisson) * std::sqrt(R) * std::pow(depth, 1.5); }

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

struct Setup {
  Scene scene;
  std::unique_ptr<Simulation> sim;
  ObjectSurface surface;
  double top = 0;  // the top face's height, m
};

Setup setup(int per_radius, int threads) {
  Setup s;
  s.scene = block_scene(R / per_radius);
  s.sim = std::make_unique<Simulation>(build_scene_model(s.scene), s.scene.solver, threads);
  s.surface = build_object_surface(s.scene, s.sim->model());
  s.top = s.surface.mesh.V.row(1).maxCoeff();
  s.sim->hold_tool(ToolShape{ToolKind::SPHERE, R, 0}, ToolPose{Vec3(0, s.top + 2 * R, 0), Eigen::Quaterniond::Identity()},
                   s.surface.mesh, s.surface.map);
  return s;
}

ToolPose at(double x, double height) { return ToolPose{Vec3(x, height, 0), Eigen::Quaterniond::Identity()}; }

}  // namespace

int run_contact_experiment(const ContactOptions& options) {
  namespace fs = std::filesystem;
  fs::create_directories(options.out);
  const fs::path out = options.out;
  const std::vector<int> spacings = options.quick ? std::vector<int>{options.per_radius.front()} : options.per_radius;
  const std::vector<double> depths = options.quick ? std::vector<double>{0.1, 0.2, 0.3}
                                                   : std::vector<double>{0.05, 0.1, 0.15, 0.2, 0.25, 0.3};
  auto force_csv = fmt::output_file((out / "contact-force.csv").string());
  force_csv.print("spacing_over_r,points,depth_over_r,depth_m,force_n,hertz_n,ratio_to_hertz,contacts,penetration_m,newton,seconds,physical\n");
  auto sliding_csv = fmt::output_file((out / "contact-sliding.csv").string());
  sliding_csv.print("spacing_over_r,x_over_spacing,normal_n,tangential_n,contacts\n");
  std::string table, sliding_table, offsets;
  for (const int n : spacings) {
    Setup s = setup(n, options.threads);
    Simulation& sim = *s.sim;
    HeldTool& tool = *sim.held_tool();
    const double spacing = R / n;
    // first contact: the highest tool position (descending by R/1000) at which a surface vertex is inside it
    double first = NAN;
    for (int k = 0; k <= 2000; ++k) {
      const double h = s.top + R + 0.5 * spacing - k * R * 1e-3;
      tool.set_pose(at(0, h));
      if (tool.load(sim.model(), sim.state().u).penetration > 0) {
        first = h - R;  // the sphere's lowest point
        break;
      }
    }
    offsets += fmt::format("| R/{} | {:.4f} R ({:.3f} mm) |\n", n, (first - s.top) / R, 1e3 * (first - s.top));
    // pressed in, depth by depth, each solve starting from the last
    for (const double d : depths) {
      sim.set_tool_pose(at(0, s.top + R - d * R));
      const auto start = std::chrono::steady_clock::now();
      const StepReport report = sim.step();
      const double took = seconds_since(start);
      if (report.status == StepStatus::FAILED) throw Error(fmt::format("contact: R/{} at depth {} R: {}", n, d, report.failure));
      const ToolLoad load = tool.load(sim.model(), sim.state().u);
      const double f = load.force.y(), f_hertz = hertz(d * R);
      // an equilibrium with inverted neighbourhoods (a material collapsing under the sphere) is no result
      const RunSummary summary = sim.summary();
      const std::string physical = summary.converged ? "yes" : fmt::format("no: {}", summary.failure);
      force_csv.print("{},{},{},{:.6g},{:.6g},{:.6g},{:.5f},{},{:.3g},{},{:.3f},{}\n", n, sim.model().n_points, d, d * R, f, f_hertz,
                      f / f_hertz, load.contacts, load.penetration, report.iterations, took, summary.converged ? 1 : 0);
      table += fmt::format("| R/{} | {} | {:.2f} | {:.4f} | {:.4f} | {:.3f} | {} | {:.2g} ({:.2g}% of the depth) | {:.1f} | {} |\n", n,
                           sim.model().n_points, d, f, f_hertz, f / f_hertz, load.contacts, load.penetration,
                           100 * load.penetration / (d * R), took, physical);
      fmt::print("contact: R/{} depth {:.2f} R: {:.4f} N (Hertz {:.4f} N, ratio {:.3f}), {} contacts, {:.1f} s\n", n, d, f, f_hertz,
                 f / f_hertz, load.contacts, took);
    }
    // sliding, frictionless, at 0.1 R deep over two spacings of the lattice (quasi-static: each an equilibrium)
    sim.set_tool_pose(at(0, s.top + R - 0.1 * R));
    sim.step();
    std::vector<double> normal, tangential;
    for (int k = 0; k <= 16; ++k) {
      const double x = k * spacing / 8;
      sim.set_tool_pose(at(x, s.top + R - 0.1 * R));
      const StepReport report = sim.step();
      if (report.status == StepStatus::FAILED) throw Error(fmt::format("contact: sliding at R/{}: {}", n, report.failure));
      const ToolLoad load = tool.load(sim.model(), sim.state().u);
      normal.push_back(load.force.y());
      tangential.push_back(std::hypot(load.force.x(), load.force.z()));
      sliding_csv.print("{},{:.4f},{:.6g},{:.6g},{}\n", n, x / spacing, load.force.y(), tangential.back(), load.contacts);
    }
    double mean = 0, var = 0, worst_tangential = 0;
    for (double v : normal) mean += v / static_cast<double>(normal.size());
    for (double v : normal) var += (v - mean) * (v - mean) / static_cast<double>(normal.size());
    for (double t : tangential) worst_tangential = std::max(worst_tangential, t);
    sliding_table += fmt::format("| R/{} | {:.4f} | {:.2f}% | {:.2f}% |\n", n, mean, 100 * std::sqrt(var) / mean, 100 * worst_tangential / mean);
  }
  force_csv.close();
  sliding_csv.close();
  auto md = fmt::output_file((out / "summary.md").string());
  md.print("# Contact: a rigid sphere pressed into a block\n\n"
           "Block {} x {} x {} mm (E = {:.0e} Pa, nu = {}, St. Venant-Kirchhoff, bottom held), a rigid frictionless sphere of "
           "radius R = {} mm pressed into the middle of its top face through the object's surface (its exact boundary at "
           "half the spacing, carried by the points), solved statically at each depth (the contact by an augmented "
           "Lagrangian: no surface vertex more than 1e-4 R inside the sphere).\n\n"
           "## Force against depth (depth from the undeformed surface)\n\n"
           "Hertz is the small-depth limit for a half-space; the block's finite thickness (4 R) stiffens it, and the "
           "strains at 0.3 R are no longer small.\n\n"
           "| spacing | points | depth / R | force (N) | Hertz (N) | ratio | vertices in contact | deepest vertex inside (m) | solve (s) | a result |\n"
           "|---|---|---|---|---|---|---|---|---|---|\n{}\n"
           "## Where the surface is first felt\n\n"
           "The sphere's lowest point at first contact, above the true top face (the point-sphere contact felt it half a "
           "spacing above):\n\n| spacing | offset |\n|---|---|\n{}\n"
           "## Sliding at 0.1 R deep, frictionless\n\n"
           "17 equilibria over two spacings along x:\n\n"
           "| spacing | mean normal force (N) | normal-force ripple (std / mean) | largest tangential / normal |\n"
           "|---|---|---|---|\n{}\n"
           "Not yet in this experiment: CalculiX's axisymmetric reference (the issue's mesh-converged FEM), friction.\n",
           1e3 * width, 1e3 * height, 1e3 * width, young, poisson, 1e3 * R, table, offsets, sliding_table);
  md.close();
  if (run_plot_script("plot_contact.py", out.string(), options.plot_script) != 0) return 1;
  fmt::print("wrote {}\n", out.string());
  return 0;
}

}  // namespace pointhaptics::experiments
