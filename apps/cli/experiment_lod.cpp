#include "experiment_lod.hpp"

#include "plots.hpp"

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/pointhaptics.hpp>

#include <fmt/format.h>
#include <fmt/os.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

namespace pointhaptics::experiments {
namespace {

namespace fs = std::filesystem;
constexpr double radius = 0.05;  // the seed's object: a half-sphere (Fig. 5-7), here 5 cm

// The half-sphere, flat face (y = 0) held, soft-tissue-like, damped so that it settles.
Scene half_sphere(double spacing) {
  Scene s;
  s.path = "half-sphere";
  s.object.shape = ShapeKind::HALF_SPHERE;
  s.object.radius = radius;
  s.object.spacing = spacing;
  s.material.young = 1e4;
  s.material.poisson = 0.45;
  s.material.density = 1000;
  s.material.damping = 20;
  FixedSpec base;
  base.box = {Vec3(-1, -1, -1), Vec3(1, 0, 1)};
  s.fixed = {base};
  s.solver.kind = SolverKind::EXPLICIT;
  s.solver.dt = 1e-3;
  return s;
}

// The spacing whose half-sphere has the point count nearest `target` (the count falls with the spacing).
double spacing_for(int target) {
  double lo = radius / 200, hi = radius / 2;
  auto count = [](double s) { return static_cast<int>(sample_object(half_sphere(s)).X.cols()); };
  double best = hi;
  int best_gap = std::abs(count(hi) - target);
  for (int it = 0; it < 40; ++it) {
    const double mid = std::sqrt(lo * hi);
    const int n = count(mid);
    if (std::abs(n - target) < best_gap) {
      best_gap = std::abs(n - target);
      best = mid;
    }
    if (n > target) lo = mid;
    else hi = mid;
  }
  return best;
}

index_t nearest_point(const Model& m, const Vec3& x) {
  index_t best = 0;
  for (index_t i = 1; i < m.n_points; ++i)
    if ((m.X.col(i) - x).squaredNorm() < (m.X.col(best) - x).squaredNorm()) best = i;
  return best;
}

struct Timing {
  double steps_per_s = 0;  // explicit steps (one force evaluation and update each) per wall second
  double realtime = 0;     // simulated seconds per wall second
  double stable_dt = 0;
};

// Explicit steps until `seconds` of wall time have passed (at least 10 solver steps).
Timing time_steps(Simulation& sim, double seconds) {
  sim.step();  // warm up
  const long long sub0 = sim.summary().substeps;
  const double t0 = sim.time();
  const auto start = std::chrono::steady_clock::now();
  double wall = 0;
  int steps = 0;
  while (wall < seconds || steps < 10) {
    sim.step();
    ++steps;
    wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  Timing t;
  t.steps_per_s = (sim.summary().substeps - sub0) / wall;
  t.realtime = (sim.time() - t0) / wall;
  t.stable_dt = sim.stable_dt();
  return t;
}

LodParams bands(double k1, double k2, std::vector<LodLevel> levels = {}, LodScheme scheme = LodScheme::RANDOM) {
  LodParams p;
  p.k1 = k1;
  p.k2 = k2;
  p.levels = std::move(levels);
  p.scheme = scheme;
  return p;
}

std::string csv_or_empty(std::optional<double> v) { return v ? fmt::format("{}", *v) : std::string(); }

// displacement errors of `u` against `reference`: max inside radius r of c relative to the largest
// reference displacement there, and the RMS over the object relative to the reference's RMS
struct Errors {
  double near = 0, near_rms = 0, whole = 0;
};

Errors errors(const Model& m, const Points& u, const Points& reference, const Vec3& c, double r) {
  double err = 0, ref = 0, err2 = 0, ref2 = 0;
  for (index_t i = 0; i < m.n_points; ++i)
    if ((m.X.col(i) - c).norm() <= r * (1 + 1e-9)) {
      const double e = (u.col(i) - reference.col(i)).norm(), f = reference.col(i).norm();
      err = std::max(err, e);
      ref = std::max(ref, f);
      err2 += e * e;
      ref2 += f * f;
    }
  Errors e;
  e.near = ref > 0 ? err / ref : 0;
  e.near_rms = ref2 > 0 ? std::sqrt(err2 / ref2) : 0;
  e.whole = (u - reference).norm() / std::max(reference.norm(), 1e-300);
  return e;
}

}  // namespace

int run_lod_table_experiment(const LodExperimentOptions& options) {
  fs::create_directories(options.out);
  const fs::path out = options.out;
  const std::vector<int> targets =
      options.quick ? std::vector<int>{224, 500, 1200} : std::vector<int>{224, 500, 1200, 10000, 100000};
  const double tr[3][2] = {{1.0, 1.5}, {1.5, 2.0}, {2.0, 2.5}};
  const double seed_fps[3][3] = {{83, 56, 46}, {50, 39, 24}, {40, 33, 20}};  // seed Table 1, rows 224, 500, 1200
  auto csv = fmt::output_file((out / "lod-table.csv").string());
  csv.print(
      "points,tr1,tr2,mode,selected,steps_per_s,seed_fps,active,realtime_factor,stable_dt_s,selection_ms,build_ms,threads\n");
  std::string md =
      "# Seed Table 1: simulation steps per second with levels of detail\n\n"
      "The seed's half-sphere (radius 5 cm, flat face held), the contact at its pole, one explicit step = one force "
      "evaluation and update. `selected`: points simulated; `active`: with the frozen ring that holds them. "
      "The seed's frame rates (3 GHz Pentium 4) for comparison.\n\n"
      "| points | T_r1, T_r2 | selected | active | steps/s | x full | seed fps | real-time factor |\n|---|---|---|---|---|---|---|---|\n";
  // progress: one line per timed configuration, with the time so far (the 100k-point object takes most of it)
  const auto started = std::chrono::steady_clock::now();
  const std::size_t n_configs = 4 * targets.size();
  std::size_t done = 0;
  const auto progress = [&](index_t n, const std::string& config, double steps_per_s) {
    ++done;
    fmt::print("lod-table: [{}/{}] {} points, {}: {:.0f} steps/s ({:.0f} s so far)\n", done, n_configs, n, config,
               steps_per_s, std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    std::fflush(stdout);
  };
  for (std::size_t o = 0; o < targets.size(); ++o) {
    const double spacing = spacing_for(targets[o]);
    Model model = build_scene_model(half_sphere(spacing));
    const index_t pole = nearest_point(model, Vec3(0, radius, 0));
    model.f_ext(1, pole) = 0.01;  // a small pull at the contact, so that something moves
    const SolverSpec solver = half_sphere(spacing).solver;
    fmt::print("lod-table: {} points (spacing {:.3g} m)\n", model.n_points, spacing);
    Simulation full(model, solver, options.threads);
    const Timing tf = time_steps(full, options.seconds);
    progress(model.n_points, "full model", tf.steps_per_s);
    csv.print("{},,,full,{},{:.6g},,{},{:.6g},{:.6g},,,{}\n", model.n_points, model.n_points, tf.steps_per_s,
              model.n_points, tf.realtime, tf.stable_dt, options.threads);
    md += fmt::format("| {} | full model | {} | {} | {:.0f} | 1 | | {:.3f} |\n", model.n_points, model.n_points,
                      model.n_points, tf.steps_per_s, tf.realtime);
    for (int b = 0; b < 3; ++b) {
      Simulation sim(model, solver, options.threads);
      sim.enable_lod(bands(tr[b][0], tr[b][1]), model.X.col(pole));
      const Timing t = time_steps(sim, options.seconds);
      progress(model.n_points, fmt::format("T_r1 = {}h, T_r2 = {}h", tr[b][0], tr[b][1]), t.steps_per_s);
      const RunSummary s = sim.summary();
      const std::optional<double> fps = o < 3 ? std::optional<double>(seed_fps[o][b]) : std::nullopt;
      csv.print("{},{},{},lod,{},{:.6g},{},{},{:.6g},{:.6g},{:.4g},{:.4g},{}\n", model.n_points, tr[b][0], tr[b][1],
                s.lod.selected, t.steps_per_s, csv_or_empty(fps), s.lod.selected + s.lod.frozen, t.realtime,
                t.stable_dt, s.lod.selection_ms, s.lod.build_ms, options.threads);
      md += fmt::format("| {} | {}h, {}h | {} | {} | {:.0f} | {:.1f} | {} | {:.3f} |\n", model.n_points, tr[b][0],
                        tr[b][1], s.lod.selected, s.lod.selected + s.lod.frozen, t.steps_per_s,
                        t.steps_per_s / tf.steps_per_s, fps ? fmt::format("{:.0f}", *fps) : "", t.realtime);
    }
  }
  csv.close();
  auto summary = fmt::output_file((out / "lod-table.md").string());
  summary.print("{}", md);
  summary.close();
  fmt::print("{}", md);
  return run_plot_script("plot_lod.py", out.string());
}

int run_propagation_experiment(const LodExperimentOptions& options) {
  fs::create_directories(options.out);
  const fs::path out = options.out;
  // seed Fig. 7-9: the 224-point object, a constant pull at point 111, every displacement at t = 9 s
  const double spacing = spacing_for(224);
  Model model = build_scene_model(half_sphere(spacing));
  const index_t pulled = 111;
  if (model.n_points <= pulled) throw Error("propagation: the object has fewer than 112 points");
  const Vec3 at = model.X.col(pulled);
  const Vec3 outward = (at - Vec3(0, 0, 0)).normalized();
  model.f_ext.col(pulled) = 0.01 * outward;  // 0.01 N, outward from the centre
  const double duration = options.quick ? 3.0 : 9.0;
  const double whole = 2.0 * radius / model.h + 1.0;  // the one propagation level reaches every point

  struct Run {
    std::string name;
    std::optional<LodParams> lod;
    Points u;
    Timing timing;
    std::vector<char> selected;
    index_t n_selected = 0;
  };
  std::vector<Run> runs;
  runs.push_back({"full", std::nullopt, {}, {}, {}, 0});
  for (LodScheme scheme : {LodScheme::RANDOM, LodScheme::DITHER})
    for (int K : {6, 8})
      runs.push_back({fmt::format("{} {:.1f}", to_string(scheme), (10 - K) / 10.0),
                      bands(1.0, 1.5, {{whole, K}}, scheme),
                      {},
                      {},
                      {},
                      0});
  for (Run& r : runs) {
    Simulation sim(model, half_sphere(spacing).solver, options.threads);
    if (r.lod) sim.enable_lod(*r.lod, at);
    const auto start = std::chrono::steady_clock::now();
    sim.run(duration);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const RunSummary s = sim.summary();
    r.u = sim.state().u;
    r.timing.steps_per_s = s.substeps / wall;
    r.timing.realtime = duration / wall;
    r.timing.stable_dt = s.stable_dt;
    r.selected = r.lod ? s.lod.active : std::vector<char>(model.n_points, 1);
    r.n_selected = r.lod ? s.lod.selected : model.n_points;
    fmt::print("propagation: {}: {} points simulated, {:.0f} steps/s\n", r.name, r.n_selected, r.timing.steps_per_s);
  }
  // per point
  auto csv = fmt::output_file((out / "propagation.csv").string());
  csv.print("index,x,y,z");
  for (const Run& r : runs) {
    std::string slug = r.name;
    std::replace(slug.begin(), slug.end(), ' ', '_');
    csv.print(",u_{0},selected_{0}", slug);
  }
  csv.print("\n");
  for (index_t i = 0; i < model.n_points; ++i) {
    csv.print("{},{:.6g},{:.6g},{:.6g}", i, model.X(0, i), model.X(1, i), model.X(2, i));
    for (const Run& r : runs) csv.print(",{:.6g},{}", r.u.col(i).norm(), r.selected[i] ? 1 : 0);
    csv.print("\n");
  }
  csv.close();
  // per run
  auto runs_csv = fmt::output_file((out / "propagation-runs.csv").string());
  runs_csv.print("run,selected,steps_per_s,realtime_factor,max_u_m,error_near_pct,error_whole_pct\n");
  std::string md = fmt::format(
      "# Seed Fig. 8-9: one propagation level at selection weight 0.4 and 0.2\n\n"
      "The {}-point half-sphere, a constant pull of 0.01 N at point {} (({:.4f}, {:.4f}, {:.4f}) m, outward), "
      "displacements at t = {} s; T_r1 = h, T_r2 = 1.5h, one propagation level over the whole object. "
      "Errors against the full model: the largest inside T_r1 (relative to the largest displacement there) and "
      "the RMS over the object.\n\n"
      "| run | points simulated | steps/s | real-time factor | max displacement (mm) | error inside T_r1 | error, whole object |\n"
      "|---|---|---|---|---|---|---|\n",
      model.n_points, pulled, at.x(), at.y(), at.z(), duration);
  const Points& reference = runs.front().u;
  for (const Run& r : runs) {
    const Errors e = errors(model, r.u, reference, at, model.h);
    runs_csv.print("{},{},{:.6g},{:.6g},{:.6g},{:.4g},{:.4g}\n", r.name, r.n_selected, r.timing.steps_per_s,
                   r.timing.realtime, r.u.colwise().norm().maxCoeff(), 100 * e.near, 100 * e.whole);
    md += fmt::format("| {} | {} | {:.0f} | {:.2f} | {:.3f} | {:.1f}% | {:.1f}% |\n", r.name, r.n_selected,
                      r.timing.steps_per_s, r.timing.realtime, 1e3 * r.u.colwise().norm().maxCoeff(), 100 * e.near,
                      100 * e.whole);
  }
  runs_csv.close();
  auto summary = fmt::output_file((out / "summary.md").string());
  summary.print("{}", md);
  summary.close();
  fmt::print("{}", md);
  return run_plot_script("plot_propagation.py", out.string());
}

namespace {

// "k1,k2[,min_neighbours];P:K;P:K" (units of h; P = 0: the whole object)
LodParams parse_config(const std::string& text, double whole) {
  LodParams p;
  std::size_t at = text.find(';');
  const std::string head = text.substr(0, at);
  if (std::sscanf(head.c_str(), "%lf,%lf,%d", &p.k1, &p.k2, &p.min_neighbours) < 2)
    throw Error(fmt::format("lod-error: --config \"{}\": expected \"k1,k2[,min_neighbours];P:K;...\"", text));
  while (at != std::string::npos) {
    const std::size_t next = text.find(';', at + 1);
    const std::string level = text.substr(at + 1, next == std::string::npos ? std::string::npos : next - at - 1);
    LodLevel l;
    if (std::sscanf(level.c_str(), "%lf:%d", &l.distance, &l.K) != 2)
      throw Error(fmt::format("lod-error: --config: level \"{}\" is not P:K", level));
    if (l.distance == 0) l.distance = whole;
    p.levels.push_back(l);
    at = next;
  }
  validate(p);
  return p;
}

std::string describe(const LodParams& p, double whole) {
  std::string s = fmt::format("T_r1 = {}h, T_r2 = {}h", p.k1, p.k2);
  if (p.min_neighbours != LodParams{}.min_neighbours) s += fmt::format(", {} neighbours", p.min_neighbours);
  for (const LodLevel& l : p.levels)
    s += l.distance >= whole ? fmt::format("; whole object at K = {}", l.K)
                             : fmt::format("; to {}h at K = {}", l.distance, l.K);
  return s;
}

}  // namespace

int run_lod_error_experiment(const LodExperimentOptions& options) {
  fs::create_directories(options.out);
  const fs::path out = options.out;
  // the displacement error against the full model's equilibrium, against the speed-up of the explicit
  // step, for the seed's random selection (three seeds) and the dithered one
  const int target = options.points > 0 ? options.points : options.quick ? 1200 : 10000;
  const double spacing = spacing_for(target);
  Scene scene = half_sphere(spacing);
  Model model = build_scene_model(scene);
  const index_t pole = nearest_point(model, Vec3(0, radius, 0));
  const Vec3 c = model.X.col(pole);
  const bool indent = options.load == "indent";
  std::string load_text;
  if (indent) {
    // a probe's imprint: the points within 0.75 h of the pole pushed 1 mm down (prescribed)
    FixedGroup imprint;
    imprint.name = "imprint";
    imprint.displacement = Vec3(0, -1e-3, 0);
    for (index_t i = 0; i < model.n_points; ++i)
      if ((model.X.col(i) - c).norm() <= 0.75 * model.h) {
        imprint.points.push_back(i);
        model.fixed[i] = 1;
      }
    model.fixed_groups.push_back(imprint);
    load_text = fmt::format("the {} points within 0.75 h of the pole pushed 1 mm in", imprint.points.size());
  } else {
    model.f_ext(1, pole) = 0.01;
    load_text = "a pull of 0.01 N at the pole";
  }
  SolverSpec statics = scene.solver;
  statics.kind = SolverKind::STATIC;
  Points reference;
  Vec3 full_force = Vec3::Zero();  // indent: what the imprint's support (the probe) feels
  double full_steps = 0, full_realtime = 0;
  {
    const auto start = std::chrono::steady_clock::now();
    Simulation sim(model, statics, options.threads);
    sim.step();
    if (!sim.summary().converged) throw Error("lod-error: the full model's static solve did not converge");
    reference = sim.state().u;
    full_force = sim.summary().reactions.back();
    fmt::print("lod-error: full model, {} points: static solve in {:.1f} s\n", model.n_points,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    Simulation dyn(model, scene.solver, options.threads);
    const Timing t = time_steps(dyn, options.seconds);
    full_steps = t.steps_per_s;
    full_realtime = t.realtime;
  }
  const double whole = 2.0 * radius / model.h + 1.0;
  auto csv = fmt::output_file((out / "lod-error.csv").string());
  csv.print(
      "points,scheme,seed,level_distance_h,K,weight,selected,active,steps_per_s,speedup,realtime_speedup,error_near_pct,"
      "error_whole_pct,error_near_rms_pct,force_error_pct,config\n");
  csv.print("{},full,,,,1,{},{},{:.6g},1,1,0,0,0,0,full\n", model.n_points, model.n_points, model.n_points, full_steps);
  struct Row {
    std::string scheme, config;
    double P;
    int K;
    double speedup = 0, steps = 0, near = 0, near_rms = 0, whole = 0, force = 0;
    int n = 0;
  };
  std::vector<Row> rows;
  struct Config {
    LodParams params;
    bool single_scheme;
  };
  std::vector<Config> configs;
  if (!options.levels.empty()) {
    for (LodScheme scheme : {LodScheme::RANDOM, LodScheme::DITHER}) {
      LodParams p = parse_config(options.levels, whole);
      p.scheme = scheme;
      configs.push_back({p, false});
    }
  } else {
    for (double P : {3.0, whole})
      for (int K : {0, 4, 6, 8, 9})
        for (LodScheme scheme : {LodScheme::RANDOM, LodScheme::DITHER}) {
          if (K == 0 && scheme == LodScheme::DITHER) continue;  // weight 1: both select everything
          configs.push_back({bands(1.0, 1.5, {{P, K}}, scheme), K == 0});
        }
  }
  for (const Config& cfg : configs) {
    const LodParams& base = cfg.params;
    const double P = base.levels.empty() ? base.k2 : base.levels.back().distance;
    const int K = base.levels.empty() ? 0 : base.levels.back().K;
    Row row{cfg.single_scheme ? std::string("all") : std::string(to_string(base.scheme)), describe(base, whole), P, K};
    const int seeds = base.scheme == LodScheme::RANDOM && !cfg.single_scheme ? 3 : 1;
    for (int seed = 1; seed <= seeds; ++seed) {
      LodParams p = base;
      p.seed = static_cast<std::uint64_t>(seed);
      Simulation sim(model, statics, options.threads);
      sim.enable_lod(p, c);
      sim.step();
      const RunSummary s = sim.summary();
      const Errors e = errors(model, sim.state().u, reference, c, p.k1 * model.h);
      Simulation dyn(model, scene.solver, options.threads);
      dyn.enable_lod(p, c);
      const Timing t = time_steps(dyn, options.seconds / 2);
      const double force = indent ? (s.reactions.back() - full_force).norm() / full_force.norm() : 0.0;
      csv.print("{},{},{},{:.4g},{},{:.1f},{},{},{:.6g},{:.4g},{:.4g},{:.4g},{:.4g},{:.4g},{:.4g},\"{}\"\n",
                model.n_points, row.scheme, seed, P, K, (10 - K) / 10.0, s.lod.selected, s.lod.selected + s.lod.frozen,
                t.steps_per_s, t.steps_per_s / full_steps, t.realtime / full_realtime, 100 * e.near, 100 * e.whole,
                100 * e.near_rms, 100 * force, row.config);
      row.near_rms += e.near_rms / seeds;
      row.force += force / seeds;
      row.steps += t.steps_per_s / seeds;
      row.speedup += t.steps_per_s / full_steps / seeds;
      row.near += e.near / seeds;
      row.whole += e.whole / seeds;
      row.n += s.lod.selected;
      if (!s.converged)
        fmt::print(stderr, "lod-error: a static solve did not converge ({}, {}, seed {})\n", row.config, row.scheme,
                   seed);
    }
    row.n /= seeds;
    fmt::print(
        "lod-error: {} {}: {} points, {:.0f} steps/s (x{:.1f}), error inside T_r1 max {:.2f}% rms {:.2f}%, whole {:.2f}%, "
        "force {:.2f}%\n",
        row.config, row.scheme, row.n, row.steps, row.speedup, 100 * row.near, 100 * row.near_rms, 100 * row.whole,
        100 * row.force);
    rows.push_back(row);
  }
  csv.close();
  std::string md = fmt::format(
      "# Displacement error against speed-up: the seed's random selection and the dithered one\n\n"
      "The {}-point half-sphere, {}, static equilibrium, with levels of detail around the pole; the random scheme "
      "averaged over 3 seeds. Steps: explicit steps per second ({} threads; the full model makes {:.0f}/s), each of "
      "which can publish a local contact model to the haptic loop. Displacement errors against the full model: inside "
      "T_r1 the largest (relative to the largest displacement there) and the RMS (relative to the RMS there); over the "
      "whole object the RMS; with an imprint, the error of the force the probe feels.\n\n"
      "| configuration | scheme | points simulated | steps/s | speed-up | inside T_r1, max | inside T_r1, RMS | whole object | force |\n"
      "|---|---|---|---|---|---|---|---|---|\n",
      model.n_points, load_text, options.threads == 0 ? std::string("all") : std::to_string(options.threads),
      full_steps);
  for (const Row& r : rows)
    md += fmt::format("| {} | {} | {} | {:.0f} | {:.1f} | {:.1f}% | {:.1f}% | {:.1f}% | {} |\n", r.config, r.scheme,
                      r.n, r.steps, r.speedup, 100 * r.near, 100 * r.near_rms, 100 * r.whole,
                      indent ? fmt::format("{:.1f}%", 100 * r.force) : "");
  auto summary = fmt::output_file((out / "lod-error.md").string());
  summary.print("{}", md);
  summary.close();
  fmt::print("{}", md);
  return run_plot_script("plot_lod_error.py", out.string());
}

}  // namespace pointhaptics::experiments
