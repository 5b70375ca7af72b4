#include "experiment_cantilever.hpp"

#include "plots.hpp"

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/fem/calculix.hpp>
#include <pointhaptics/pointhaptics.hpp>

#include <fmt/format.h>
#include <fmt/os.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <optional>
#include <thread>

namespace pointhaptics::experiments {
namespace {

// seed §2: the cantilever [0, 0.15] x [0, 0.03] x [0, 0.03] m, E = 1e5 Pa, nu = 0.4, rho = 1000 kg/m^3
constexpr double L = 0.15, H = 0.03, W = 0.03, young = 1e5, poisson = 0.4, density = 1000.0, g = 9.81;

struct LoadCase {
  std::string name;
  double force = 0;  // N in -y on the tip face; 0 with gravity
  bool gravity = false;
};

struct Deflection {
  double centre = 0;  // -u_y at the tip-face centre (0.15, 0.015, 0.015)
  double mean = 0;    // mean -u_y over the tip-face points / nodes
  double corner = 0;  // -u_y at the seed's upper right point of the front face of the tip (0.15, 0.03, 0.03)
};

Deflection deflection_of(const Points& X, const Points& u) {
  Deflection d;
  int n = 0;
  bool centre_found = false;
  double dy = 1e300, dz = 1e300;  // the tip face's nearest node rows to the centre, when it has no node there
  for (Eigen::Index k = 0; k < X.cols(); ++k) {
    const Vec3 p = X.col(k);
    if (std::abs(p.x() - L) > 1e-9) continue;
    d.mean -= u(1, k);
    ++n;
    if ((p - Vec3(L, H / 2, W / 2)).norm() < 1e-9) d.centre = -u(1, k), centre_found = true;
    if ((p - Vec3(L, H, W)).norm() < 1e-9) d.corner = -u(1, k);
    if (std::abs(p.y() - H / 2) > 1e-9) dy = std::min(dy, std::abs(p.y() - H / 2));
    if (std::abs(p.z() - W / 2) > 1e-9) dz = std::min(dz, std::abs(p.z() - W / 2));
  }
  d.mean /= std::max(n, 1);
  if (!centre_found) {
    // a mesh with an odd number of elements across (16x3x3) has no node at the face centre, the centre of
    // one element's face: the 20-node brick's face interpolates it there as -1/4 of each of the face's
    // corners and 1/2 of each of its mid-edge nodes
    const std::array<std::pair<Vec3, double>, 8> face{{{{L, H / 2 - dy, W / 2 - dz}, -0.25},
                                                       {{L, H / 2 + dy, W / 2 - dz}, -0.25},
                                                       {{L, H / 2 - dy, W / 2 + dz}, -0.25},
                                                       {{L, H / 2 + dy, W / 2 + dz}, -0.25},
                                                       {{L, H / 2 - dy, W / 2}, 0.5},
                                                       {{L, H / 2 + dy, W / 2}, 0.5},
                                                       {{L, H / 2, W / 2 - dz}, 0.5},
                                                       {{L, H / 2, W / 2 + dz}, 0.5}}};
    int found = 0;
    double centre = 0;
    for (const auto& [q, weight] : face)
      for (Eigen::Index k = 0; k < X.cols(); ++k)
        if ((X.col(k) - q).norm() < 1e-9) {
          centre -= weight * u(1, k);
          ++found;
          break;
        }
    d.centre = found == 8 ? centre : std::numeric_limits<double>::quiet_NaN();
  }
  return d;
}

// Timoshenko beam theory (shear coefficient 5/6 of a rectangle)
double timoshenko(const LoadCase& c) {
  const double I = W * H * H * H / 12, A = W * H, G = young / (2 * (1 + poisson)), kappa = 5.0 / 6.0;
  if (c.gravity) {
    const double q = density * g * A;
    return q * std::pow(L, 4) / (8 * young * I) + q * L * L / (2 * kappa * G * A);
  }
  return c.force * L * L * L / (3 * young * I) + c.force * L / (kappa * G * A);
}

Scene beam_scene(const LoadCase& c, double spacing, double support_factor, double support) {
  Scene s;
  s.path = "cantilever";
  s.object.shape = ShapeKind::BOX;
  s.object.size = Vec3(L, H, W);
  s.object.spacing = spacing;
  s.material.young = young;
  s.material.poisson = poisson;
  s.material.density = density;
  s.kernel.support_factor = support_factor;
  s.kernel.support = support;
  FixedSpec clamp;
  clamp.box = {Vec3(-1, -1, -1), Vec3(0, 1, 1)};
  s.fixed.push_back(clamp);
  LoadSpec load;
  if (c.gravity) {
    load.kind = LoadKind::GRAVITY;
    load.g = Vec3(0, -g, 0);
  } else {
    load.kind = LoadKind::TRACTION;
    load.box = {Vec3(L, -1, -1), Vec3(1, 1, 1)};
    load.total = Vec3(0, -c.force, 0);
  }
  s.loads.push_back(load);
  s.solver.kind = SolverKind::STATIC;
  s.solver.preconditioner = Preconditioner::TWO_LEVEL;  // the bending modes by a coarse level (docs/performance.md)
  // Newton to a relative residual of 1e-4 (ccx: 1e-5 of the mean force, the *CONTROLS of fem/calculix.cpp): the tip deflection
  // is then within 2e-6 of a solve to the default 1e-8 (s = 5 mm, 0.01 N), which needs a fourth Newton step
  s.solver.tolerance = 1e-4;
  return s;
}

struct PointRun {
  Deflection d;
  index_t points = 0;
  double h = 0, seconds = 0;
  long long iterations = 0, cg_iterations = 0;
  Points X, u;
};

PointRun solve_point_model(const Scene& scene, int threads) {
  const auto start = std::chrono::steady_clock::now();
  Simulation sim(build_scene_model(scene), scene.solver, threads);
  sim.run(0.0);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const RunSummary s = sim.summary();  // (a report: not timed)
  if (!s.converged)
    throw Error(fmt::format("point model at spacing {} did not converge: {}", scene.object.spacing, s.failure));
  PointRun r;
  r.seconds = seconds;
  r.points = sim.model().n_points;
  r.h = sim.model().h;
  r.iterations = s.iterations;
  r.cg_iterations = s.cg_iterations;
  r.d = deflection_of(sim.model().X, sim.state().u);
  r.X = sim.model().X;
  r.u = sim.state().u;
  return r;
}

fem::BoxProblem fem_problem(const LoadCase& c, int nx, int ny, int nz, bool nlgeom) {
  fem::BoxProblem p;
  p.size = Vec3(L, H, W);
  p.nx = nx;
  p.ny = ny;
  p.nz = nz;
  p.young = young;
  p.poisson = poisson;
  p.density = density;
  p.nlgeom = nlgeom;
  // up to 0.01 N the tip turns about a degree, and one increment gives ccx's deflection to 1e-6 of its
  // automatic increments (from 5% of the load) in a fifth of the time (0.25 against 1.27 s at 16x3x3): the
  // speed at equal accuracy (below) must time ccx as cheaply as it reaches that accuracy
  if (nlgeom && !c.gravity && c.force <= 0.01) p.fixed_increments = 1;
  p.clamps.push_back({Vec3(-1, -1, -1), Vec3(0, 1, 1)});
  if (c.gravity) p.gravity = Vec3(0, -g, 0);
  else p.tractions.push_back({{Vec3(L, -1, -1), Vec3(1, 1, 1)}, Vec3(0, -c.force, 0)});
  return p;
}

// Richardson extrapolation from three meshes refined by 2: d_inf = d3 + (d3 - d2)^2 / ((d2 - d1) - (d3 - d2))
// when the differences shrink monotonically; else the finest value.
double extrapolate(double d1, double d2, double d3) {
  const double a = d2 - d1, b = d3 - d2;
  if (a == 0 || b == 0 || a * b < 0 || std::abs(b) >= std::abs(a)) return d3;
  return d3 + b * b / (a - b);
}

}  // namespace

int run_cantilever_experiment(const CantileverOptions& options) {
  namespace fs = std::filesystem;
  fs::create_directories(options.out);
  const fs::path out = options.out;
  const int threads = options.threads > 0 ? options.threads : available_cores();
  fem::find_ccx();  // fail early, with the installation hint

  std::vector<LoadCase> cases;
  for (double f : options.quick ? std::vector<double>{0.01, 0.3} : std::vector<double>{0.003, 0.01, 0.03, 0.1, 0.3})
    cases.push_back({fmt::format("F = {} N", f), f, false});
  if (!options.quick) cases.push_back({"gravity", 0.0, true});
  const std::vector<double> spacings =
      options.quick ? std::vector<double>{0.015, 0.0075} : std::vector<double>{0.015, 0.0075, 0.005, 0.00375};
  const std::vector<double> factors = options.quick ? std::vector<double>{2.0} : std::vector<double>{2.0, 2.5};
  // FEM meshes (x, y, z elements), each refined by 2; the finest two plus extrapolation give "converged"
  const std::vector<std::array<int, 3>> meshes =
      options.quick ? std::vector<std::array<int, 3>>{{10, 2, 2}, {20, 4, 4}}
                    : std::vector<std::array<int, 3>>{{10, 2, 2}, {20, 4, 4}, {40, 8, 8}};

  auto csv = fmt::output_file((out / "cantilever.csv").string());
  csv.print(
      "case,force_n,method,spacing_m,support_factor,h_m,points_or_elements,d_centre_m,d_mean_m,d_corner_m,"
      "error_centre_pct,seconds,iterations\n");
  struct Row {
    std::string method;
    double spacing, factor, h, d, error, seconds;
  };
  std::vector<std::vector<Row>> table(cases.size());
  std::vector<double> reference(cases.size());
  std::string cost_lines;
  // F = 0.01 N: every run's time and error, for the speed at equal accuracy (issue 19)
  struct Timed {
    std::string label;
    double seconds, error;
  };
  std::vector<Timed> timed_fem, timed_point;
  PointRun deformed_point;
  fem::Solution deformed_fem;

  for (size_t ci = 0; ci < cases.size(); ++ci) {
    const LoadCase& c = cases[ci];
    fmt::print("{}:\n", c.name);
    // CalculiX NLGEOM on three meshes, extrapolated
    std::vector<double> fem_d;
    std::vector<double> fem_s;
    for (const auto& m : meshes) {
      const fem::Solution sol = fem::solve(fem_problem(c, m[0], m[1], m[2], true), threads);
      const Deflection d = deflection_of(sol.nodes, sol.displacement);
      fem_d.push_back(d.centre);
      fem_s.push_back(sol.wall_s);
      fmt::print("  CalculiX NLGEOM {}x{}x{}: d = {:.5e} m ({:.1f} s)\n", m[0], m[1], m[2], d.centre, sol.wall_s);
      csv.print("{},{},calculix_nlgeom,{},,,{},{:.6e},{:.6e},{:.6e},,{:.3f},\n", c.name, c.force, L / m[0],
                m[0] * m[1] * m[2], d.centre, d.mean, d.corner, sol.wall_s);
      if (!c.gravity && c.force == cases.back().force && &m == &meshes[1]) deformed_fem = sol;  // 20x4x4
    }
    const size_t nm = fem_d.size();
    reference[ci] = nm >= 3 ? extrapolate(fem_d[nm - 3], fem_d[nm - 2], fem_d[nm - 1]) : fem_d.back();
    if (c.force == 0.01) {
      for (size_t k = 0; k < meshes.size(); ++k)
        timed_fem.push_back({fmt::format("CalculiX NLGEOM {}x{}x{}", meshes[k][0], meshes[k][1], meshes[k][2]),
                             fem_s[k], 100 * (fem_d[k] / reference[ci] - 1)});
      // a mesh between the refinement steps, for the cheapest one within 1% (not in the extrapolation)
      if (!options.quick) {
        const fem::Solution sol = fem::solve(fem_problem(c, 16, 3, 3, true), threads);
        const double d = deflection_of(sol.nodes, sol.displacement).centre;
        fmt::print("  CalculiX NLGEOM 16x3x3: d = {:.5e} m ({:.1f} s)\n", d, sol.wall_s);
        timed_fem.push_back({"CalculiX NLGEOM 16x3x3", sol.wall_s, 100 * (d / reference[ci] - 1)});
      }
    }
    const fem::Solution lin = fem::solve(fem_problem(c, meshes[1][0], meshes[1][1], meshes[1][2], false), threads);
    const double d_linear = deflection_of(lin.nodes, lin.displacement).centre;
    const double d_timo = timoshenko(c);
    csv.print("{},{},calculix_extrapolated,,,,,{:.6e},,,,,\n", c.name, c.force, reference[ci]);
    csv.print("{},{},calculix_linear,{},,,{},{:.6e},,,,{:.3f},\n", c.name, c.force, L / meshes[1][0],
              meshes[1][0] * meshes[1][1] * meshes[1][2], d_linear, lin.wall_s);
    csv.print("{},{},timoshenko,,,,,{:.6e},,,{:.3f},,\n", c.name, c.force, d_timo, 100 * (d_timo / reference[ci] - 1));
    auto error = [&](double d) { return 100 * (d / reference[ci] - 1); };
    table[ci].push_back({"CalculiX NLGEOM (extrapolated)", 0, 0, 0, reference[ci], 0, 0});
    table[ci].push_back({"CalculiX linear", 0, 0, 0, d_linear, error(d_linear), lin.wall_s});
    table[ci].push_back({"Timoshenko (linear)", 0, 0, 0, d_timo, error(d_timo), 0});
    // point model: our settings at each spacing and support, then the seed's own (h = 0.1 m at 15 mm)
    struct Setting {
      double spacing, factor, support;
    };
    std::vector<Setting> settings;
    for (double f : factors)
      for (double s : spacings) settings.push_back({s, f, 0.0});
    settings.push_back({0.015, 0.0, 0.1});
    for (const Setting& st : settings) {
      const PointRun r =
          solve_point_model(beam_scene(c, st.spacing, st.support > 0 ? 2.0 : st.factor, st.support), threads);
      const std::string method = st.support > 0 ? "point_seed_h" : "point";
      fmt::print("  point model s = {} m, h = {:.4g} m ({} points): d = {:.5e} m ({:+.2f}%), {:.3f} s\n", st.spacing,
                 r.h, r.points, r.d.centre, error(r.d.centre), r.seconds);
      csv.print("{},{},{},{},{},{},{},{:.6e},{:.6e},{:.6e},{:.4f},{:.4f},{}\n", c.name, c.force, method, st.spacing,
                st.support > 0 ? r.h / st.spacing : st.factor, r.h, r.points, r.d.centre, r.d.mean, r.d.corner,
                error(r.d.centre), r.seconds, r.iterations);
      table[ci].push_back({st.support > 0 ? "point, seed's h = 0.1 m" : fmt::format("point, h = {}s", st.factor),
                           st.spacing, st.factor, r.h, r.d.centre, error(r.d.centre), r.seconds});
      if (!c.gravity && c.force == cases.back().force && st.spacing == 0.0075 && st.factor == 2.0 && st.support == 0)
        deformed_point = r;
      if (c.force == 0.01 && st.factor == 2.0 && st.support == 0)
        timed_point.push_back(
            {fmt::format("point model, s = {} m ({} points)", st.spacing, r.points), r.seconds, error(r.d.centre)});
      if (c.force == 0.01 && st.factor == 2.0 && st.support == 0) {
        cost_lines +=
            fmt::format("- F = 0.01 N, point model at s = {} m ({} points): {:.3f} s static solve, error {:+.2f}%\n",
                        st.spacing, r.points, r.seconds, error(r.d.centre));
        if (st.spacing == spacings.back())
          for (size_t k = 0; k < meshes.size(); ++k)
            cost_lines += fmt::format("- F = 0.01 N, CalculiX NLGEOM {}x{}x{}: {:.2f} s, error {:+.2f}%\n",
                                      meshes[k][0], meshes[k][1], meshes[k][2], fem_s[k], error(fem_d[k]));
      }
    }
  }
  csv.close();

  // the haptic case: a point load on the upper face at mid-span, vs CalculiX with the same force on one cell
  const double s_pl = 0.0075, f_pl = 0.01;
  Scene pl = beam_scene({"point", 0, false}, s_pl, 2.0, 0.0);
  pl.loads.clear();
  const PointCloud cloud = sample_object(pl);
  index_t loaded = 0;
  for (index_t i = 0; i < cloud.size(); ++i)
    if ((cloud.X.col(i) - Vec3(L / 2, H, W / 2)).norm() < (cloud.X.col(loaded) - Vec3(L / 2, H, W / 2)).norm())
      loaded = i;
  LoadSpec point_load;
  point_load.kind = LoadKind::POINT;
  point_load.point = loaded;
  point_load.force = Vec3(0, -f_pl, 0);
  pl.loads.push_back(point_load);
  const PointRun pr = solve_point_model(pl, threads);
  // linear FEM: the deflection (~0.2 mm) is far inside the small-strain range, and linear ccx takes seconds
  fem::BoxProblem pf = fem_problem({"point", 0, false}, 40, 8, 8, false);
  pf.tractions.clear();
  pf.tractions.push_back(
      {{Vec3(L / 2 - s_pl / 2, H, W / 2 - s_pl / 2), Vec3(L / 2 + s_pl / 2, H, W / 2 + s_pl / 2)}, Vec3(0, -f_pl, 0)});
  const fem::Solution fs_pl = fem::solve(pf, threads);
  auto pl_csv = fmt::output_file((out / "point-load.csv").string());
  pl_csv.print("y_m,point_uy_m,calculix_uy_m\n");
  bool monotone = true;
  double previous = -1, bottom_point = 0, bottom_fem = 0;
  for (double y = H; y > -1e-12; y -= s_pl) {
    double up = NAN, uf = NAN;
    for (index_t i = 0; i < pr.points; ++i)
      if ((pr.X.col(i) - Vec3(L / 2, y, W / 2)).norm() < 1e-9) up = pr.u(1, i);
    for (Eigen::Index k = 0; k < fs_pl.nodes.cols(); ++k)
      if ((fs_pl.nodes.col(k) - Vec3(L / 2, y, W / 2)).norm() < 1e-9) uf = fs_pl.displacement(1, k);
    pl_csv.print("{:.5f},{:.6e},{:.6e}\n", y, up, uf);
    // the downward displacement shrinks (or stays) from the loaded point down to the bottom face
    if (previous >= 0 && -up > previous * (1 + 1e-9)) monotone = false;
    previous = -up;
    bottom_point = -up;
    bottom_fem = -uf;
  }
  pl_csv.close();
  const double pl_error = 100 * (bottom_point / bottom_fem - 1);
  fmt::print("point load: bottom deflection {:.5e} m vs CalculiX {:.5e} m ({:+.2f}%), profile {}\n", bottom_point,
             bottom_fem, pl_error, monotone ? "monotone" : "NOT monotone");

  // deformed shapes of the largest tip load, for the side-by-side figure
  auto def_csv = fmt::output_file((out / "deformed.csv").string());
  def_csv.print("model,x,y,z,ux,uy,uz\n");
  for (index_t i = 0; i < deformed_point.points; ++i)
    def_csv.print("point,{},{},{},{},{},{}\n", deformed_point.X(0, i), deformed_point.X(1, i), deformed_point.X(2, i),
                  deformed_point.u(0, i), deformed_point.u(1, i), deformed_point.u(2, i));
  for (Eigen::Index k = 0; k < deformed_fem.nodes.cols(); ++k)
    def_csv.print("calculix,{},{},{},{},{},{}\n", deformed_fem.nodes(0, k), deformed_fem.nodes(1, k),
                  deformed_fem.nodes(2, k), deformed_fem.displacement(0, k), deformed_fem.displacement(1, k),
                  deformed_fem.displacement(2, k));
  def_csv.close();

  // summary
  auto md = fmt::output_file((out / "summary.md").string());
  md.print("# Cantilever: point model vs CalculiX (seed Fig. 3-4)\n\n");
  std::string mesh_list;
  for (const auto& m : meshes) mesh_list += fmt::format("{}{}x{}x{}", mesh_list.empty() ? "" : ", ", m[0], m[1], m[2]);
  md.print(
      "Beam [0, 0.15] x [0, 0.03] x [0, 0.03] m, E = 1e5 Pa, nu = 0.4, rho = 1000 kg/m^3, face x = 0 clamped, "
      "uniform traction in -y on face x = 0.15 (or gravity). Deflection d = -u_y at the tip-face centre. Errors "
      "are against CalculiX NLGEOM (St. Venant-Kirchhoff, C3D20R) on {} elements ({}). Point model: static "
      "Newton solve, cell volumes, poly6 kernel, hourglass alpha = {} (the defaults).\n\n",
      mesh_list, meshes.size() >= 3 ? "Richardson-extrapolated from the finest three" : "the finest",
      MaterialParams{}.hourglass);
  for (size_t ci = 0; ci < cases.size(); ++ci) {
    md.print("## {}\n\n| method | spacing (m) | h (m) | d (m) | error | time (s) |\n|---|---|---|---|---|---|\n",
             cases[ci].name);
    for (const Row& r : table[ci])
      md.print("| {} | {} | {} | {:.5e} | {} | {} |\n", r.method, r.spacing > 0 ? fmt::format("{}", r.spacing) : "",
               r.h > 0 ? fmt::format("{:.4g}", r.h) : "", r.d,
               r.method.rfind("CalculiX NLGEOM", 0) == 0 ? "" : fmt::format("{:+.2f}%", r.error),
               r.seconds > 0 ? fmt::format("{:.3f}", r.seconds) : "");
    md.print("\n");
  }
  md.print(
      "## Point load (the haptic case)\n\n{} N on point {} at ({}, {}, {}) m, spacing {} m; CalculiX: the same force as a "
      "uniform traction on one sampling cell around it (40x8x8 elements, linear).\n\n"
      "- displacement down the depth below the load: {}\n- bottom-face deflection below the load: point model {:.5e} m, "
      "CalculiX {:.5e} m ({:+.2f}%)\n\n",
      f_pl, loaded, L / 2, H, W / 2, s_pl, monotone ? "monotone (no zig-zag)" : "NOT monotone", bottom_point,
      bottom_fem, pl_error);
  md.print("## Cost\n\n{}\n", cost_lines);
  // the cheapest run of each within 1% of the reference
  auto cheapest = [](const std::vector<Timed>& runs) -> const Timed* {
    const Timed* best = nullptr;
    for (const Timed& t : runs)
      if (std::abs(t.error) <= 1.0 && (!best || t.seconds < best->seconds)) best = &t;
    return best;
  };
  const Timed *best_point = cheapest(timed_point), *best_fem = cheapest(timed_fem);
  md.print("## Speed at equal accuracy (F = 0.01 N, within 1% of the reference)\n\n{}",
           options.quick
               ? "(--quick: the reference is the finest mesh run, not the extrapolated one; the full run decides)\n\n"
               : "");
  if (best_point && best_fem) {
    const std::string line = fmt::format(
        "the cheapest point model within 1%: {} ({:.3f} s, {:+.2f}%); the cheapest CalculiX: {} "
        "({:.2f} s, {:+.2f}%); the point model is {:.0f}x faster",
        best_point->label, best_point->seconds, best_point->error, best_fem->label, best_fem->seconds, best_fem->error,
        best_fem->seconds / best_point->seconds);
    md.print(
        "{} (each timed from its input: the point model's sampling, neighbour search and static solve; ccx's run "
        "with reading the deck and writing results).\n",
        line);
    fmt::print("speed at equal accuracy: {}\n", line);
  } else {
    md.print("no run of {} reached 1% in this set\n", best_point ? "CalculiX" : "the point model");
  }
  md.close();

  // plots (matplotlib from Debian's python3-matplotlib)
  if (run_plot_script("plot_cantilever.py", out.string(), options.plot_script) != 0) return 1;
  fmt::print("wrote {}\n", out.string());
  return 0;
}

}  // namespace pointhaptics::experiments
