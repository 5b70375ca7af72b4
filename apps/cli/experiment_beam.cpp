#include "experiment_beam.hpp"

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/fem/calculix.hpp>
#include <pointhaptics/pointhaptics.hpp>

#include <fmt/format.h>
#include <fmt/os.h>

#include <chrono>
#include <filesystem>

namespace pointhaptics::experiments {
namespace {

// mean -u_y over the points or nodes of the free end face x = x_max
double tip_sag(const Points& X, const Points& u, double x_max) {
  double sum = 0;
  int n = 0;
  for (Eigen::Index k = 0; k < X.cols(); ++k)
    if (std::abs(X(0, k) - x_max) < 1e-9) {
      sum -= u(1, k);
      ++n;
    }
  return n ? sum / n : 0.0;
}

}  // namespace

int run_beam_experiment(const BeamOptions& options) {
  namespace fs = std::filesystem;
  fs::create_directories(options.out);
  const fs::path out = options.out;
  Scene scene = read_scene_file(options.scene);
  if (scene.object.shape != ShapeKind::BOX)
    throw Error(fmt::format("{}: the beam experiment needs a box", options.scene));
  const double x_max = scene.object.origin.x() + scene.object.size.x();
  fem::find_ccx();
  auto csv = fmt::output_file((out / "beam.csv").string());
  csv.print("method,threads,points_or_elements,tip_sag_m,error_pct,compute_s,simulated_s,compute_s_per_simulated_s\n");
  std::string md = fmt::format(
      "# {}: settled tip sag and cost\n\n| method | threads | tip sag (m) | vs CalculiX | compute s per simulated s |\n|---|---|---|---|---|\n",
      options.scene);

  // CalculiX NLGEOM on two meshes of 20-node hexahedra
  double reference = 0;
  for (int m : {1, 2}) {
    fem::BoxProblem p;
    p.origin = scene.object.origin;
    p.size = scene.object.size;
    p.nx = 16 * m;
    p.ny = 4 * m;
    p.nz = 4 * m;
    p.young = scene.material.young;
    p.poisson = scene.material.poisson;
    p.density = scene.material.density;
    p.nlgeom = true;
    for (const FixedSpec& f : scene.fixed) {
      if (f.sphere || f.cylinder)
        throw Error(fmt::format("beam-4x1x1: {}: the CalculiX model takes [[fixed]] boxes only", scene.path));
      p.clamps.push_back({f.box.min, f.box.max});
    }
    for (const LoadSpec& l : scene.loads) {
      if (l.kind == LoadKind::GRAVITY) p.gravity = l.g;
      else throw Error(fmt::format("{}: the beam experiment supports gravity loads only", options.scene));
    }
    const fem::Solution sol = fem::solve(p, 2);
    reference = tip_sag(sol.nodes, sol.displacement, x_max);
    fmt::print("CalculiX NLGEOM {}x{}x{}: tip sag {:.5f} m ({:.1f} s)\n", p.nx, p.ny, p.nz, reference, sol.wall_s);
    csv.print("calculix_nlgeom,2,{},{:.6e},,{:.3f},,\n", p.nx * p.ny * p.nz, reference, sol.wall_s);
    md += fmt::format("| CalculiX NLGEOM {}x{}x{} C3D20R | 2 | {:.5f} | | ({:.1f} s static) |\n", p.nx, p.ny, p.nz,
                      reference, sol.wall_s);
  }
  auto error = [&](double d) { return 100 * (d / reference - 1); };

  // point model: static, then damped dynamics with each solver
  Scene statics = scene;
  statics.solver.kind = SolverKind::STATIC;
  {
    const auto start = std::chrono::steady_clock::now();
    Simulation sim(build_scene_model(statics), statics.solver, 2);
    sim.run(0);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double sag = tip_sag(sim.model().X, sim.state().u, x_max);
    fmt::print("point model static: tip sag {:.5f} m ({:+.2f}%), {:.2f} s\n", sag, error(sag), s);
    csv.print("point_static,2,{},{:.6e},{:.3f},{:.3f},,\n", sim.model().n_points, sag, error(sag), s);
    md += fmt::format("| point model, static | 2 | {:.5f} | {:+.2f}% | ({:.2f} s static) |\n", sag, error(sag), s);
  }
  std::vector<SolverKind> kinds{SolverKind::EXPLICIT};
  if (options.implicit) kinds.push_back(SolverKind::IMPLICIT);
  for (SolverKind kind : kinds)
    for (int threads : {1, 2}) {
      Scene dyn = scene;
      dyn.solver.kind = kind;
      Simulation sim(build_scene_model(dyn), dyn.solver, threads);
      const auto start = std::chrono::steady_clock::now();
      sim.run(options.duration);
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const double sag = tip_sag(sim.model().X, sim.state().u, x_max);
      fmt::print(
          "point model {} ({} threads, dt = {} s): tip sag after {} s {:.5f} m ({:+.2f}%), {:.2f} s compute per simulated s\n",
          to_string(kind), threads, dyn.solver.dt, options.duration, sag, error(sag), s / options.duration);
      csv.print("point_{},{},{},{:.6e},{:.3f},{:.3f},{},{:.4f}\n", to_string(kind), threads, sim.model().n_points, sag,
                error(sag), s, options.duration, s / options.duration);
      md +=
          fmt::format("| point model, {} dt = {} s, after {} s | {} | {:.5f} | {:+.2f}% | {:.2f} |\n", to_string(kind),
                      dyn.solver.dt, options.duration, threads, sag, error(sag), s / options.duration);
    }
  // the reduced model ([reduction] modes = r): implicit steps of 1 ms; its set-up (the basis and the polynomial)
  // timed apart from the stepping
  if (options.modes > 0)
    for (int threads : {1, 2}) {
      Scene dyn = scene;
      dyn.solver.kind = SolverKind::IMPLICIT;
      dyn.solver.dt = 1e-3;
      dyn.solver.reduction.modes = options.modes;
      dyn.solver.reduction.cache.clear();  // the set-up measured every time
      const auto setup_start = std::chrono::steady_clock::now();
      Simulation sim(build_scene_model(dyn), dyn.solver, threads);
      const double setup_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count();
      const auto start = std::chrono::steady_clock::now();
      sim.run(options.duration);
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const RunSummary summary = sim.summary();
      if (!summary.converged) throw Error(fmt::format("beam-4x1x1: the reduced run failed: {}", summary.failure));
      const double sag = tip_sag(sim.model().X, sim.state().u, x_max);
      fmt::print(
          "point model reduced, r = {} ({} threads, implicit dt = {} s): tip sag after {} s {:.5f} m ({:+.2f}%), "
          "{:.4f} s compute per simulated s; set-up {:.2f} s (model and basis)\n",
          options.modes, threads, dyn.solver.dt, options.duration, sag, error(sag), s / options.duration, setup_s);
      csv.print("point_reduced,{},{},{:.6e},{:.3f},{:.3f},{},{:.4f}\n", threads, sim.model().n_points, sag, error(sag),
                s, options.duration, s / options.duration);
      md += fmt::format(
          "| point model, reduced r = {}, implicit dt = {} s, after {} s (set-up {:.2f} s, not counted) | {} | {:.5f} "
          "| {:+.2f}% | {:.4f} |\n",
          options.modes, dyn.solver.dt, options.duration, setup_s, threads, sag, error(sag), s / options.duration);
    }
  csv.close();
  auto summary = fmt::output_file((out / "summary.md").string());
  summary.print("{}", md);
  summary.close();
  fmt::print("wrote {}\n", out.string());
  return 0;
}

}  // namespace pointhaptics::experiments
