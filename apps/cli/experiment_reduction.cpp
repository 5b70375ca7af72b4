#include "experiment_reduction.hpp"

#include "plots.hpp"

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/fem/calculix.hpp>
#include <pointhaptics/pointhaptics.hpp>
#include <pointhaptics/core/run_control.hpp>
#include <pointhaptics/mechanics/tangent.hpp>
#include <pointhaptics/mechanics/tangent_matrix.hpp>
#include <pointhaptics/solvers/sparse_cholesky.hpp>

#include <fmt/format.h>
#include <fmt/os.h>

#include <array>
#include <chrono>
#include <cmath>
#include <algorithm>
#include <filesystem>
#include <map>
#include <numbers>

namespace pointhaptics::experiments {
namespace {

// A cantilever held at x = 0 under a uniform traction on one face, T times `direction` in all.
struct Beam {
  std::string name, description;
  Vec3 size = Vec3::Zero();
  double spacing = 0;
  MaterialParams material;
  fem::Box loaded;  ///< the face the traction is spread over
  Vec3 direction = Vec3::Zero();
  std::vector<double> loads;  ///< T, N: the static cases, up to a tip displacement of about 20% of the length
  double sudden_load = 0;     ///< N: the dynamic case, applied at t = 0 and held
  double dt = 0, duration = 0;
  std::array<int, 3> mesh{};  ///< CalculiX's coarsest mesh (x, y, z elements); the next is twice as fine
};

std::vector<Beam> beams(bool quick) {
  std::vector<Beam> out;
  Beam seed;  // the seed's cantilever (§2), its tip face pulled down
  seed.name = "seed";
  seed.description = "seed cantilever 0.15 x 0.03 x 0.03 m, E = 1e5 Pa, nu = 0.4, tip traction -y";
  seed.size = Vec3(0.15, 0.03, 0.03);
  seed.spacing = 0.0075;
  seed.material.young = 1e5;
  seed.material.poisson = 0.4;
  seed.material.density = 1000;
  seed.material.damping = 2;
  seed.loaded = {Vec3(0.15, -1, -1), Vec3(1, 1, 1)};
  seed.direction = Vec3(0, -1, 0);
  seed.loads = quick ? std::vector<double>{0.01, 0.2} : std::vector<double>{0.01, 0.05, 0.1, 0.2};
  seed.sudden_load = 0.1;
  seed.dt = 2e-3;
  seed.duration = 1.0;
  seed.mesh = {20, 4, 4};
  out.push_back(seed);
  // other proportions, material and load than anything shipped: flat, lighter and stiffer, pressed on its whole
  // top face at a slant, so it bends about both axes
  Beam check;
  check.name = "check";
  check.description =
      "check beam 0.24 x 0.02 x 0.04 m, E = 3e5 Pa, nu = 0.3, rho = 1200, top-face traction along (0, -1, 0.3)";
  check.size = Vec3(0.24, 0.02, 0.04);
  check.spacing = quick ? 0.005 : 0.004;
  check.material.young = 3e5;
  check.material.poisson = 0.3;
  check.material.density = 1200;
  check.material.damping = 1;
  check.loaded = {Vec3(-1, 0.02, -1), Vec3(1, 1, 1)};
  check.direction = Vec3(0, -1, 0.3);
  check.loads = quick ? std::vector<double>{0.02, 0.25} : std::vector<double>{0.02, 0.08, 0.16, 0.25};
  check.sudden_load = 0.12;
  check.dt = 5e-3;
  check.duration = 1.5;
  check.mesh = {24, 2, 4};
  out.push_back(check);
  return out;
}

Scene beam_scene(const Beam& beam, double load, SolverKind kind, int modes) {
  Scene s;
  s.path = beam.name;
  s.object.shape = ShapeKind::BOX;
  s.object.size = beam.size;
  s.object.spacing = beam.spacing;
  s.material = beam.material;
  FixedSpec clamp;
  clamp.box = {Vec3(-1, -1, -1), Vec3(0, 1, 1)};
  s.fixed.push_back(clamp);
  LoadSpec traction;
  traction.kind = LoadKind::TRACTION;
  traction.box = {beam.loaded.min, beam.loaded.max};
  traction.total = load * beam.direction;
  s.loads.push_back(traction);
  s.solver.kind = kind;
  s.solver.dt = beam.dt;
  s.solver.duration = beam.duration;
  if (kind == SolverKind::STATIC && modes == 0) s.solver.preconditioner = Preconditioner::TWO_LEVEL;
  s.solver.reduction.modes = modes;  // 0: the full model; the basis made every time (no cache)
  return s;
}

// the mean displacement of the tip face x = L's points or nodes
Vec3 tip_of(const Points& X, const Points& u, double length) {
  Vec3 sum = Vec3::Zero();
  int n = 0;
  for (Eigen::Index k = 0; k < X.cols(); ++k)
    if (std::abs(X(0, k) - length) < 1e-9) {
      sum += u.col(k);
      ++n;
    }
  return n ? Vec3(sum / n) : Vec3::Zero();
}

struct StaticRun {
  Vec3 tip = Vec3::Zero();
  double seconds = 0, setup_s = 0, first_frequency_hz = 0;
};

StaticRun solve_static(const Beam& beam, double load, int modes, int threads) {
  const Scene scene = beam_scene(beam, load, SolverKind::STATIC, modes);
  const auto start = std::chrono::steady_clock::now();
  Simulation sim(build_scene_model(scene), scene.solver, threads);
  sim.run(0);
  StaticRun r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const RunSummary s = sim.summary();
  if (!s.converged)
    throw Error(fmt::format("{} at {} N, {}: did not converge: {}", beam.name, load,
                            modes ? fmt::format("r = {}", modes) : std::string("full"), s.failure));
  r.tip = tip_of(sim.model().X, sim.state().u, beam.size.x());
  r.setup_s = s.reduction.setup_s;
  r.first_frequency_hz = s.reduction.first_frequency_hz;
  return r;
}

// the tip's displacement at every step after a load applied at t = 0
std::vector<Vec3> sudden_load_history(const Beam& beam, int modes, int threads) {
  const Scene scene = beam_scene(beam, beam.sudden_load, SolverKind::IMPLICIT, modes);
  Simulation sim(build_scene_model(scene), scene.solver, threads);
  std::vector<Vec3> tip;
  sim.run(beam.duration, [&](long long, long long) {
    tip.push_back(tip_of(sim.model().X, sim.state().u, beam.size.x()));
    return true;
  });
  if (!sim.summary().converged)
    throw Error(fmt::format("{}: the sudden load's run did not converge: {}", beam.name, sim.summary().failure));
  return tip;
}

// the largest distance between two histories over the largest displacement of the reference
double history_error(const std::vector<Vec3>& history, const std::vector<Vec3>& reference) {
  double worst = 0, largest = 0;
  for (std::size_t k = 0; k < reference.size() && k < history.size(); ++k) {
    worst = std::max(worst, (history[k] - reference[k]).norm());
    largest = std::max(largest, reference[k].norm());
  }
  return largest > 0 ? worst / largest : 0.0;
}

Vec3 calculix_tip(const Beam& beam, double load, int refinement, int threads, double& seconds) {
  fem::BoxProblem p;
  p.size = beam.size;
  p.nx = beam.mesh[0] * refinement;
  p.ny = beam.mesh[1] * refinement;
  p.nz = beam.mesh[2] * refinement;
  p.young = beam.material.young;
  p.poisson = beam.material.poisson;
  p.density = beam.material.density;
  p.nlgeom = true;
  p.clamps.push_back({Vec3(-1, -1, -1), Vec3(0, 1, 1)});
  p.tractions.push_back({beam.loaded, load * beam.direction});
  const fem::Solution sol = fem::solve(p, threads);
  seconds = sol.wall_s;
  return tip_of(sol.nodes, sol.displacement, beam.size.x());
}

// The full model's lowest natural frequency with its exact rest tangent, by inverse iteration: each solve by
// conjugate gradients preconditioned with the assembled tangent's Cholesky factor. The factor's own eigenvalues
// (the Lanczos solve of reduction/modal_basis.hpp) are a little high: its hourglass part is a bound of the exact
// one; the reduced model's polynomial, and so its frequency, has the exact tangent.
double full_first_frequency(const Beam& beam, int threads) {
  const Model model = build_scene_model(beam_scene(beam, 0.0, SolverKind::STATIC, 0));
  Workspace ws(model, threads);
  const index_t n = model.n_points;
  Tangent tangent;
  tangent.linearise(model, Points::Zero(3, n), TangentMode::EXACT, &ws);
  TangentMatrix assembled;
  assemble_tangent(model, tangent, assembled, &ws);
  SparseCholesky factor;
  factor.analyse(model, assembled);
  if (!factor.factorise(assembled))
    throw Error(fmt::format("{}: the rest tangent is not positive definite", beam.name));
  const auto held_at_zero = [&](Points& p) {
    for (index_t i = 0; i < n; ++i)
      if (model.fixed[static_cast<std::size_t>(i)]) p.col(i).setZero();
  };
  const auto dot = [](const Points& a, const Points& b) { return (a.array() * b.array()).sum(); };
  Points K_of(3, n);
  const auto apply_K = [&](const Points& x, Points& out) {
    tangent.apply(model, x, ws, out);
    held_at_zero(out);
  };
  // start from a bend along the load: u_load ~ x^2
  Points x = Points::Zero(3, n);
  for (index_t i = 0; i < n; ++i) x.col(i) = beam.direction * model.X(0, i) * model.X(0, i);
  held_at_zero(x);
  Points b(3, n), y(3, n), r(3, n), z(3, n), p(3, n), Kp(3, n);
  double lambda = 0;
  for (int iteration = 0; iteration < 200; ++iteration) {
    throw_if_stop_requested("reduction experiment (the full model's frequency)");
    for (index_t i = 0; i < n; ++i) b.col(i) = model.mass[i] * x.col(i);
    held_at_zero(b);
    // K y = M x by preconditioned conjugate gradients, from the factor's answer
    factor.solve(b, y);
    apply_K(y, K_of);
    r = b - K_of;
    factor.solve(r, z);
    p = z;
    double rz = dot(r, z);
    const double b_norm = std::sqrt(dot(b, b));
    for (int k = 0; k < 500 && std::sqrt(dot(r, r)) > 1e-13 * b_norm; ++k) {
      apply_K(p, Kp);
      const double alpha = rz / dot(p, Kp);
      y += alpha * p;
      r -= alpha * Kp;
      factor.solve(r, z);
      const double next = dot(r, z);
      p = z + (next / rz) * p;
      rz = next;
    }
    double mass_norm = 0;
    for (index_t i = 0; i < n; ++i) mass_norm += model.mass[i] * y.col(i).squaredNorm();
    x = y / std::sqrt(mass_norm);
    apply_K(x, K_of);
    const double next = dot(x, K_of);  // the Rayleigh quotient (x is mass-normalised)
    if (std::abs(next - lambda) < 1e-13 * next) break;
    lambda = next;
  }
  return std::sqrt(lambda) / (2 * std::numbers::pi);
}

double percent(double value, double reference) { return 100 * (value / reference - 1); }
double percent(const Vec3& value, const Vec3& reference) { return 100 * (value - reference).norm() / reference.norm(); }

}  // namespace

int run_reduction_experiment(const ReductionOptions& options) {
  namespace fs = std::filesystem;
  fs::create_directories(options.out);
  const fs::path out = options.out;
  const int threads = options.threads > 0 ? options.threads : available_cores();
  fem::find_ccx();
  std::vector<int> modes = options.modes;
  if (modes.empty()) modes = options.quick ? std::vector<int>{6, 12, 20} : std::vector<int>{6, 10, 15, 20, 30, 40};
  if (std::find(modes.begin(), modes.end(), options.checked_modes) == modes.end())
    modes.push_back(options.checked_modes);
  std::sort(modes.begin(), modes.end());

  auto csv = fmt::output_file((out / "reduction.csv").string());
  csv.print("beam,quantity,load_N,modes,value,full,calculix,error_vs_full_pct,error_vs_calculix_pct,setup_s,solve_s\n");
  std::string md = "# The reduced model against the full point model and CalculiX NLGEOM\n\n";
  std::vector<std::string> misses;
  const auto check = [&](bool ok, const std::string& what) {
    if (!ok) misses.push_back(what);
    return ok ? "yes" : "**no**";
  };

  for (const Beam& beam : beams(options.quick)) {
    fmt::print("== {}\n", beam.description);
    md +=
        fmt::format("## {}\n\nspacing {} m; tip = the mean displacement of the points (nodes) of the face x = {} m\n\n",
                    beam.description, beam.spacing, beam.size.x());
    // statics: CalculiX (two meshes, the finer the reference; one with --quick), the full model, each r
    md += fmt::format(
        "| load (N) | tip / length (full) | CalculiX coarse / fine vs full | r | vs full | vs CalculiX | within 2% "
        "(r = {}) |\n|---|---|---|---|---|---|---|\n",
        options.checked_modes);
    std::map<int, double> frequency;  // per r
    for (double load : beam.loads) {
      double fem_s = 0;
      const Vec3 coarse = calculix_tip(beam, load, 1, threads, fem_s);
      Vec3 reference = coarse;
      double fine_s = 0;
      if (!options.quick) reference = calculix_tip(beam, load, 2, threads, fine_s);
      const StaticRun full = solve_static(beam, load, 0, threads);
      fmt::print("{} N: full model tip ({:.5f}, {:.5f}, {:.5f}) m in {:.2f} s; CalculiX {:.5f} / {:.5f} m\n", load,
                 full.tip.x(), full.tip.y(), full.tip.z(), full.seconds, coarse.norm(), reference.norm());
      csv.print("{},tip_static,{},0,{:.8e},{:.8e},{:.8e},0,{:.4f},,{:.3f}\n", beam.name, load, full.tip.norm(),
                full.tip.norm(), reference.norm(), percent(full.tip, reference), full.seconds);
      for (int r : modes) {
        const StaticRun reduced = solve_static(beam, load, r, threads);
        const double vs_full = percent(reduced.tip, full.tip), vs_fem = percent(reduced.tip, reference);
        csv.print("{},tip_static,{},{},{:.8e},{:.8e},{:.8e},{:.4f},{:.4f},{:.3f},{:.3f}\n", beam.name, load, r,
                  reduced.tip.norm(), full.tip.norm(), reference.norm(), vs_full, vs_fem, reduced.setup_s,
                  reduced.seconds - reduced.setup_s);
        if (load == beam.loads.front()) frequency[r] = reduced.first_frequency_hz;  // the same at every load
        const bool checked = r == options.checked_modes;
        md += fmt::format(
            "| {} | {:.4f} | {:.2f}% / {:.2f}% | {} | {:.3f}% | {:.3f}% | {} |\n", load,
            full.tip.norm() / beam.size.x(), percent(coarse, full.tip), percent(reference, full.tip), r, vs_full,
            vs_fem,
            checked ? check(vs_full <= 2 && vs_fem <= 2,
                            fmt::format("{} at {} N, r = {}: static tip {:.2f}% from the full model, {:.2f}% from "
                                        "CalculiX",
                                        beam.name, load, r, vs_full, vs_fem))
                    : "");
      }
    }
    // the first natural frequency
    const double f_full = full_first_frequency(beam, threads);
    md += fmt::format(
        "\nfirst natural frequency: full model {:.5f} Hz (its exact rest tangent, by inverse iteration)\n\n| r | reduced (Hz) | vs full | within 1% |\n|---|---|---|---|\n",
        f_full);
    for (int r : modes) {
      const double error = percent(frequency[r], f_full);
      csv.print("{},first_frequency,,{},{:.8e},{:.8e},,{:.4f},,,\n", beam.name, r, frequency[r], f_full, error);
      md += fmt::format("| {} | {:.5f} | {:+.3f}% | {} |\n", r, frequency[r], error,
                        r == options.checked_modes
                            ? check(std::abs(error) <= 1, fmt::format("{}, r = {}: first frequency {:+.3f}% from the "
                                                                      "full model's",
                                                                      beam.name, r, error))
                            : "");
    }
    // a load applied at once: the tip's history, backward Euler at dt in both
    const auto start = std::chrono::steady_clock::now();
    const std::vector<Vec3> full_history = sudden_load_history(beam, 0, threads);
    const double full_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    double peak = 0;
    for (const Vec3& t : full_history) peak = std::max(peak, t.norm());
    md += fmt::format(
        "\n{} N at once, held, {} s of backward Euler at dt = {} s (full model: {:.2f} s of compute, peak tip {:.4f} "
        "m = {:.1f}% of the length): the largest difference of the tip's histories over the peak\n\n| r | vs full "
        "| within 2% |\n|---|---|---|\n",
        beam.sudden_load, beam.duration, beam.dt, full_s, peak, 100 * peak / beam.size.x());
    for (int r : modes) {
      const auto reduced_start = std::chrono::steady_clock::now();
      const std::vector<Vec3> history = sudden_load_history(beam, r, threads);
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - reduced_start).count();
      const double error = 100 * history_error(history, full_history);
      csv.print("{},tip_dynamic,{},{},{:.8e},{:.8e},,{:.4f},,,{:.3f}\n", beam.name, beam.sudden_load, r,
                history.back().norm(), full_history.back().norm(), error, s);
      md += fmt::format("| {} | {:.3f}% | {} |\n", r, error,
                        r == options.checked_modes
                            ? check(error <= 2, fmt::format("{}, r = {}: the sudden load's history {:.2f}% from the "
                                                            "full model's",
                                                            beam.name, r, error))
                            : "");
      fmt::print("{} r = {}: sudden load history within {:.3f}% of the full model's\n", beam.name, r, error);
    }
    md += "\n";
  }
  csv.close();
  md += misses.empty() ? "Every checked figure is within its goal.\n"
                       : fmt::format("{} checked figures miss their goal.\n", misses.size());
  auto summary = fmt::output_file((out / "summary.md").string());
  summary.print("{}", md);
  summary.close();
  if (run_plot_script("plot_reduction.py", out.string(), options.plot_script) != 0) return 1;
  fmt::print("wrote {}\n", out.string());
  for (const std::string& miss : misses) fmt::print(stderr, "reduction: {}\n", miss);
  return misses.empty() ? 0 : 1;
}

}  // namespace pointhaptics::experiments
