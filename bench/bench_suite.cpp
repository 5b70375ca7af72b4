#include "bench_suite.hpp"

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/core/memory_limit.hpp>
#include <pointhaptics/core/workspace.hpp>
#include <pointhaptics/geometry/sampling.hpp>
#include <pointhaptics/geometry/shape_surfaces.hpp>
#include <pointhaptics/mechanics/cut.hpp>
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/mechanics/tangent.hpp>
#include <pointhaptics/mechanics/tangent_matrix.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>
#include <pointhaptics/mechanics/surface_map.hpp>
#include <pointhaptics/mechanics/viscoelasticity.hpp>
#include <pointhaptics/haptics/devices/virtual_device.hpp>
#include <pointhaptics/session/interactive.hpp>
#include <pointhaptics/io/output_file.hpp>
#include <pointhaptics/session/scene_builder.hpp>
#include <pointhaptics/world/simulation.hpp>
#include <pointhaptics/solvers/explicit_solver.hpp>
#include <pointhaptics/solvers/sparse_cholesky.hpp>
#include <pointhaptics/reduction/modal_basis.hpp>
#include <pointhaptics/reduction/reduced_integrator.hpp>

#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <string_view>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <regex>

namespace pointhaptics::bench {
namespace {

// a cube-ish box of about n points, h = 2 spacing (~26 neighbours inside), default material
const Model& bench_model(int n) {
  static std::map<int, std::unique_ptr<Model>> cache;
  auto& slot = cache[n];
  if (!slot) {
    const int side = std::max(2, static_cast<int>(std::lround(std::cbrt(static_cast<double>(n)))));
    const double spacing = 0.005;
    const PointCloud cloud = sample_box(Vec3::Zero(), Vec3::Constant(spacing * (side - 1)), spacing);
    slot = std::make_unique<Model>(build_model(cloud, MaterialParams{}, KernelParams{}));
  }
  return *slot;
}

// the force loop's cost per material (issue 17): the bench box with each model, and with per-point materials
// (a neo-Hookean inclusion, ten times stiffer, in the svk box: a stiff nodule in soft tissue), and a
// viscoelastic neo-Hookean (two Prony terms: the force loop with its history's update, as in an implicit step's
// solve or an explicit step of one sub-step)
const std::array<std::string_view, 6> material_variants = {"svk",       "neo_hookean", "mooney_rivlin",
                                                           "corotated", "regions",     "viscoelastic"};

const Model& material_model(int n, int variant) {
  static std::map<std::pair<int, int>, std::unique_ptr<Model>> cache;
  auto& slot = cache[{n, variant}];
  if (!slot) {
    const Model& base = bench_model(n);
    PointCloud cloud;
    cloud.X = base.X;
    cloud.volume = base.volume;
    cloud.spacing = base.spacing;
    MaterialParams m;
    std::vector<MaterialParams> materials;
    std::vector<std::uint8_t> material_of;
    if (const std::string_view name = material_variants[variant]; name == "regions") {
      MaterialParams inclusion = m;
      inclusion.model = MaterialModel::NEO_HOOKEAN;
      inclusion.young *= 10;
      materials = {m, inclusion};
      const Vec3 centre = 0.5 * (base.X.rowwise().minCoeff() + base.X.rowwise().maxCoeff());
      const double radius = 0.3 * (base.X.rowwise().maxCoeff() - base.X.rowwise().minCoeff()).maxCoeff();
      for (index_t i = 0; i < base.n_points; ++i)
        material_of.push_back((base.X.col(i) - centre).norm() < radius ? 1 : 0);
    } else if (name == "viscoelastic") {
      m.model = MaterialModel::NEO_HOOKEAN;
      m.prony = {{0.3, 0.1}, {0.2, 1.0}};
    } else {
      m.model = *parse_enum<MaterialModel>(name);
    }
    slot = std::make_unique<Model>(build_model(cloud, m, KernelParams{}, materials, material_of));
  }
  return *slot;
}

Points random_displacement(const Model& model) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1e-3 * model.spacing);
  Points u(3, model.n_points);
  for (Eigen::Index k = 0; k < u.size(); ++k) u.data()[k] = noise(rng);
  return u;
}

void set_counters(benchmark::State& state, const Model& model, int threads) {
  const double evaluations = static_cast<double>(state.iterations()) * model.n_points;
  state.counters["points"] = model.n_points;
  state.counters["threads"] = threads;
  state.counters["neighbours_per_point"] = static_cast<double>(model.n_pairs()) / model.n_points;
  state.counters["point_steps_per_s"] = benchmark::Counter(evaluations, benchmark::Counter::kIsRate);
  state.counters["ns_per_pair"] = benchmark::Counter(static_cast<double>(state.iterations()) * model.n_pairs() * 1e-9,
                                                     benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// the force loop on `model`, timed
void time_forces(benchmark::State& state, const Model& model, int threads) {
  Workspace ws(model, threads);
  State s = State::at_rest(model);
  s.u = random_displacement(model);
  const bool viscous = !model.material.prony.empty();
  for (auto _ : state) {
    if (viscous) begin_viscous_step(model, s, 1e-4, ws);
    compute_internal_forces(model, s.u, ws);
    if (viscous) end_viscous_step(model, 1e-4, s, ws);
    benchmark::DoNotOptimize(ws.f_int.data());
    benchmark::ClobberMemory();
  }
  set_counters(state, model, threads);
}

void force_benchmark(benchmark::State& state) {
  time_forces(state, bench_model(static_cast<int>(state.range(0))), static_cast<int>(state.range(1)));
}

// What bounds the force loop (issue 19, item 4): the bench box of ~10k points with its neighbour lists
// rewired so that the loop's gathers come from near memory or from L1 alone, with and without the hourglass
// pass. The arithmetic, the loads and the stores are the real loop's, only where the neighbours' data sit
// changes (the forces are meaningless: timing only). range(0): 0 the real neighbours, 1 near (j within 12
// points of i: a stencil's data in a few cache lines), 2 cached (j among the first 32 points: all in L1);
// range(1): the hourglass pass on (1) or off (0).
const std::array<std::string_view, 3> stream_variants = {"real", "near", "cached"};

const Model& stream_model(int variant, bool hourglass) {
  static std::map<std::pair<int, bool>, std::unique_ptr<Model>> cache;
  auto& slot = cache[{variant, hourglass}];
  if (!slot) {
    slot = std::make_unique<Model>(bench_model(10000));
    Model& model = *slot;
    if (!hourglass) model.material.hourglass = 0;
    const index_t n = model.n_points;
    for (index_t i = 0; i < n; ++i)
      for (index_t e = model.neighbours.begin(i), k = 0; e < model.neighbours.end(i); ++e, ++k) {
        if (variant == 1) model.neighbours.index[e] = std::clamp<index_t>(i + (k % 24) - 12 + (k % 24 >= 12), 0, n - 1);
        if (variant == 2) model.neighbours.index[e] = k % 32;
      }
  }
  return *slot;
}

void stream_benchmark(benchmark::State& state) {
  time_forces(state, stream_model(static_cast<int>(state.range(0)), state.range(1) != 0), 1);
}

void material_benchmark(benchmark::State& state) {
  time_forces(state, material_model(static_cast<int>(state.range(0)), static_cast<int>(state.range(2))),
              static_cast<int>(state.range(1)));
}

void step_benchmark(benchmark::State& state) {
  const Model& model = bench_model(static_cast<int>(state.range(0)));
  const int threads = static_cast<int>(state.range(1));
  Workspace ws(model, threads);
  State s = State::at_rest(model);
  s.u = random_displacement(model);
  const double dt = stable_time_step(model);
  for (auto _ : state) {
    explicit_step(model, s, ws, dt, dt);  // exactly one sub-step
    benchmark::DoNotOptimize(s.u.data());
  }
  set_counters(state, model, threads);
}

// carrying the object's surface (issue 15): the bench box's exact boundary at half the spacing, moved by the
// points' displacement through the MLS map (y = Y + W u), as a frame or a contact query needs it
void surface_benchmark(benchmark::State& state) {
  const Model& model = bench_model(static_cast<int>(state.range(0)));
  const TriangleMesh surface = box_surface(
      model.X.rowwise().minCoeff(), model.X.rowwise().maxCoeff() - model.X.rowwise().minCoeff(), 0.5 * model.spacing);
  const SurfaceMap map = build_surface_map(model, surface.V);
  const Points u = random_displacement(model);
  Points y;
  for (auto _ : state) {
    carry_surface(map, surface.V, u, y);
    benchmark::DoNotOptimize(y.data());
  }
  state.counters["points"] = model.n_points;
  state.counters["vertices"] = static_cast<double>(surface.V.cols());
  state.counters["triangles"] = static_cast<double>(surface.F.size());
  state.counters["weights_per_vertex"] = static_cast<double>(map.weight.size()) / static_cast<double>(surface.V.cols());
}

// scenes/beam-4x1x1.toml: a 4 x 1 x 1 m beam, E = 5e6 Pa, nu = 0.33, clamped at x = 0, sagging under
// gravity, spacing 1/13 m (10388 points), damping 10 1/s
Scene beam_4x1x1(SolverKind kind) {
  Scene s;
  s.path = "beam-4x1x1";
  s.object.size = Vec3(4, 1, 1);
  s.object.spacing = 1.0 / 13.0;
  s.material.young = 5e6;
  s.material.poisson = 0.33;
  s.material.density = 1000;
  s.material.damping = 10;
  FixedSpec clamp;
  clamp.box = {Vec3(-1, -1, -1), Vec3(0, 2, 2)};
  s.fixed.push_back(clamp);
  LoadSpec gravity;
  gravity.kind = LoadKind::GRAVITY;
  gravity.g = Vec3(0, -9.81, 0);
  s.loads.push_back(gravity);
  s.solver.kind = kind;
  s.solver.dt = 2e-3;
  return s;
}

// compute seconds per simulated second: each iteration simulates 0.05 s from rest (the first, hardest
// part of the sag) with the scene's solver; range(0): 0 explicit, 1 implicit; range(1): threads
void beam_benchmark(benchmark::State& state) {
  const Scene scene = beam_4x1x1(state.range(0) == 0 ? SolverKind::EXPLICIT : SolverKind::IMPLICIT);
  const int threads = static_cast<int>(state.range(1));
  const Model model = build_scene_model(scene);
  const double simulated = 0.05;
  for (auto _ : state) {
    state.PauseTiming();
    Simulation sim(model, scene.solver, threads);
    state.ResumeTiming();
    sim.run(simulated);
    benchmark::DoNotOptimize(sim.state().u.data());
  }
  state.counters["points"] = model.n_points;
  state.counters["threads"] = threads;
  state.counters["compute_s_per_simulated_s"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * simulated, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// the 4 x 1 x 1 beam as a reduced model (issue 49): r = range(0) modes and derivatives, svk's polynomial, on 2
// threads; range(1): Newton iterations per step in real time (0: each step converged to 1e-9); range(2): the
// basis made on a sampling that many times coarser (1: on the points themselves). Counters: the set-up (basis: factor, modes, derivatives; the polynomial's tables), the tables' memory,
// and the reduced static sag at the free end; the timed loop is one backward Euler step at dt = 1 ms (one Newton
// solve in r unknowns), the Vega comparison's "step"
void reduced_beam_benchmark(benchmark::State& state) {
  const int r = static_cast<int>(state.range(0)), budget = static_cast<int>(state.range(1)),
            coarsening = static_cast<int>(state.range(2));
  const Scene scene = beam_4x1x1(SolverKind::IMPLICIT);
  const Model model = build_scene_model(scene);
  Workspace ws(model, 2);
  ModalBasisSettings settings;
  settings.size = r;
  ModalBasis basis;
  if (coarsening > 1) {
    // the basis on a sampling `coarsening` times coarser (`[reduction] basis_spacing`), carried to the points
    const auto start = std::chrono::steady_clock::now();
    const Model coarse = coarse_model(model, coarsening * model.spacing);
    Workspace coarse_ws(coarse, 2);
    settings.loads = {coarse.f_ext};
    const ModalBasis on_coarse = build_modal_basis(coarse, settings, coarse_ws);
    basis = carry_basis(on_coarse, coarse, model);
    basis.total_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  } else {
    settings.loads = {model.f_ext};
    basis = build_modal_basis(model, settings, ws);
  }
  const SvkPolynomial polynomial(model, basis.U, ws);
  ReducedIntegrator integrator(
      polynomial, basis.U.transpose() * Eigen::Map<const Eigen::VectorXd>(model.f_ext.data(), model.f_ext.size()),
      model.material.damping);
  Eigen::VectorXd sag = Eigen::VectorXd::Zero(r);
  integrator.solve_static(sag);
  const Points u = displacement_of(basis.U, sag, model.n_points);
  double tip = 0;
  int n_tip = 0;
  for (index_t i = 0; i < model.n_points; ++i)
    if (model.X(0, i) > 4.0 - 1e-6) {
      tip += u(1, i);
      ++n_tip;
    }
  // the first 0.2 s of the sag from rest, again and again: every step moves (a beam at rest would need no Newton
  // iteration at all)
  ReducedState reduced{Eigen::VectorXd::Zero(r), Eigen::VectorXd::Zero(r)};
  long long newton = 0, steps = 0;
  for (auto _ : state) {
    if (steps % 200 == 0) {
      reduced.q.setZero();
      reduced.v.setZero();
    }
    const ReducedSolveReport report =
        budget > 0 ? integrator.step(reduced, 1e-3, 1e-9, budget, true) : integrator.step(reduced, 1e-3);
    newton += report.iterations;
    ++steps;
    benchmark::DoNotOptimize(reduced.q.data());
  }
  state.counters["points"] = model.n_points;
  state.counters["modes"] = r;
  state.counters["linear_modes"] = basis.linear_modes;
  state.counters["basis_s"] = basis.total_s;
  state.counters["factorise_s"] = basis.factorise_s;
  state.counters["eigen_s"] = basis.modes_s;
  state.counters["derivatives_s"] = basis.derivatives_s;
  state.counters["polynomial_s"] = polynomial.build_s();
  state.counters["setup_s"] = basis.total_s + polynomial.build_s();
  state.counters["factor_mb"] = basis.factor_bytes / 1e6;
  state.counters["tables_mb"] = polynomial.bytes() / 1e6;
  state.counters["static_tip_sag_m"] = -tip / n_tip;
  state.counters["newton_per_step"] = static_cast<double>(newton) / static_cast<double>(std::max(steps, 1LL));
}

// the seed's cantilever, 0.15 x 0.03 x 0.03 m, clamped at x = 0 (nu = 0.4, 1000 kg/m^3, damping 20 / s)
Scene seed_cantilever(const char* name, double spacing, double young, SolverKind solver) {
  Scene s;
  s.path = name;
  s.object.size = Vec3(0.15, 0.03, 0.03);
  s.object.spacing = spacing;
  s.material.young = young;
  s.material.poisson = 0.4;
  s.material.density = 1000;
  s.material.damping = 20;
  FixedSpec clamp;
  clamp.box = {Vec3(-1, -1, -1), Vec3(0, 1, 1)};
  s.fixed.push_back(clamp);
  s.solver.kind = solver;
  s.solver.dt = 1e-3;
  return s;
}

// the seed's cantilever at E = 1e8 Pa (525 points, s = 7.5 mm, a 0.3 N tip traction) stepped implicitly at
// 1 kHz for 0.2 s from rest with either preconditioner; range(0): 0 block-Jacobi, 1 Cholesky; range(1): threads
// the preconditioners the stiff cantilever is stepped with, by the benchmark's first argument
constexpr std::array<Preconditioner, 3> stiff_preconditioners{Preconditioner::BLOCK_JACOBI, Preconditioner::CHOLESKY,
                                                              Preconditioner::TWO_LEVEL};

void stiff_cantilever_benchmark(benchmark::State& state) {
  Scene s = seed_cantilever("stiff-cantilever", 0.0075, 1e8, SolverKind::IMPLICIT);
  LoadSpec tip;
  tip.kind = LoadKind::TRACTION;
  tip.box = {Vec3(0.15, -1, -1), Vec3(1, 1, 1)};
  tip.total = Vec3(0, -0.3, 0);
  s.loads.push_back(tip);
  s.solver.preconditioner = stiff_preconditioners[static_cast<std::size_t>(state.range(0))];
  const Model model = build_scene_model(s);
  const double simulated = 0.2;
  RunSummary summary;
  for (auto _ : state) {
    state.PauseTiming();
    Simulation sim(model, s.solver, static_cast<int>(state.range(1)));
    state.ResumeTiming();
    sim.run(simulated);
    state.PauseTiming();
    summary = sim.summary();
    state.ResumeTiming();
  }
  state.counters["points"] = model.n_points;
  state.counters["threads"] = static_cast<double>(state.range(1));
  state.counters["cg_per_step"] =
      static_cast<double>(summary.cg_iterations) / static_cast<double>(std::max(1LL, summary.steps));
  state.counters["factorisations"] = static_cast<double>(summary.factorisations);
  state.counters["compute_s_per_simulated_s"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * simulated, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// the Cholesky factor of the tangent of a cube of about n points (bench_model) with the inertia of a 1 ms
// step: its pattern, size and cost. One iteration is one numeric factorisation; above 20k points it is the
// symbolic analysis alone, whose predicted factor size is reported (a numeric factor there needs many GB).
void cholesky_benchmark(benchmark::State& state) {
  const Model& model = bench_model(static_cast<int>(state.range(0)));
  Tangent tangent;
  tangent.linearise(model, Points::Zero(3, model.n_points), TangentMode::PROJECTED);
  TangentMatrix K;
  assemble_tangent(model, tangent, K);
  for (index_t i = 0; i < model.n_points; ++i)
    Eigen::Map<Mat3>(K.values.data() + 9 * static_cast<std::size_t>(K.diagonal[i])).diagonal().array() +=
        model.mass[i] / 1e-6;
  SparseCholesky chol;
  const bool numeric = model.n_points <= 20000;
  if (numeric) chol.analyse(model, K);
  for (auto _ : state) {
    if (!numeric) chol.analyse(model, K);
    else if (!chol.factorise(K)) state.SkipWithError("the tangent is not positive definite");
  }
  const CholeskyStats& c = chol.stats();
  state.counters["points"] = model.n_points;
  state.counters["blocks_per_row"] = static_cast<double>(K.n_blocks()) / model.n_points;
  state.counters["factor_nonzeros"] = c.factor_nonzeros;
  state.counters["factor_mb"] = (numeric ? c.factor_bytes : c.factor_nonzeros * sizeof(double)) / 1e6;
  state.counters["analyse_s"] = c.analyse_s;
  state.counters["numeric"] = numeric;
}

// the haptic loop in real time while the simulation steps a ~10k-point object on the other core:
// achieved rate, period error quantiles, the longest tick (one iteration = 2 s of wall time)
void haptic_benchmark(benchmark::State& state) {
  Scene s;
  s.path = "haptic-bench";
  const int side = std::max(2, static_cast<int>(std::lround(std::cbrt(static_cast<double>(state.range(0))))));
  s.object.spacing = 0.004;
  s.object.size = Vec3::Constant(s.object.spacing * (side - 1));
  s.material.young = 2e4;
  s.material.damping = 10;
  FixedSpec base;
  base.box = {Vec3(-1, -1, -1), Vec3(1, 0, 1)};
  s.fixed.push_back(base);
  s.solver.kind = SolverKind::EXPLICIT;
  s.solver.dt = 1e-3;
  const Model model = build_scene_model(s);
  HapticStats stats;
  long long steps = 0;
  double wall = 0;
  for (auto _ : state) {
    Simulation sim(model, s.solver, 1);  // one core for the simulation, one for the haptic loop
    VirtualDevice device(
        Trajectory({{0.0, Vec3::Zero(), false}, {1.0, Vec3(0, -0.02, 0), false}, {2.0, Vec3::Zero(), false}}),
        known_device_specs("touch"));
    InteractiveOptions o;
    o.duration = 2.0;
    o.probe.radius = 0.01;
    const Vec3 hi = model.X.rowwise().maxCoeff();
    o.mapping.origin = Vec3(0.5 * hi.x(), hi.y() + 0.02, 0.5 * hi.z());
    o.log = false;
    const InteractiveResult r = run_interactive(sim, device, o);
    stats = r.haptic;
    steps = r.simulation_steps;
    wall = r.simulation_wall_s;
  }
  state.counters["points"] = model.n_points;
  state.counters["rate_hz"] = stats.rate_hz;
  state.counters["period_p50_us"] = stats.period_p50_us;
  state.counters["period_p99_us"] = stats.period_p99_us;
  state.counters["period_max_us"] = stats.period_max_us;
  state.counters["tick_max_us"] = stats.tick_max_us;
  state.counters["sim_steps_per_s"] = wall > 0 ? steps / wall : 0.0;
}

// a blade step near the contact (issue 18): the seed's cantilever at 2.5 mm spacing (10,309 points, E = 1e6 Pa,
// clamped at x = 0), a blade's edge along z moved down through the plane x = 3.625 cm (between two planes of
// points) 0.7 mm per update (0.7 m/s at 1 kHz), from 5 mm above the beam to 5 mm below it, then again on a
// fresh model. Part 0: the whole update (Simulation::cut: the pairs found and severed, the stencils refitted,
// the stable step checked on a patch, the solver rebuilt, the sheet recorded); 1: the pairs found and severed
// and the stencils refitted (mechanics/cut.hpp) only; 2: the stable step's check on the patch only
const std::array<std::string_view, 3> blade_parts = {"update", "sever", "stable_step"};

// A blade's edge along z (z0 to z1) in the plane x, drawn down from `top` to `bottom` 0.7 mm per update (0.7 m/s
// at 1 kHz), then again from the top after fresh() (untimed); update(sweep) cuts and returns the pairs severed.
template <class Fresh, class Update>
void blade_strokes(benchmark::State& state, double x, double z0, double z1, double top, double bottom, Fresh&& fresh,
                   Update&& update) {
  const double stroke = 0.0007;
  double y = top;
  fresh();
  long long pairs = 0, updates = 0;
  for (auto _ : state) {
    if (y < bottom) {
      state.PauseTiming();
      fresh();
      y = top;
      state.ResumeTiming();
    }
    pairs += update(BladeSweep{Vec3(x, y, z0), Vec3(x, y, z1), Vec3(x, y - stroke, z0), Vec3(x, y - stroke, z1)});
    y -= stroke;
    ++updates;
  }
  state.counters["pairs_per_update"] = updates > 0 ? static_cast<double>(pairs) / static_cast<double>(updates) : 0.0;
}

void blade_benchmark(benchmark::State& state) {
  const int part = static_cast<int>(state.range(0)), threads = static_cast<int>(state.range(1));
  static const Scene scene = seed_cantilever("blade-bench", 0.0025, 1e6, SolverKind::EXPLICIT);
  static const Model model = build_scene_model(scene);
  std::unique_ptr<Simulation> sim;
  Model cut_model;
  auto fresh = [&] {
    if (part == 0) sim = std::make_unique<Simulation>(model, scene.solver, threads);
    else cut_model = model;
  };
  blade_strokes(state, 0.03625, -0.01, 0.04, 0.035, -0.005, fresh, [&](const BladeSweep& sweep) -> index_t {
    if (part == 0) return sim->cut(sweep).severed_pairs;
    // (an explicit simulation's cut: the hourglass diagonal dropped)
    if (part == 1) return cut(cut_model, cut_model.X, sweep, false).severed_pairs;
    state.PauseTiming();
    const CutReport report = cut(cut_model, cut_model.X, sweep, false);
    state.ResumeTiming();
    if (!report.cut_points.empty())
      benchmark::DoNotOptimize(local_stable_time_step(cut_model, report.cut_points, ModelSimulation::cut_patch_rings,
                                                      0.8, ModelSimulation::cut_lanczos_steps));
    return report.severed_pairs;
  });
  state.counters["points"] = model.n_points;
  state.counters["threads"] = threads;
}

// the same blade step with levels of detail (issue 18's second goal): scenes/half_sphere_100k_lod.toml's object
// (a half-sphere of radius 5 cm at 1.37 mm spacing, 100k points) and levels of detail around the top, a blade
// 1 cm long along z drawn down from the top 0.7 mm per update, 2 cm deep, then again on a fresh object. The
// update cuts the active set and carries the cut to the object (LevelsOfDetail::carry_cuts)
void blade_lod_benchmark(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  static const Scene scene = [] {
    Scene s;
    s.path = "blade-lod-bench";
    s.object.shape = ShapeKind::HALF_SPHERE;
    s.object.radius = 0.05;
    s.object.spacing = 0.00137;
    s.material.model = MaterialModel::NEO_HOOKEAN;
    s.material.young = 1e4;
    s.material.poisson = 0.45;
    s.material.damping = 20;
    FixedSpec base;
    base.box = {Vec3(-1, -1, -1), Vec3(1, 0, 1)};
    s.fixed.push_back(base);
    s.solver.kind = SolverKind::EXPLICIT;
    s.solver.dt = 1e-4;
    s.lod.present = true;
    s.lod.params.k1 = 1.0;
    s.lod.params.k2 = 1.0;
    s.lod.params.levels = {{4.0, 0}, {40.0, 9}};
    s.lod.params.scheme = LodScheme::DITHER;
    s.lod.params.min_neighbours = 8;
    return s;
  }();
  static const Model model = build_scene_model(scene);
  std::unique_ptr<Simulation> sim;
  auto fresh = [&] {
    sim = std::make_unique<Simulation>(model, scene.solver, threads);
    sim->enable_lod(scene.lod.params, Vec3(0, 0.05, 0));
  };
  blade_strokes(state, 0.5 * scene.object.spacing, -0.005, 0.005, 0.0505, 0.0305, fresh,
                [&](const BladeSweep& sweep) { return sim->cut(sweep).severed_pairs; });
  state.counters["points"] = model.n_points;
  state.counters["simulated"] = sim->simulated_model().n_points;
  state.counters["threads"] = threads;
  state.counters["object_pairs_cut"] = static_cast<double>(sim->summary().cut.cut_pairs);
}

// collects each run's counters for the JSON while the console reporter prints the table
class CollectingReporter : public benchmark::ConsoleReporter {
 public:
  nlohmann::json force = nlohmann::json::array(), step = nlohmann::json::array(), beam = nlohmann::json::array(),
                 haptic = nlohmann::json::array(), materials = nlohmann::json::array(),
                 surface = nlohmann::json::array(), stiff_cantilever = nlohmann::json::array(),
                 cholesky = nlohmann::json::array(), force_streams = nlohmann::json::array(),
                 blade = nlohmann::json::array();
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.error_occurred) continue;
      // repeated: the median of the repetitions (the other aggregates are printed only)
      if (run.run_type == Run::RT_Aggregate && run.aggregate_name != "median") continue;
      if (run.benchmark_name().rfind("haptic", 0) == 0) {
        nlohmann::json row;
        for (const char* key :
             {"points", "rate_hz", "period_p50_us", "period_p99_us", "period_max_us", "tick_max_us", "sim_steps_per_s"})
          row[key] = static_cast<double>(run.counters.at(key).value);
        haptic.push_back(row);
        continue;
      }
      if (run.benchmark_name().rfind("materials/", 0) == 0) {
        const std::string name = run.benchmark_name();
        const size_t slash = name.find('/', 10);
        materials.push_back({{"model", name.substr(10, slash - 10)},
                             {"points", static_cast<long long>(run.counters.at("points").value)},
                             {"threads", static_cast<int>(run.counters.at("threads").value)},
                             {"point_steps_per_s", static_cast<double>(run.counters.at("point_steps_per_s").value)}});
        continue;
      }
      if (run.benchmark_name().rfind("surface/", 0) == 0) {
        surface.push_back({{"points", static_cast<long long>(run.counters.at("points").value)},
                           {"vertices", static_cast<long long>(run.counters.at("vertices").value)},
                           {"triangles", static_cast<long long>(run.counters.at("triangles").value)},
                           {"weights_per_vertex", static_cast<double>(run.counters.at("weights_per_vertex").value)},
                           {"carry_us", run.GetAdjustedRealTime()}});  // the benchmark's unit is microseconds
        continue;
      }
      if (run.benchmark_name().rfind("force_streams/", 0) == 0) {
        const std::string name = run.benchmark_name();
        const size_t slash = name.find('/', 14);
        force_streams.push_back(
            {{"neighbours", name.substr(14, slash - 14)},
             {"hourglass", name.find("hourglass:on") != std::string::npos},
             {"points", static_cast<long long>(run.counters.at("points").value)},
             {"ns_per_pair", static_cast<double>(run.counters.at("ns_per_pair").value)},
             {"point_steps_per_s", static_cast<double>(run.counters.at("point_steps_per_s").value)}});
        continue;
      }
      if (run.benchmark_name().rfind("stiff_cantilever/", 0) == 0) {
        const std::string name = run.benchmark_name().substr(std::string("stiff_cantilever/").size());
        stiff_cantilever.push_back(
            {{"preconditioner", name.substr(0, name.find('/'))},
             {"threads", static_cast<int>(run.counters.at("threads").value)},
             {"points", static_cast<long long>(run.counters.at("points").value)},
             {"cg_per_step", static_cast<double>(run.counters.at("cg_per_step").value)},
             {"factorisations", static_cast<double>(run.counters.at("factorisations").value)},
             {"compute_s_per_simulated_s", static_cast<double>(run.counters.at("compute_s_per_simulated_s").value)}});
        continue;
      }
      if (run.benchmark_name().rfind("blade/", 0) == 0) {
        const std::string name = run.benchmark_name();
        const size_t slash = name.find('/', 6);
        nlohmann::json row{{"part", name.substr(6, slash - 6)},
                           {"points", static_cast<long long>(run.counters.at("points").value)},
                           {"threads", static_cast<int>(run.counters.at("threads").value)},
                           {"pairs_per_update", static_cast<double>(run.counters.at("pairs_per_update").value)},
                           {"ms", run.GetAdjustedRealTime() / 1e3}};  // the benchmark's unit is microseconds
        for (const char* key : {"simulated", "object_pairs_cut"})     // with levels of detail
          if (auto it = run.counters.find(key); it != run.counters.end())
            row[key] = static_cast<double>(it->second.value);
        blade.push_back(row);
        continue;
      }
      if (run.benchmark_name().rfind("cholesky/", 0) == 0) {
        nlohmann::json row{{"points", static_cast<long long>(run.counters.at("points").value)}};
        for (const char* key : {"blocks_per_row", "factor_nonzeros", "factor_mb", "analyse_s"})
          row[key] = static_cast<double>(run.counters.at(key).value);
        row["numeric"] = run.counters.at("numeric").value > 0;
        // the benchmark's time is a numeric factorisation, or the analysis alone
        row[row["numeric"].get<bool>() ? "factorise_s" : "analysis_only_s"] = run.GetAdjustedRealTime() / 1e3;
        cholesky.push_back(row);
        continue;
      }
      if (run.benchmark_name().rfind("beam4x1x1", 0) == 0) {
        beam.push_back(
            {{"solver", run.benchmark_name().find("implicit") != std::string::npos ? "implicit" : "explicit"},
             {"threads", static_cast<int>(run.counters.at("threads").value)},
             {"points", static_cast<long long>(run.counters.at("points").value)},
             {"compute_s_per_simulated_s", static_cast<double>(run.counters.at("compute_s_per_simulated_s").value)}});
        continue;
      }
      nlohmann::json row;
      for (const char* key : {"points", "threads", "neighbours_per_point", "ns_per_pair", "point_steps_per_s"}) {
        auto it = run.counters.find(key);
        row[key] = it == run.counters.end() ? 0.0 : static_cast<double>(it->second.value);
      }
      row["points"] = static_cast<long long>(row["points"].get<double>());
      row["threads"] = static_cast<int>(row["threads"].get<double>());
      (run.benchmark_name().rfind("forces", 0) == 0 ? force : step).push_back(row);
    }
  }
};

}  // namespace

int run_bench_suite(const BenchOptions& options) {
  // sizes too big for what this process may take are refused before anything is built (issue 52: --sizes
  // 100000000 ran out of memory, and its message named --max-memory, which bench does not have); each size's
  // models are held together (the force, step and material variants' caches)
  const MemoryLimit limit = memory_limit();
  for (int n : options.sizes) {
    const ModelEstimate e = estimate_model(n, KernelParams{}, 1.0);
    const double held = (2.0 + static_cast<double>(material_variants.size())) * e.bytes;
    if (held > limit.bytes)
      throw Error(
          fmt::format("bench --sizes {}: its models would need about {:.3g} GB, more than {} ({:.3g} GB); "
                      "give smaller --sizes",
                      n, held / 1e9, limit.what, limit.bytes / 1e9));
  }
  for (int n : options.sizes)
    for (int t : options.threads) {
      benchmark::RegisterBenchmark(fmt::format("forces/points:{}/threads:{}", n, t).c_str(), force_benchmark)
          ->Args({n, t})
          ->Unit(benchmark::kMicrosecond)
          ->MinTime(options.min_time)
          ->UseRealTime();
      benchmark::RegisterBenchmark(fmt::format("step/points:{}/threads:{}", n, t).c_str(), step_benchmark)
          ->Args({n, t})
          ->Unit(benchmark::kMicrosecond)
          ->MinTime(options.min_time)
          ->UseRealTime();
      for (int v = 0; v < static_cast<int>(material_variants.size()); ++v)
        benchmark::RegisterBenchmark(
            fmt::format("materials/{}/points:{}/threads:{}", material_variants[v], n, t).c_str(), material_benchmark)
            ->Args({n, t, v})
            ->Unit(benchmark::kMicrosecond)
            ->MinTime(options.min_time)
            ->UseRealTime();
    }
  for (int n : options.sizes)
    benchmark::RegisterBenchmark(fmt::format("surface/points:{}/threads:1", n).c_str(), surface_benchmark)
        ->Args({n})
        ->Unit(benchmark::kMicrosecond)
        ->MinTime(options.min_time)
        ->UseRealTime();
  for (int t : options.threads)
    for (int solver : {0, 1})
      benchmark::RegisterBenchmark(fmt::format("beam4x1x1/{}/threads:{}", solver ? "implicit" : "explicit", t).c_str(),
                                   beam_benchmark)
          ->Args({solver, t})
          ->Unit(benchmark::kMillisecond)
          ->Iterations(1)
          ->UseRealTime();
  for (int r : {20, 40})
    for (int budget : {0, 1})
      for (int coarsening : {1, 2})
        benchmark::RegisterBenchmark(fmt::format("reduced_beam4x1x1/modes:{}/{}/basis_spacing:{}/threads:2", r,
                                                 budget ? "newton:1" : "converged", coarsening)
                                         .c_str(),
                                     reduced_beam_benchmark)
            ->Args({r, budget, coarsening})
            ->Unit(benchmark::kMicrosecond)
            ->MinTime(options.min_time)
            ->UseRealTime();
  for (int variant = 0; variant < static_cast<int>(stream_variants.size()); ++variant)
    for (int hourglass : {1, 0})
      benchmark::RegisterBenchmark(
          fmt::format("force_streams/{}/hourglass:{}/threads:1", stream_variants[variant], hourglass ? "on" : "off")
              .c_str(),
          stream_benchmark)
          ->Args({variant, hourglass})
          ->Unit(benchmark::kMicrosecond)
          ->MinTime(options.min_time)
          ->UseRealTime();
  for (std::size_t preconditioner = 0; preconditioner < stiff_preconditioners.size(); ++preconditioner)
    benchmark::RegisterBenchmark(fmt::format("stiff_cantilever/{}/threads:{}",
                                             enum_name(stiff_preconditioners[preconditioner]), options.threads.back())
                                     .c_str(),
                                 stiff_cantilever_benchmark)
        ->Args({static_cast<int64_t>(preconditioner), options.threads.back()})
        ->Unit(benchmark::kMillisecond)
        ->Iterations(3)
        ->UseRealTime();
  for (int n : options.sizes)
    benchmark::RegisterBenchmark(fmt::format("cholesky/points:{}", n).c_str(), cholesky_benchmark)
        ->Args({n})
        ->Unit(benchmark::kMillisecond)
        ->Iterations(1)
        ->UseRealTime();
  for (int part = 0; part < static_cast<int>(blade_parts.size()); ++part)
    for (int t : part == 0 ? options.threads : std::vector<int>{1})
      benchmark::RegisterBenchmark(fmt::format("blade/{}/points:10309/threads:{}", blade_parts[part], t).c_str(),
                                   blade_benchmark)
          ->Args({part, t})
          ->Unit(benchmark::kMicrosecond)
          ->MinTime(options.min_time)
          ->UseRealTime();
  benchmark::RegisterBenchmark(fmt::format("blade/update_lod/points:100000/threads:{}", options.threads.back()).c_str(),
                               blade_lod_benchmark)
      ->Args({options.threads.back()})
      ->Unit(benchmark::kMicrosecond)
      ->MinTime(options.min_time)
      ->UseRealTime();
  benchmark::RegisterBenchmark("haptic/points:10000", haptic_benchmark)
      ->Args({10000})
      ->Unit(benchmark::kMillisecond)
      ->Iterations(1)
      ->UseRealTime();
  // a bad pattern or one that matches nothing is an error, not an empty table and exit 0
  try {
    const std::regex check(options.filter, std::regex::extended);
  } catch (const std::regex_error& e) {
    fmt::print(stderr, "pointhaptics bench: --filter '{}' is not a valid regular expression ({})\n", options.filter,
               e.what());
    return 1;
  }
  if (!options.json_path.empty()) {
    try {
      check_output_path(options.json_path, "--json");
    } catch (const Error& e) {
      fmt::print(stderr, "pointhaptics bench: error: {}\n", e.what());
      return 1;
    }
  }
  std::string filter_flag = "--benchmark_filter=" + options.filter;
  std::string name = "pointhaptics-bench";
  // repetitions in random order, so that a shared machine's slow spells fall on every benchmark alike
  std::string repetitions = fmt::format("--benchmark_repetitions={}", options.repetitions),
              interleave = "--benchmark_enable_random_interleaving=true",
              aggregates = "--benchmark_report_aggregates_only=true";
  std::vector<char*> argv = {name.data(), filter_flag.data()};
  if (options.repetitions > 1) argv.insert(argv.end(), {repetitions.data(), interleave.data(), aggregates.data()});
  int argc = static_cast<int>(argv.size());
  argv.push_back(nullptr);
  benchmark::Initialize(&argc, argv.data());
  CollectingReporter reporter;
  const std::size_t ran = benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  if (ran == 0) {
    fmt::print(stderr, "pointhaptics bench: --filter '{}' matches no benchmark\n", options.filter);
    return 1;
  }
  // each material's time relative to svk's at the same size and threads (the cost measure)
  for (nlohmann::json& row : reporter.materials)
    for (const nlohmann::json& svk : reporter.materials)
      if (svk["model"] == "svk" && svk["points"] == row["points"] && svk["threads"] == row["threads"])
        row["relative_to_svk"] = svk["point_steps_per_s"].get<double>() / row["point_steps_per_s"].get<double>();
  // issue 15's bound: a carry of the surface against one explicit step of the same points on one thread
  for (nlohmann::json& row : reporter.surface)
    for (const nlohmann::json& step : reporter.step)
      if (step["points"] == row["points"] && step["threads"] == 1)
        row["relative_to_step"] = row["carry_us"].get<double>() * step["point_steps_per_s"].get<double>() /
                                  (1e6 * step["points"].get<double>());
  if (!options.json_path.empty()) {
    const std::string text = nlohmann::json{
        {"force", reporter.force},
        {"step", reporter.step},
        {"beam_4x1x1", reporter.beam},
        {"haptic", reporter.haptic},
        {"materials", reporter.materials},
        {"surface", reporter.surface},
        {"stiff_cantilever", reporter.stiff_cantilever},
        {"cholesky", reporter.cholesky},
        {"force_streams", reporter.force_streams},
        {"blade",
         reporter.blade}}.dump(1);
    try {
      write_text_file(options.json_path, "--json", [&](TextOutput& out) { out.print("{}\n", text); });
    } catch (const Error& e) {
      fmt::print(stderr, "pointhaptics bench: error: {}\n", e.what());
      return 1;
    }
  }
  return 0;
}

}  // namespace pointhaptics::bench
