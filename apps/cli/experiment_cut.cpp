#include "experiment_cut.hpp"

#include "plots.hpp"

#include <pointhaptics/haptics/devices/virtual_device.hpp>
#include <pointhaptics/haptics/force_rendering.hpp>
#include <pointhaptics/mechanics/cut.hpp>
#include <pointhaptics/pointhaptics.hpp>

#include <fmt/format.h>
#include <fmt/os.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>

namespace pointhaptics::experiments {

namespace {

/// The seed's cantilever (0.15 x 0.03 x 0.03 m, 7.5 mm spacing, clamped at x = 0) at E = 1e6 Pa under its weight,
/// as scenes/cantilever_cut.toml has it, without its script.
Scene cantilever() {
  Scene scene;
  scene.path = "cut-cantilever";
  scene.object.size = Vec3(0.15, 0.03, 0.03);
  scene.object.spacing = 0.0075;
  scene.material.young = 1e6;
  scene.material.poisson = 0.4;
  scene.material.density = 1000;
  scene.material.damping = 20;
  FixedSpec root;
  root.box = {Vec3(-1, -1, -1), Vec3(0, 1, 1)};
  scene.fixed = {root};
  LoadSpec gravity;
  gravity.kind = LoadKind::GRAVITY;
  scene.loads = {gravity};
  scene.solver.kind = SolverKind::EXPLICIT;
  scene.solver.dt = 1e-3;
  return scene;
}

/// What a cut run measured, for cut.json, and the frames of its surface for the pictures.
struct CutRun {
  nlohmann::json json;
  nlohmann::json frames = nlohmann::json::array();
  long long pieces = 0, cut_pairs = 0, non_finite = 0;
  double max_update_ms = 0, max_force_step_n = 0;
};

/// A frame of the object's surface as its cuts leave it (split along their sheets), deformed by u x `scale`:
/// vertices, triangles, and how many of the last ones are faces of cuts.
nlohmann::json surface_frame(const std::string& title, CutSurface& surface, const Simulation& sim, double scale) {
  const ObjectSurface& cut = surface.at(sim.model(), sim.cut_sheets());
  const Points y = deformed_surface(cut, scale * sim.state().u);
  nlohmann::json vertices = nlohmann::json::array(), faces = nlohmann::json::array();
  for (Eigen::Index v = 0; v < y.cols(); ++v) vertices.push_back({y(0, v), y(1, v), y(2, v)});
  for (const auto& f : cut.mesh.F) faces.push_back({f[0], f[1], f[2]});
  return {{"title", title},
          {"time_s", sim.time()},
          {"vertices", std::move(vertices)},
          {"faces", std::move(faces)},
          {"cut_faces", cut.cut_faces}};
}

long long non_finite_entries(const Points& p) { return static_cast<long long>((!p.array().isFinite()).count()); }

// a blade 5 cm long along z drawn down through the plane x = 3.375 cm at 0.35 m/s, button held, resisting with
// `resistance` J/m^2
CutRun blade_through_cantilever(const CutOptions& options, double resistance) {
  const Scene scene = cantilever();
  Simulation sim(build_scene_model(scene), scene.solver, options.threads);
  const Vec3 above(0.03375, 0.05, 0.015), below(0.03375, -0.02, 0.015);
  VirtualDevice device(Trajectory({{0.0, Vec3::Zero(), true},
                                   {0.05, Vec3::Zero(), true},
                                   {0.25, below - above, true},
                                   {0.5, below - above, true}}),
                       known_device_specs("touch"));
  InteractiveOptions o;
  o.probe.radius = 0.001;
  o.probe.length = 0.05;
  o.probe.mode = ProbeMode::CUT;
  o.probe.cut_resistance = resistance;
  o.mapping.origin = above;
  o.duration = 0.5;
  o.real_time = false;
  double work = 0, largest = 0, blade_step = 0;
  Vec3 last_probe = Vec3::Constant(NAN), last_force = Vec3::Zero();
  CutRun run;
  // the surface as the blade goes through and the free piece falls
  CutSurface surface(build_object_surface(scene, sim.model()));
  const std::vector<double> frame_times{0.1, 0.15, 0.2, 0.3, 0.4, 0.5};
  std::size_t next_frame = 0;
  o.after_step = [&](long long) {
    if (next_frame < frame_times.size() && sim.time() >= frame_times[next_frame] - 1e-9) {
      run.frames.push_back(
          surface_frame(fmt::format("blade through the cantilever, t = {:.2f} s", sim.time()), surface, sim, 1.0));
      ++next_frame;
    }
    const ProbeTool* tool = sim.probe();
    const Vec3 f = tool->contact_model().f0;
    if (last_probe.allFinite()) work -= f.dot(tool->probe() - last_probe);
    largest = std::max(largest, f.norm());
    blade_step = std::max(blade_step, (f - last_force).norm());
    last_probe = tool->probe();
    last_force = f;
  };
  const InteractiveResult r = run_interactive(sim, device, o);
  if (r.haptic.device_failed) throw Error(fmt::format("experiment cut: the device failed: {}", r.haptic.device_error));
  if (sim.diagnostics().failed) throw Error(fmt::format("experiment cut: {}", sim.diagnostics().failure));
  const RunSummary s = sim.summary();
  double tick_step = 0;
  for (std::size_t k = 0; k < r.log.size(); ++k) {
    run.non_finite += !r.log[k].force.allFinite();
    if (k > 0) tick_step = std::max(tick_step, (r.log[k].force - r.log[k - 1].force).norm());
  }
  run.non_finite += non_finite_entries(sim.state().u) + non_finite_entries(sim.state().velocity);
  run.pieces = static_cast<long long>(s.cut.piece_points.size());
  run.cut_pairs = s.cut.cut_pairs;
  run.max_update_ms = s.cut.max_update_ms;
  run.max_force_step_n = tick_step;
  const double area = cut_area(sim.model(), s.cut.cut_pairs);
  // the free piece: its points' mean vertical speed, against the damping's terminal g / c
  double free_velocity = 0;
  long long free_points = 0;
  for (index_t i = 0; i < sim.model().n_points; ++i)
    if (sim.model().X(0, i) > above.x()) {
      free_velocity += sim.state().velocity(1, i);
      ++free_points;
    }
  run.json = {{"points", sim.model().n_points},
              {"pieces", run.pieces},
              {"piece_points", s.cut.piece_points},
              {"cut_pairs", run.cut_pairs},
              {"cut_area_m2", area},
              {"section_area_m2", 9e-4},
              {"cut_resistance_j_per_m2", resistance},
              {"work_j", work},
              {"resistance_times_area_j", resistance * area},
              {"largest_force_n", largest},
              {"max_blade_force_step_n", blade_step},
              {"max_force_step_n", tick_step},
              {"per_tick_bound_n", ForceRules{}.max_change},
              {"sweeps", s.cut.sweeps},
              {"max_update_ms", s.cut.max_update_ms},
              {"mean_update_ms", s.cut.mean_update_ms},
              {"free_piece_speed_m_per_s", free_points > 0 ? free_velocity / static_cast<double>(free_points) : 0.0},
              {"terminal_speed_m_per_s", -9.81 / scene.material.damping},
              {"non_finite", run.non_finite}};
  return run;
}

// a block 6 x 3 x 3 cm, bottom held, its two end faces pulled apart; statically, without and with a slit cut
// from the top down to mid-height between two planes of points: how far the slit's lips open at the top
CutRun slit_opens_under_load(const CutOptions& options) {
  Scene scene;
  scene.path = "cut-slit";
  scene.object.size = Vec3(0.06, 0.03, 0.03);
  scene.object.spacing = 0.003;
  scene.material.young = 1e5;
  scene.material.poisson = 0.4;
  scene.material.model = MaterialModel::NEO_HOOKEAN;
  FixedSpec bottom;
  bottom.box = {Vec3(-1, -1, -1), Vec3(1, 0, 1)};
  scene.fixed = {bottom};
  LoadSpec left, right;
  left.box = {Vec3(-1, -1, -1), Vec3(0, 1, 1)};
  left.total = Vec3(-0.5, 0, 0);
  right.box = {Vec3(0.06, -1, -1), Vec3(1, 1, 1)};
  right.total = Vec3(0.5, 0, 0);
  scene.loads = {left, right};
  scene.solver.kind = SolverKind::STATIC;
  const double x_slit = 0.0315, top = 0.03;
  auto opening = [&](const Simulation& sim) {
    // mean x-gap change between the top points on either side of the slit, m
    const Model& m = sim.model();
    double sum = 0;
    int n = 0;
    for (index_t i = 0; i < m.n_points; ++i)
      if (std::abs(m.X(1, i) - top) < 1e-9 && std::abs(m.X(0, i) - (x_slit + 0.0015)) < 1e-6) {
        for (index_t j = 0; j < m.n_points; ++j)
          if (std::abs(m.X(1, j) - top) < 1e-9 && std::abs(m.X(0, j) - (x_slit - 0.0015)) < 1e-6 &&
              std::abs(m.X(2, j) - m.X(2, i)) < 1e-9) {
            sum += sim.state().u(0, i) - sim.state().u(0, j);
            ++n;
          }
      }
    return n > 0 ? sum / n : 0.0;
  };
  Simulation whole(build_scene_model(scene), scene.solver, options.threads);
  whole.run(0);
  CutSpec slit;
  slit.edge = {Vec3(x_slit, 0.04, -0.01), Vec3(x_slit, 0.04, 0.04)};
  slit.to = {Vec3(x_slit, 0.015, -0.01), Vec3(x_slit, 0.015, 0.04)};
  Simulation cut(build_scene_model(scene), scene.solver, options.threads);
  cut.add_scripted_cut(slit);
  cut.run(0);
  for (const Simulation* s : {&whole, &cut})
    if (s->diagnostics().failed)
      throw Error(fmt::format("experiment cut: the slit's static solve failed: {}", s->diagnostics().failure));
  const RunSummary s = cut.summary();
  CutRun run;
  CutSurface surface(build_object_surface(scene, cut.model()));
  run.frames.push_back(surface_frame("the slit pulled open (displacements x 10)", surface, cut, 10.0));
  run.non_finite = non_finite_entries(cut.state().u) + non_finite_entries(whole.state().u);
  run.pieces = static_cast<long long>(s.cut.piece_points.size());
  run.cut_pairs = s.cut.cut_pairs;
  run.max_update_ms = s.cut.max_update_ms;
  run.json = {{"points", cut.model().n_points},
              {"pieces", run.pieces},
              {"cut_pairs", run.cut_pairs},
              {"slit_depth_m", top - 0.015},
              {"opening_whole_m", opening(whole)},
              {"opening_slit_m", opening(cut)},
              {"converged", s.converged},
              {"regularised_neighbourhoods", cut.model().diagnostics.regularised_neighbourhoods},
              {"max_update_ms", s.cut.max_update_ms},
              {"non_finite", run.non_finite}};
  return run;
}

}  // namespace

int run_cut_experiment(const CutOptions& options) {
  namespace fs = std::filesystem;
  fs::create_directories(options.out);
  const fs::path out = options.out;
  const double resistance = 50.0;
  const CutRun through = blade_through_cantilever(options, resistance);
  const CutRun slit = slit_opens_under_load(options);
  const nlohmann::json doc = {{"pieces", through.pieces},
                              {"cut_pairs", through.cut_pairs + slit.cut_pairs},
                              {"max_update_ms", std::max(through.max_update_ms, slit.max_update_ms)},
                              {"max_force_step_n", through.max_force_step_n},
                              {"non_finite", through.non_finite + slit.non_finite},
                              {"through", through.json},
                              {"slit", slit.json}};
  auto json = fmt::output_file((out / "cut.json").string());
  json.print("{}\n", doc.dump(1));
  json.close();
  nlohmann::json frames = through.frames;
  for (const auto& f : slit.frames) frames.push_back(f);
  auto frames_file = fmt::output_file((out / "surface-frames.json").string());
  frames_file.print("{}\n", frames.dump());
  frames_file.close();
  const int plots = run_plot_script("plot_cut.py", out.string());
  const nlohmann::json& t = through.json;
  const nlohmann::json& s = slit.json;
  auto md = fmt::output_file((out / "summary.md").string());
  md.print(
      "# Cutting (issue 18)\n\n"
      "## A device's blade through the seed's cantilever\n\n"
      "The cantilever (0.15 x 0.03 x 0.03 m, {} points, E = 1e6 Pa, under its weight). A virtual hand draws a 5 cm blade "
      "down through x = 3.375 cm at 0.35 m/s, button held, cut resistance {} J/m^2 (deterministic, simulated time).\n\n"
      "| | |\n|---|---|\n"
      "| pieces | {} ({} points) |\n| pairs cut | {} |\n| their area | {:.3g} m^2 (the section: 9e-4 m^2) |\n"
      "| the hand's work against the resistance | {:.4g} J (resistance x area: {:.4g} J) |\n"
      "| largest resistance | {:.3g} N |\n| largest change of the commanded force per tick | {:.3g} N (bound {:.3g} N) |\n"
      "| steps that cut, update mean / max | {}, {:.2f} / {:.2f} ms |\n| the free piece's fall | {:.3f} m/s (terminal {:.3f} m/s) |\n"
      "| non-finite values | {} |\n\n"
      "## A slit that opens under load\n\n"
      "A block 6 x 3 x 3 cm ({} points, neo-Hookean, E = 1e5 Pa), bottom held, its end faces pulled apart by 0.5 N each, "
      "solved statically. A scripted blade cuts a slit {} cm deep from the top between two planes of points.\n\n"
      "| | |\n|---|---|\n| pieces | {} |\n| pairs cut | {} |\n| the top's opening across the slit, whole | {:.4g} m |\n"
      "| ... with the slit | {:.4g} m |\n| converged | {} |\n| non-finite values | {} |\n\n"
      "## The surface\n\n"
      "The object's surface split along the cuts' sheets (the faces of the cuts darker), as the blade goes through "
      "and the free piece falls, then the slit pulled open (displacements x 10): `surface-1.png` ... `surface-{}.png`, "
      "all in `surface-series.png`; the frames' vertices and triangles in `surface-frames.json`.\n",
      t["points"].get<long long>(), resistance, t["pieces"].get<long long>(), t["piece_points"].dump(),
      t["cut_pairs"].get<long long>(), t["cut_area_m2"].get<double>(), t["work_j"].get<double>(),
      t["resistance_times_area_j"].get<double>(), t["largest_force_n"].get<double>(),
      t["max_force_step_n"].get<double>(), t["per_tick_bound_n"].get<double>(), t["sweeps"].get<long long>(),
      t["mean_update_ms"].get<double>(), t["max_update_ms"].get<double>(), t["free_piece_speed_m_per_s"].get<double>(),
      t["terminal_speed_m_per_s"].get<double>(), t["non_finite"].get<long long>(), s["points"].get<long long>(),
      100 * s["slit_depth_m"].get<double>(), s["pieces"].get<long long>(), s["cut_pairs"].get<long long>(),
      s["opening_whole_m"].get<double>(), s["opening_slit_m"].get<double>(), s["converged"].get<bool>(),
      s["non_finite"].get<long long>(), frames.size());
  md.close();
  fmt::print(
      "cut: blade through the cantilever: {} pieces, {} pairs, work {:.4g} J against {:.4g} J, force step per tick {:.3g} N; "
      "slit: opening {:.3g} m against {:.3g} m whole; non-finite {}\n",
      t["pieces"].get<long long>(), t["cut_pairs"].get<long long>(), t["work_j"].get<double>(),
      t["resistance_times_area_j"].get<double>(), t["max_force_step_n"].get<double>(),
      s["opening_slit_m"].get<double>(), s["opening_whole_m"].get<double>(), doc["non_finite"].get<long long>());
  fmt::print("wrote {}\n", out.string());
  // what must hold: nothing non-finite, the cantilever in two, the slit open wider than the whole block's top,
  // both surfaces split (faces of cuts), the pictures drawn
  const bool held = doc["non_finite"].get<long long>() == 0 && through.pieces == 2 && slit.pieces == 1 &&
                    s["opening_slit_m"].get<double>() > 2 * s["opening_whole_m"].get<double>() && plots == 0 &&
                    through.frames.back()["cut_faces"].get<long long>() > 0 &&
                    slit.frames.back()["cut_faces"].get<long long>() > 0;
  if (!held) fmt::print(stderr, "experiment cut: a check failed (see {})\n", (out / "cut.json").string());
  return held ? 0 : 1;
}

}  // namespace pointhaptics::experiments
