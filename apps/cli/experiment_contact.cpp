#include "experiment_contact.hpp"

#include "plots.hpp"

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/fem/calculix_indentation.hpp>
#include <pointhaptics/pointhaptics.hpp>

#include <fmt/format.h>
#include <fmt/os.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <thread>

namespace pointhaptics::experiments {
namespace {

// the block: 80 x 40 x 80 mm, E = 1e5 Pa, nu = 0.3, bottom held; a rigid sphere of radius 10 mm
constexpr double R = 0.01, width = 0.08, height = 0.04, young = 1e5, poisson = 0.3;

Scene block_scene(double spacing, MaterialModel model, int refine) {
  Scene s;
  s.path = "contact-block";
  s.object.size = Vec3(width, height, width);
  s.object.origin = Vec3(-0.5 * width, 0, -0.5 * width);
  s.object.spacing = spacing;
  s.material.young = young;
  s.material.poisson = poisson;
  s.material.density = 1000;
  s.material.model = model;
  FixedSpec bottom;
  bottom.box = {Vec3(-1, -1, -1), Vec3(1, 1e-9, 1)};
  s.fixed.push_back(bottom);
  s.solver.kind = SolverKind::STATIC;
  if (refine > 0) {
    RefineSpec r;
    r.box = {Vec3(-1.2 * R, height - 1.2 * R, -1.2 * R), Vec3(1.2 * R, height + R, 1.2 * R)};
    r.spacing = R / refine;
    s.refine.push_back(r);
    s.object.surface_edge = 0.5 * r.spacing;
  }
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

Setup setup(int per_radius, MaterialModel model, int refine, int threads, bool non_negative_map, double friction = 0) {
  Setup s;
  s.scene = block_scene(R / per_radius, model, refine);
  s.sim = std::make_unique<Simulation>(build_scene_model(s.scene), s.scene.solver, threads);
  s.surface = build_object_surface(s.scene, s.sim->model());
  s.top = s.surface.mesh.V.row(1).maxCoeff();
  SurfaceContactParams contact;
  contact.friction = friction;
  contact.non_negative_weights = non_negative_map;
  s.sim->hold_tool(ToolShape{ToolKind::SPHERE, R, 0},
                   ToolPose{Vec3(0, s.top + 2 * R, 0), Eigen::Quaterniond::Identity()}, s.surface.mesh, s.surface.map,
                   contact);
  return s;
}

ToolPose at(double x, double height) { return ToolPose{Vec3(x, height, 0), Eigen::Quaterniond::Identity()}; }

// The CalculiX reference: an axisymmetric cylinder of the block's half width and height (its top's corners
// are far from the contact: a cylinder of the square top's area changes the force by little, measured below)
struct FemRun {
  std::string what;
  int per_radius = 0;
  double block_radius = 0, penalty_factor = 100;
  fem::IndentationSolution solution;
};

FemRun run_fem(const std::string& what, int per_radius, double block_radius, double penalty_factor,
               const MaterialParams& material, double max_depth, int increments, int threads) {
  FemRun run{what, per_radius, block_radius, penalty_factor, {}};
  fem::IndentationProblem p;
  p.sphere_radius = R;
  p.block_radius = block_radius;
  p.height = height;
  p.material = material;
  p.max_depth = max_depth;
  p.increments = increments;
  p.elements_per_radius = per_radius;
  p.penalty = penalty_factor * young * per_radius / R;
  run.solution = fem::solve_indentation(p, threads);
  fmt::print("contact: CalculiX {} (R/{} at the contact, {} nodes): {:.4f} N at {:.2f} R, {:.1f} s\n", what, per_radius,
             run.solution.nodes, run.solution.curve.back().force, max_depth / R, run.solution.wall_s);
  return run;
}

}  // namespace

int run_contact_experiment(const ContactOptions& options) {
  namespace fs = std::filesystem;
  fs::create_directories(options.out);
  const fs::path out = options.out;
  // the uniform samplings, then the first one refined near the contact
  std::vector<std::pair<int, int>> samplings;  // (spacing R / n, refined to R / m near the contact; 0: not)
  for (const int n : options.quick ? std::vector<int>{options.per_radius.front()} : options.per_radius)
    samplings.emplace_back(n, 0);
  if (options.refine > 0) {
    if (options.refine <= options.per_radius.front())
      throw Error(fmt::format("experiment contact: --refine {} must be finer than the spacing R/{}", options.refine,
                              options.per_radius.front()));
    samplings.emplace_back(options.per_radius.front(), options.refine);
  }
  const std::vector<double> depths =
      options.quick ? std::vector<double>{0.1, 0.2, 0.3} : std::vector<double>{0.05, 0.1, 0.15, 0.2, 0.25, 0.3};
  const std::optional<MaterialModel> model = parse_enum<MaterialModel>(options.material);
  if (!model || *model == MaterialModel::COROTATED)
    throw Error(
        fmt::format("experiment contact: --material \"{}\" is not one CalculiX has (svk | neo_hookean | mooney_rivlin)",
                    options.material));
  if (options.fem_per_radius.empty()) throw Error("experiment contact: --fem-meshes needs at least one element size");
  const Scene reference_scene = block_scene(R, *model, 0);
  const int fem_threads = options.threads > 0 ? options.threads : available_cores();

  // CalculiX: the meshes, then at the finest two checks of the model itself (a tenfold contact penalty, and a
  // cylinder of the block's top area instead of its inscribed one)
  const std::vector<int> fem_meshes =
      options.quick ? std::vector<int>{options.fem_per_radius.front()} : options.fem_per_radius;
  std::vector<FemRun> fem_runs;
  for (const int n : fem_meshes)
    fem_runs.push_back(run_fem("mesh", n, 0.5 * width, 100, reference_scene.material, 0.3 * R, 6, fem_threads));
  const FemRun reference = fem_runs.back();
  if (!options.quick) {
    fem_runs.push_back(run_fem("penalty x10", reference.per_radius, 0.5 * width, 1000, reference_scene.material,
                               0.3 * R, 6, fem_threads));
    fem_runs.push_back(run_fem("equal-area cylinder", reference.per_radius, width / std::sqrt(std::numbers::pi), 100,
                               reference_scene.material, 0.3 * R, 6, fem_threads));
  }
  auto fem_csv = fmt::output_file((out / "contact-calculix.csv").string());
  fem_csv.print(
      "run,elements_per_radius,block_radius_m,penalty_e_per_h,nodes,seconds,depth_over_r,force_n,ratio_to_reference\n");
  std::string fem_table;
  for (const FemRun& run : fem_runs) {
    std::string row = fmt::format("| {} | R/{} | {:.1f} mm | {:.0f} E/h | {} | {:.1f} |", run.what, run.per_radius,
                                  1e3 * run.block_radius, run.penalty_factor, run.solution.nodes, run.solution.wall_s);
    for (const double d : depths) {
      const double f = run.solution.force_at(d * R), f_ref = reference.solution.force_at(d * R);
      fem_csv.print("{},{},{:.6g},{:.0f},{},{:.2f},{},{:.6g},{:.6f}\n", run.what, run.per_radius, run.block_radius,
                    run.penalty_factor, run.solution.nodes, run.solution.wall_s, d, f, f / f_ref);
      row += fmt::format(" {:.4f} ({:+.2f}%) |", f, 100 * (f / f_ref - 1));
    }
    fem_table += row + "\n";
  }
  fem_csv.close();
  std::string depth_header, depth_rule;
  for (const double d : depths) {
    depth_header += fmt::format(" {:.2f} R |", d);
    depth_rule += "---|";
  }
  auto force_csv = fmt::output_file((out / "contact-force.csv").string());
  force_csv.print(
      "spacing_over_r,refine_over_r,points,depth_over_r,depth_m,force_n,hertz_n,ratio_to_hertz,calculix_n,ratio_to_calculix,contacts,"
      "penetration_m,newton,seconds,physical\n");
  auto sliding_csv = fmt::output_file((out / "contact-sliding.csv").string());
  sliding_csv.print("spacing_over_r,refine_over_r,x_over_spacing,normal_n,tangential_n,contacts\n");
  std::string table, sliding_table, offsets, goal;
  for (const auto& [n, refine] : samplings) {
    const std::string label =
        refine > 0 ? fmt::format("R/{} (R/{} near the contact)", n, refine) : fmt::format("R/{}", n);
    Setup s = setup(n, *model, refine, options.threads, options.surface_map == "non_negative");
    double worst = 0;  // the largest |force / CalculiX - 1| from 0.1 R to 0.3 R
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
    offsets += fmt::format("| {} | {:.4f} R ({:.3f} mm) |\n", label, (first - s.top) / R, 1e3 * (first - s.top));
    // pressed in, depth by depth, each solve starting from the last
    for (const double d : depths) {
      sim.set_tool_pose(at(0, s.top + R - d * R));
      const auto start = std::chrono::steady_clock::now();
      const StepReport report = sim.step();
      const double took = seconds_since(start);
      if (report.status == StepStatus::FAILED)
        throw Error(fmt::format("contact: {} at depth {} R: {}", label, d, report.failure));
      const ToolLoad load = tool.load(sim.model(), sim.state().u);
      const double f = load.force.y(), f_hertz = hertz(d * R), f_fem = reference.solution.force_at(d * R);
      // an equilibrium with inverted neighbourhoods (a material collapsing under the sphere) is no result
      const RunSummary summary = sim.summary();
      const std::string physical = summary.converged ? "yes" : fmt::format("no: {}", summary.failure);
      force_csv.print("{},{},{},{},{:.6g},{:.6g},{:.6g},{:.5f},{:.6g},{:.5f},{},{:.3g},{},{:.3f},{}\n", n, refine,
                      sim.model().n_points, d, d * R, f, f_hertz, f / f_hertz, f_fem, f / f_fem, load.contacts,
                      load.penetration, report.iterations, took, summary.converged ? 1 : 0);
      table += fmt::format(
          "| {} | {} | {:.2f} | {:.4f} | {:.4f} | {:.3f} | {:.4f} | **{:.3f}** | {} | {:.2g} ({:.2g}% of the depth) | {:.1f} | {} |\n",
          label, sim.model().n_points, d, f, f_hertz, f / f_hertz, f_fem, f / f_fem, load.contacts, load.penetration,
          100 * load.penetration / (d * R), took, physical);
      fmt::print(
          "contact: {} depth {:.2f} R: {:.4f} N (CalculiX {:.4f} N, ratio {:.3f}; Hertz {:.4f} N), {} contacts, {:.1f} s\n",
          label, d, f, f_fem, f / f_fem, f_hertz, load.contacts, took);
      if (d >= 0.1 - 1e-9) worst = std::max(worst, std::abs(f / f_fem - 1));
    }
    goal += fmt::format("| {} | {:.1f}% |\n", label, 100 * worst);
    // sliding, frictionless, at 0.1 R deep over two spacings of the lattice (quasi-static: each an equilibrium)
    sim.set_tool_pose(at(0, s.top + R - 0.1 * R));
    sim.step();
    std::vector<double> normal, tangential;
    for (int k = 0; k <= 16; ++k) {
      const double x = k * spacing / 8;
      sim.set_tool_pose(at(x, s.top + R - 0.1 * R));
      const StepReport report = sim.step();
      if (report.status == StepStatus::FAILED)
        throw Error(fmt::format("contact: sliding at {}: {}", label, report.failure));
      const ToolLoad load = tool.load(sim.model(), sim.state().u);
      normal.push_back(load.force.y());
      tangential.push_back(std::hypot(load.force.x(), load.force.z()));
      sliding_csv.print("{},{},{:.4f},{:.6g},{:.6g},{}\n", n, refine, x / spacing, load.force.y(), tangential.back(),
                        load.contacts);
    }
    double mean = 0, var = 0, worst_tangential = 0;
    for (double v : normal) mean += v / static_cast<double>(normal.size());
    for (double v : normal) var += (v - mean) * (v - mean) / static_cast<double>(normal.size());
    for (double t : tangential) worst_tangential = std::max(worst_tangential, t);
    sliding_table += fmt::format("| {} | {:.4f} | {:.2f}% | {:.2f}% |\n", label, mean, 100 * std::sqrt(var) / mean,
                                 100 * worst_tangential / mean);
  }
  force_csv.close();
  sliding_csv.close();

  // friction: the first sampling once more with Coulomb friction, pressed 0.1 R deep, nudged (it sticks), then
  // dragged along x (a spacing to reach steady sliding, then measured over the next) in quasi-static steps
  // of a spacing / steps: each step's friction is what its end's pressure allows, so a vertex whose pressure grows
  // during a long step sticks short of the cone; the shortest steps are the goal's (a hand at 8 cm/s moves a
  // 32nd of R/4 in a 1 ms step), the longer ones show the convergence
  auto friction_csv = fmt::output_file((out / "contact-friction.csv").string());
  friction_csv.print(
      "spacing_over_r,refine_over_r,steps_per_spacing,x_over_spacing,pressure_n,friction_n,friction_over_pressure,drag_over_normal\n");
  std::string friction_table;
  std::vector<std::pair<std::pair<int, int>, int>> friction_runs;  // (sampling, steps per spacing)
  if (options.drag_steps.empty()) throw Error("experiment contact: --drag-steps needs at least one number of steps");
  for (const int steps : options.quick ? std::vector<int>{options.drag_steps.back()} : options.drag_steps)
    friction_runs.push_back({samplings.front(), steps});
  if (!options.quick && samplings.back().second > 0)
    friction_runs.push_back({samplings.back(), options.drag_steps.back()});
  for (const auto& [sampling, steps] : friction_runs) {
    const auto [n, refine] = sampling;
    const std::string label =
        refine > 0 ? fmt::format("R/{} (R/{} near the contact)", n, refine) : fmt::format("R/{}", n);
    Setup s = setup(n, *model, refine, options.threads, options.surface_map == "non_negative", options.friction);
    Simulation& sim = *s.sim;
    HeldTool& tool = *sim.held_tool();
    const double spacing = R / n, height = s.top + R - 0.1 * R;
    struct Sample {
      double pressure, friction, drag;
    };
    auto move_to = [&](double x) {
      sim.set_tool_pose(at(x, height));
      const StepReport report = sim.step();
      if (report.status == StepStatus::FAILED)
        throw Error(fmt::format("contact: friction at {}, x = {:.4f} spacing: {}", label, x / spacing, report.failure));
      const ToolLoad load = tool.load(sim.model(), sim.state().u);
      const Vec3 pressure = load.force - load.friction;
      const Sample sample{pressure.norm(), load.friction.norm(), -load.force.x() / load.force.y()};
      friction_csv.print("{},{},{},{:.4f},{:.6g},{:.6g},{:.5f},{:.5f}\n", n, refine, steps, x / spacing,
                         sample.pressure, sample.friction, sample.friction / sample.pressure, sample.drag);
      return sample;
    };
    // pressed in steps from first touch (each step's new contacts anchor as seen before it)
    for (const double d : {0.0, 0.025, 0.05, 0.075}) {
      sim.set_tool_pose(at(0, s.top + R - d * R));
      const StepReport report = sim.step();
      if (report.status == StepStatus::FAILED)
        throw Error(fmt::format("contact: friction at {}, pressed {} R: {}", label, d, report.failure));
    }
    move_to(0);
    const Sample nudged = move_to(1e-3 * spacing);
    const auto start = std::chrono::steady_clock::now();
    for (int k = 1; k <= steps; ++k) move_to(k * spacing / steps);
    double worst = 0, mean = 0, drag = 0;
    for (int k = 1; k <= steps; ++k) {
      const Sample sample = move_to(spacing + k * spacing / steps);
      const double ratio = sample.friction / sample.pressure;
      worst = std::max(worst, std::abs(ratio / options.friction - 1));
      mean += ratio / steps;
      drag += sample.drag / steps;
    }
    const double took = seconds_since(start) / (2 * steps);
    fmt::print(
        "contact: friction {} at {}, {} steps per spacing: sliding friction / pressure {:.4f} (worst {:.2f}% from mu), drag / "
        "normal {:.4f}; nudged {:.4f}; {:.2f} s per step\n",
        options.friction, label, steps, mean, 100 * worst, drag, nudged.friction / nudged.pressure, took);
    friction_table += fmt::format(
        "| {} | {} ({:.3f} mm) | {} | {:.4f} | {:.4f} ({:.2f}% from mu at worst) | {:.4f} | {:.2f} |\n", label, steps,
        1e3 * spacing / steps, options.friction, nudged.friction / nudged.pressure, mean, 100 * worst, drag, took);
  }
  friction_csv.close();
  auto md = fmt::output_file((out / "summary.md").string());
  md.print(
      "# Contact: a rigid sphere pressed into a block\n\n"
      "Block {} x {} x {} mm (E = {:.0e} Pa, nu = {}, {}, bottom held), a rigid frictionless sphere of "
      "radius R = {} mm pressed into the middle of its top face through the object's surface (its exact boundary at "
      "half the spacing, carried by the points), solved statically at each depth (the contact by an augmented "
      "Lagrangian: no surface vertex more than 1e-4 R inside the sphere; the contact's surface map: {}).\n\n"
      "## The reference: CalculiX\n\n"
      "An axisymmetric model (CAX8, geometrically nonlinear, the same material) of a cylinder of the block's half "
      "width and height, bottom held, and a rigid sphere (a layer of elements 10^4 times stiffer, moved by its inner "
      "nodes) in frictionless surface-to-surface contact (penalty 100 E / h). Forces in N at each depth, and their "
      "difference from the reference (the first row of the finest mesh):\n\n"
      "| run | elements at the contact | cylinder radius | penalty | nodes | ccx (s) |{}\n|---|---|---|---|---|---|{}\n{}\n"
      "## Force against depth (depth from the undeformed surface)\n\n"
      "Hertz is the small-depth limit for a half-space; the block's finite thickness (4 R) stiffens it, and the "
      "strains at 0.3 R are no longer small. The issue's goal: within 5% of CalculiX from 0.1 R to 0.3 R at R/4.\n\n"
      "| spacing | points | depth / R | force (N) | Hertz (N) | / Hertz | CalculiX (N) | / CalculiX | vertices in contact | deepest vertex inside (m) | solve (s) | a result |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|\n{}\n"
      "Largest difference from CalculiX from 0.1 R to 0.3 R:\n\n| spacing | largest difference |\n|---|---|\n{}\n"
      "## Where the surface is first felt\n\n"
      "The sphere's lowest point at first contact, above the true top face (the point-sphere contact felt it half a "
      "spacing above):\n\n| spacing | offset |\n|---|---|\n{}\n"
      "## Sliding at 0.1 R deep, frictionless\n\n"
      "17 equilibria over two spacings along x:\n\n"
      "| spacing | mean normal force (N) | normal-force ripple (std / mean) | largest tangential / normal |\n"
      "|---|---|---|---|\n{}\n"
      "## Sliding at 0.1 R deep with Coulomb friction\n\n"
      "Pressed, nudged by a thousandth of a spacing (the contact sticks: its friction stays inside the cone), dragged "
      "a spacing to slide, then measured at every equilibrium over the next spacing, in quasi-static steps of a spacing / "
      "steps (a hand at 8 cm/s moves 0.08 mm in a 1 ms step). The friction's part of the force against the "
      "pressure's (the goal: within 5% of mu), and the whole force's drag against its normal part (the tilted "
      "normals of the dragged surface add to it). A step's friction is what the pressure at its end allows: a "
      "vertex whose pressure grows during a long step sticks short of its cone, so the friction converges to mu "
      "as the steps shorten:\n\n"
      "| sampling | steps per spacing (step) | mu | nudged: friction / pressure | sliding: friction / pressure | sliding: drag / normal | solve per step (s) |\n"
      "|---|---|---|---|---|---|---|\n{}\n",
      1e3 * width, 1e3 * height, 1e3 * width, young, poisson, options.material, 1e3 * R, options.surface_map,
      depth_header, depth_rule, fem_table, table, goal, offsets, sliding_table, friction_table);
  md.close();
  if (run_plot_script("plot_contact.py", out.string(), options.plot_script) != 0) return 1;
  fmt::print("wrote {}\n", out.string());
  return 0;
}

}  // namespace pointhaptics::experiments
