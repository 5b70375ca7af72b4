#include "experiment_materials.hpp"

#include "plots.hpp"

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/fem/calculix.hpp>
#include <pointhaptics/pointhaptics.hpp>

#include <fmt/format.h>
#include <fmt/os.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>
#include <thread>

namespace pointhaptics::experiments {
namespace {

// The models CalculiX has, with the same small-strain moduli; Mooney-Rivlin splits the shear modulus 70 : 30
MaterialParams material_of(MaterialModel model, double young, double poisson) {
  MaterialParams m;
  m.model = model;
  m.young = young;
  m.poisson = poisson;
  if (model == MaterialModel::MOONEY_RIVLIN) m.c10 = 0.7, m.c01 = 0.3;
  return m;
}

struct Outcome {
  double value = NAN;  // deflection (m) or force (N)
  bool ok = false;
  std::string note;
  double seconds = 0;
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// ---- the seed's cantilever: [0, 0.15] x [0, 0.03] x [0, 0.03] m, E = 1e5 Pa, nu = 0.4, face x = 0 clamped ----
constexpr double L = 0.15, H = 0.03, W = 0.03;

struct BeamCase {
  std::string name;
  double force = 0;  // N down on the tip face; 0: gravity
};

Scene beam_scene(const MaterialParams& m, const BeamCase& c, double spacing) {
  Scene s;
  s.path = "materials-cantilever";
  s.object.size = Vec3(L, H, W);
  s.object.spacing = spacing;
  s.material = m;
  FixedSpec clamp;
  clamp.box = {Vec3(-1, -1, -1), Vec3(0, 1, 1)};
  s.fixed.push_back(clamp);
  LoadSpec load;
  if (c.force > 0) {
    load.kind = LoadKind::TRACTION;
    load.box = {Vec3(L, -1, -1), Vec3(1, 1, 1)};
    load.total = Vec3(0, -c.force, 0);
  } else {
    load.kind = LoadKind::GRAVITY;
  }
  s.loads.push_back(load);
  s.solver.kind = SolverKind::STATIC;
  return s;
}

// -u_y at the tip-face centre
double tip_deflection(const Points& X, const Points& u) {
  for (Eigen::Index k = 0; k < X.cols(); ++k)
    if ((X.col(k) - Vec3(L, H / 2, W / 2)).norm() < 1e-9) return -u(1, k);
  return NAN;
}

// a static scene solved by the point model: the outcome (converged, why not, time) and `value` of the solution
template <class Value>
Outcome solve_point_model(const Scene& scene, int threads, Value&& value) {
  const auto start = std::chrono::steady_clock::now();
  Simulation sim(build_scene_model(scene), SolverSpec{SolverKind::STATIC}, threads);
  sim.run(0.0);
  const RunSummary s = sim.summary();
  Outcome o;
  o.seconds = seconds_since(start);
  o.ok = s.converged;
  o.note = s.failure;
  o.value = value(sim, s);
  return o;
}

Outcome point_beam(const MaterialParams& m, const BeamCase& c, double spacing, int threads) {
  return solve_point_model(beam_scene(m, c, spacing), threads, [](const Simulation& sim, const RunSummary&) {
    return tip_deflection(sim.model().X, sim.state().u);
  });
}

Outcome fem_beam(const MaterialParams& m, const BeamCase& c, int nx, int threads) {
  fem::BoxProblem p;
  p.size = Vec3(L, H, W);
  p.nx = nx, p.ny = nx / 5, p.nz = nx / 5;
  fem::set_material(p, m);
  p.nlgeom = true;
  p.clamps.push_back({Vec3(-1, -1, -1), Vec3(0, 1, 1)});
  if (c.force > 0) p.tractions.push_back({{Vec3(L, -1, -1), Vec3(1, 1, 1)}, Vec3(0, -c.force, 0)});
  else p.gravity = Vec3(0, -9.81, 0);
  Outcome o;
  try {
    const fem::Solution sol = fem::solve(p, threads);
    o.value = tip_deflection(sol.nodes, sol.displacement);
    o.seconds = sol.wall_s;
    o.ok = std::isfinite(o.value);
  } catch (const Error& e) {
    o.note = e.what();
  }
  return o;
}

// ---- the flat punch: a 0.1 x 0.05 x 0.1 m block, E = 1e4 Pa, nu = 0.45, bottom held, the top face's points
// within 10 mm of its centre pushed down (scenes/punch.toml) ----
constexpr double punch_radius = 0.01, block_height = 0.05;

Scene punch_scene(const MaterialParams& m, double depth, double spacing) {
  Scene s;
  s.path = "materials-punch";
  s.object.size = Vec3(0.1, block_height, 0.1);
  s.object.origin = Vec3(-0.05, 0, -0.05);
  s.object.spacing = spacing;
  s.material = m;
  FixedSpec bottom;
  bottom.box = {Vec3(-1, -1, -1), Vec3(1, 0, 1)};
  s.fixed.push_back(bottom);
  FixedSpec punch;
  punch.cylinder = CylinderRegion{Vec3(0, block_height, 0), Vec3::UnitY(), punch_radius, 1e-4};
  punch.displacement = Vec3(0, -depth, 0);
  s.fixed.push_back(punch);
  s.solver.kind = SolverKind::STATIC;
  return s;
}

Outcome point_punch(const MaterialParams& m, double depth, double spacing, int threads) {
  // the punch pushes down
  return solve_point_model(punch_scene(m, depth, spacing), threads,
                           [](const Simulation&, const RunSummary& s) { return -s.reactions[1].y(); });
}

// Richardson's extrapolation of three solutions on meshes refined by `ratio` each time (coarse to fine), with
// the order they show; NAN when they do not converge monotonically
double richardson(double coarse, double middle, double fine, double ratio) {
  const double d1 = middle - coarse, d2 = fine - middle;
  if (!(d1 * d2 > 0) || !(std::abs(d2) < std::abs(d1))) return NAN;
  const double order = std::log(d1 / d2) / std::log(ratio);
  return fine + d2 / (std::pow(ratio, order) - 1);
}

// CalculiX: the whole depth in `increments` equal increments, the punch force printed at each. The block and
// punch are symmetric about x = 0 and z = 0: CalculiX solves the quarter x, z >= 0 with mirror planes there
// (nx / 2 elements a side, so nx is the whole block's count across), and the force is four times the quarter's
std::vector<Outcome> fem_punch(const MaterialParams& m, double depth, int increments, int nx, int threads) {
  fem::BoxProblem p;
  p.origin = Vec3(0, 0, 0);
  p.size = Vec3(0.05, block_height, 0.05);
  p.nx = nx / 2, p.ny = nx / 2, p.nz = nx / 2;
  p.symmetry = {{0, 0.0}, {2, 0.0}};
  fem::set_material(p, m);
  p.nlgeom = true;
  p.fixed_increments = increments;
  p.clamps.push_back({Vec3(-1, -1, -1), Vec3(1, 0, 1)});
  fem::Prescribed punch;
  punch.region = {Vec3(-1, block_height, -1), Vec3(1, 1, 1)};
  punch.centre = Vec3(0, block_height, 0);
  punch.radius = punch_radius;
  punch.displacement = Vec3(0, -depth, 0);
  p.prescribed.push_back(punch);
  std::vector<Outcome> out(increments);
  try {
    // ccx may stop part way (St. Venant-Kirchhoff's collapse): the depths it reached are still results
    const fem::Solution sol = fem::solve(p, threads, /*partial=*/true);
    for (Outcome& o : out) o.note = sol.failure;
    for (const fem::Reaction& r : sol.reactions.empty() ? std::vector<fem::Reaction>{} : sol.reactions[0]) {
      const int k = static_cast<int>(std::lround(r.time * increments)) - 1;
      if (k < 0 || k >= increments || std::abs(r.time * increments - (k + 1)) > 1e-6) continue;
      out[k].value = -4 * r.force.y();
      out[k].ok = true;
      out[k].note.clear();
      out[k].seconds = sol.wall_s;
    }
  } catch (const Error& e) {
    for (Outcome& o : out) o.note = e.what();
  }
  return out;
}

std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

}  // namespace

int run_materials_experiment(const MaterialsOptions& options) {
  namespace fs = std::filesystem;
  fs::create_directories(options.out);
  const fs::path out = options.out;
  const int threads = options.threads > 0 ? options.threads : available_cores();
  fem::find_ccx();
  std::vector<MaterialModel> models = {MaterialModel::SVK, MaterialModel::NEO_HOOKEAN, MaterialModel::MOONEY_RIVLIN};
  if (!options.models.empty()) {
    models.clear();
    for (const std::string& name : options.models) {
      const std::optional<MaterialModel> model = parse_enum<MaterialModel>(name);
      if (!model || *model == MaterialModel::COROTATED) {
        fmt::print(
            stderr,
            "pointhaptics: experiment materials: --models: \"{}\" is not one CalculiX has (svk | neo_hookean | mooney_rivlin)\n",
            name);
        return 1;
      }
      models.push_back(*model);
    }
  }
  auto md = fmt::output_file((out / "summary.md").string());
  md.print(
      "# Materials: the point model against CalculiX's own models\n\n"
      "Each model with the same small-strain moduli: svk as CalculiX's *ELASTIC with NLGEOM, neo_hookean as "
      "*HYPERELASTIC, NEO HOOKE (C10 = mu / 2, D1 = 2 / K), mooney_rivlin as MOONEY-RIVLIN (C10 : C01 = 70 : 30, "
      "D1 = 2 / K). CalculiX: C3D20R, NLGEOM; the reference is its finest mesh.\n\n");

  // the cantilever
  const std::vector<BeamCase> beam_cases = {{"F = 0.3 N", 0.3}, {"gravity", 0.0}};
  const std::vector<int> beam_meshes = options.quick ? std::vector<int>{20} : std::vector<int>{20, 40};
  const std::vector<double> spacings = {0.0075, 0.005};
  auto csv = fmt::output_file((out / "materials.csv").string());
  csv.print("model,case,method,spacing_or_elements,deflection_m,error_pct,seconds,converged\n");
  md.print(
      "## The seed's cantilever (E = 1e5 Pa, nu = 0.4): tip-face centre deflection\n\n"
      "| model | case | CalculiX (m) | point 7.5 mm | point 5 mm |\n|---|---|---|---|---|\n");
  for (const MaterialModel model : models) {
    const MaterialParams m = material_of(model, 1e5, 0.4);
    for (const BeamCase& c : beam_cases) {
      Outcome reference;
      for (const int nx : beam_meshes) {
        reference = fem_beam(m, c, nx, threads);
        csv.print("{},{},calculix,{}x{}x{},{:.6e},,{:.2f},{}\n", to_string(model), c.name, nx, nx / 5, nx / 5,
                  reference.value, reference.seconds, reference.ok);
        fmt::print("{} {}: CalculiX {}x{}x{}: {:.5e} m ({:.1f} s){}\n", to_string(model), c.name, nx, nx / 5, nx / 5,
                   reference.value, reference.seconds, reference.ok ? "" : " FAILED: " + first_line(reference.note));
      }
      std::string cells;
      for (const double s : spacings) {
        const Outcome o = point_beam(m, c, s, threads);
        const double error = 100 * (o.value / reference.value - 1);
        csv.print("{},{},point,{},{:.6e},{:.3f},{:.3f},{}\n", to_string(model), c.name, s, o.value, error, o.seconds,
                  o.ok);
        fmt::print("{} {}: point model s = {} m: {:.5e} m ({:+.2f}%), {:.2f} s\n", to_string(model), c.name, s, o.value,
                   error, o.seconds);
        cells += o.ok ? fmt::format(" {:+.2f}% |", error) : fmt::format(" not converged ({}) |", first_line(o.note));
      }
      md.print("| {} | {} | {:.5e} |{}\n", to_string(model), c.name, reference.value, cells);
    }
  }
  csv.close();

  // the punch
  const std::vector<double> depths = {0.001, 0.002, 0.003, 0.004, 0.005};
  // the punch's footprint is a staircase of the discretisation on both sides: finer spacings and meshes
  // approach the 10 mm disc
  std::vector<int> punch_meshes = options.punch_meshes;
  if (punch_meshes.empty()) punch_meshes = options.quick ? std::vector<int>{10} : std::vector<int>{10, 20, 40};
  for (int& n : punch_meshes) n += n % 2;  // the quarter has n / 2 a side
  const int punch_mesh = punch_meshes.back();
  // the last three meshes, each twice the one before: the edge of a flat punch is singular, so the force
  // converges slowly with the mesh; Richardson's extrapolation estimates CalculiX's converged force
  const size_t n_meshes = punch_meshes.size();
  const bool extrapolate = n_meshes >= 3 && punch_meshes[n_meshes - 1] == 2 * punch_meshes[n_meshes - 2] &&
                           punch_meshes[n_meshes - 2] == 2 * punch_meshes[n_meshes - 3];
  const std::vector<double> punch_spacings =
      options.quick ? std::vector<double>{0.005} : std::vector<double>{0.005, 0.0025};
  auto punch_csv = fmt::output_file((out / "punch.csv").string());
  punch_csv.print(
      "model,spacing_m,depth_m,calculix_n,point_n,error_pct,point_converged,point_inverted,calculix_extrapolated_n,"
      "error_extrapolated_pct,calculix_elements\n");
  auto fem_csv = fmt::output_file((out / "punch-calculix.csv").string());
  fem_csv.print("model,elements,depth_m,force_n,seconds,converged\n");
  std::string fem_md;
  md.print(
      "\n## Flat punch (block 0.1 x 0.05 x 0.1 m, E = 1e4 Pa, nu = 0.45, 10 mm radius): force against depth\n\n"
      "CalculiX {}x{}x{} elements (a quarter of them, with two mirror planes; its punch: the nodes within 10 mm of "
      "the centre), the depth in 5 fixed increments; the point model's punch: its points within 10 mm.\n\n"
      "| model | spacing (mm) | depth (mm) | CalculiX (N) | point (N) | error | against CalculiX extrapolated |\n"
      "|---|---|---|---|---|---|---|\n",
      punch_mesh, punch_mesh / 2, punch_mesh);
  for (const MaterialModel model : models) {
    const MaterialParams m = material_of(model, 1e4, 0.45);
    std::vector<Outcome> fem;
    std::vector<std::vector<Outcome>> by_mesh;
    for (const int n : punch_meshes) {
      fem = fem_punch(m, depths.back(), static_cast<int>(depths.size()), n, threads);
      by_mesh.push_back(fem);
      std::string cells;
      for (size_t k = 0; k < depths.size(); ++k) {
        fem_csv.print("{},{},{},{:.6e},{:.2f},{}\n", to_string(model), n, depths[k], fem[k].value, fem[k].seconds,
                      fem[k].ok);
        cells += fem[k].ok ? fmt::format(" {:.4f} |", fem[k].value) : " did not converge |";
      }
      fmt::print("{} punch CalculiX {}x{}x{}: {:.4f} N at 5 mm ({:.0f} s)\n", to_string(model), n, n / 2, n,
                 fem.back().value, fem.back().seconds);
      fem_md += fmt::format("| {} | {}x{}x{} |{} {:.0f} |\n", to_string(model), n, n / 2, n, cells, fem.back().seconds);
    }
    // at each depth the finest mesh that reached it (ccx may stop part way on the finest)
    std::vector<int> fem_mesh(depths.size(), punch_mesh);
    for (size_t k = 0; k < depths.size(); ++k)
      for (size_t mesh = by_mesh.size(); mesh-- > 0 && !fem[k].ok;)
        if (by_mesh[mesh][k].ok) fem[k] = by_mesh[mesh][k], fem_mesh[k] = punch_meshes[mesh];
    std::vector<double> extrapolated(depths.size(), NAN);
    if (extrapolate) {
      std::string cells;
      for (size_t k = 0; k < depths.size(); ++k) {
        const Outcome &a = by_mesh[n_meshes - 3][k], &b = by_mesh[n_meshes - 2][k], &c = by_mesh[n_meshes - 1][k];
        if (a.ok && b.ok && c.ok) extrapolated[k] = richardson(a.value, b.value, c.value, 2.0);
        cells += std::isfinite(extrapolated[k]) ? fmt::format(" {:.4f} |", extrapolated[k]) : " - |";
      }
      fem_md += fmt::format("| {} | extrapolated |{} |\n", to_string(model), cells);
    }
    for (const double spacing : punch_spacings)
      for (size_t k = 0; k < depths.size(); ++k) {
        const Outcome o = point_punch(m, depths[k], spacing, threads);
        const double error = fem[k].ok ? 100 * (o.value / fem[k].value - 1) : NAN;
        const double error_extrapolated = 100 * (o.value / extrapolated[k] - 1);
        punch_csv.print("{},{},{},{:.6e},{:.6e},{:.3f},{},{},{:.6e},{:.3f},{}\n", to_string(model), spacing, depths[k],
                        fem[k].value, o.value, error, o.ok, o.note.find("inverted") != std::string::npos,
                        extrapolated[k], error_extrapolated, fem_mesh[k]);
        fmt::print("{} punch s = {} m, {} mm: CalculiX {} N, point {:.4f} N{} ({:+.2f}%, {:.1f} s)\n", to_string(model),
                   spacing, 1e3 * depths[k], fem[k].ok ? fmt::format("{:.4f}", fem[k].value) : "no result", o.value,
                   o.ok ? "" : " NOT converged", error, o.seconds);
        md.print("| {} | {} | {} | {} | {} | {} | {} |\n", to_string(model), 1e3 * spacing, 1e3 * depths[k],
                 fem[k].ok ? fmt::format("{:.4f}{}", fem[k].value,
                                         fem_mesh[k] == punch_mesh ? "" : fmt::format(" ({} across)", fem_mesh[k]))
                           : "did not converge",
                 o.ok ? fmt::format("{:.4f}", o.value) : fmt::format("{:.4f} ({})", o.value, first_line(o.note)),
                 fem[k].ok && o.ok ? fmt::format("{:+.2f}%", error) : "",
                 std::isfinite(error_extrapolated) && o.ok ? fmt::format("{:+.2f}%", error_extrapolated) : "");
      }
  }
  punch_csv.close();
  fem_csv.close();
  md.print(
      "\nCalculiX's punch force against its mesh (N; `punch-calculix.csv`; extrapolated: Richardson's extrapolation of the last three meshes with the order they show, the converged force's estimate):\n\n| model | elements | 1 mm | 2 mm | 3 mm | "
      "4 mm | 5 mm | ccx (s) |\n|---|---|---|---|---|---|---|---|\n{}",
      fem_md);
  md.close();
  if (run_plot_script("plot_materials.py", out.string(), options.plot_script) != 0) return 1;
  fmt::print("wrote {}\n", out.string());
  return 0;
}

}  // namespace pointhaptics::experiments
