// pointhaptics: the command line. `pointhaptics <command> [scene.toml] [options]`, --help on every command.
#include "experiment_beam.hpp"
#include "experiment_cantilever.hpp"
#include "experiment_contact.hpp"
#include "experiment_contact_pairs.hpp"
#include "experiment_cut.hpp"
#include "experiment_force_profile.hpp"
#include "experiment_lod.hpp"
#include "experiment_materials.hpp"
#include "experiment_reduction.hpp"
#include "progress_bar.hpp"
#include "python_command.hpp"

#include <pointhaptics/core/stoppable_call.hpp>
#include <pointhaptics/io/mesh_file.hpp>
#include <pointhaptics/pointhaptics.hpp>

#include "bench_suite.hpp"
#ifdef PH_HAVE_VIEWER
#include "viewer.hpp"
#endif

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace ph = pointhaptics;

namespace {

struct RunOptions {
  std::string scene;
  std::string json;
  std::string force_log;
  std::string tool_log;
  std::string vtk;
  std::string csv;
  std::string surface;
  int vtk_every = 0;
  bool deterministic = false;
  bool quiet = false;
  int threads = 0;
  std::uint64_t max_memory = 0;       ///< bytes; 0: the memory available
  std::vector<std::string> settings;  ///< --set key=value
};

void print_summary(ph::Simulation& sim, const ph::RunSummary& s, double setup_s) {
  const ph::Model& m = sim.model();
  const ph::State& st = sim.state();
  Eigen::Index worst = 0;
  const double max_u = m.n_points ? st.u.colwise().norm().maxCoeff(&worst) : 0.0;
  fmt::print("points          {} ({} held), h = {:.4g} m, {:.1f} neighbours per point (min {}), kernel {}\n",
             m.n_points, std::count(m.fixed.begin(), m.fixed.end(), 1), m.h, m.diagnostics.mean_neighbours,
             m.diagnostics.min_neighbours, ph::to_string(m.kernel.type));
  if (m.diagnostics.regularised_neighbourhoods)
    fmt::print("warning         {} neighbourhoods were ill-conditioned and regularised\n",
               m.diagnostics.regularised_neighbourhoods);
  fmt::print("material        {}: E = {:.4g} Pa, nu = {:.3g}, rho = {:.4g} kg/m^3, total mass {:.4g} kg{}\n",
             ph::to_string(m.material.model), m.material.young, m.material.poisson, m.material.density, m.mass.sum(),
             m.point_materials.size() > 1 ? fmt::format("; {} region materials", m.point_materials.size() - 1) : "");
  if (s.inverted_steps > 0 || s.inverted > 0)
    fmt::print("warning         {} step{} ended with inverted neighbourhoods (det F <= 0); {} inverted at the end\n",
               s.inverted_steps, s.inverted_steps == 1 ? "" : "s", s.inverted);
  if (s.solver_kind == "static")
    fmt::print("solver          static: {} in {} load increments, {} Newton and {} CG iterations, residual {:.3g}\n",
               s.converged ? "converged" : "NOT converged", s.substeps, s.iterations, s.cg_iterations, s.residual);
  else if (s.solver_kind == "implicit")
    fmt::print("solver          implicit: {} steps of {:.3g} s, {} Newton and {} CG iterations, t = {:.4g} s{}\n",
               s.steps, sim.solver().dt, s.iterations, s.cg_iterations, st.time,
               s.budget_steps > 0 ? fmt::format("; {} steps ended at the iteration budget, last residual {:.3g}",
                                                s.budget_steps, s.residual)
                                  : std::string());
  else
    fmt::print("solver          {}: {} steps of {:.3g} s, {} sub-steps (stable sub-step {:.3g} s), t = {:.4g} s\n",
               s.solver_kind, s.steps, sim.solver().dt, s.substeps, s.stable_dt, st.time);
  if (s.preconditioner == "cholesky")
    fmt::print(
        "preconditioner  cholesky: {} factorisation{} of the tangent{}, factor {:.1f} MB\n", s.factorisations,
        s.factorisations == 1 ? "" : "s",
        s.background_factorisations > 0 ? fmt::format(" ({} in the background)", s.background_factorisations) : "",
        s.factor_bytes / 1e6);
  if (s.preconditioner == "two_level")
    fmt::print("preconditioner  two_level: a coarse level of {} points, its factor {:.2f} MB{}\n", s.coarse_points,
               s.factor_bytes / 1e6,
               s.coarse_points == 0 ? " (none: the object is too small; block-Jacobi alone)" : "");
  if (s.reduction.modes > 0) {
    const pointhaptics::ReductionSummary& r = s.reduction;
    fmt::print(
        "reduction       r = {} ({} modes, {} derivatives, {} load responses{}); set-up {:.2f} s (factor {:.2f} s, "
        "{:.0f} MB; modes {:.2f} s; derivatives {:.2f} s; polynomial {:.2f} s, {:.2f} MB)\n",
        r.modes, r.linear_modes, r.derivatives, r.load_vectors,
        r.basis_spacing > 0 ? fmt::format(", made at {} m", r.basis_spacing) : std::string(), r.setup_s, r.factorise_s,
        r.factor_bytes / 1e6, r.modes_s, r.derivatives_s, r.polynomial_s, r.tables_bytes / 1e6);
    fmt::print("                lowest natural frequency {:.4g} Hz; basis {}\n", r.first_frequency_hz,
               r.from_cache           ? fmt::format("read from {}", r.cache_file)
               : r.cache_file.empty() ? std::string("not kept")
                                      : fmt::format("kept in {}", r.cache_file));
    if (!r.cache_note.empty()) fmt::print("                {}\n", r.cache_note);
    if (r.contact_patches > 0)
      fmt::print(
          "                contact patch: up to {} points in full around the tools, chosen {} times, {} "
          "Hessians made\n",
          r.contact_points, r.contact_patches, r.contact_hessians);
  }
  fmt::print("displacement    max {:.4g} m at point {} ({:.4g}, {:.4g}, {:.4g})\n", max_u, worst, m.X(0, worst),
             m.X(1, worst), m.X(2, worst));
  // the out-of-balance force: |f_int + f_ext| over the free points relative to the load; in dynamics it is
  // the inertia (and a probe's push), not an error
  fmt::print("energy          strain {:.4g} J, kinetic {:.4g} J\n", s.strain_energy, s.kinetic_energy);
  fmt::print("out-of-balance  {:.3g} of the load{}\n", s.residual,
             s.reduction.modes > 0 && s.solver_kind == "static"
                 ? std::string(" (the full model's at u = U q: a reduced model balances the forces projected on its "
                               "basis, not every point's)")
             : s.solver_kind == "static" ? std::string(" (the equilibrium's residual)")
                                         : std::string(" (in dynamics the inertia and any probe force, not an error)"));
  for (size_t g = 0; g < s.reactions.size(); ++g)
    fmt::print("reaction        {}: ({:.4g}, {:.4g}, {:.4g}) N on {} points\n", m.fixed_groups[g].name,
               s.reactions[g][0], s.reactions[g][1], s.reactions[g][2], m.fixed_groups[g].points.size());
  if (s.tool.present)
    fmt::print(
        "tool            {} at ({:.4g}, {:.4g}, {:.4g}) m: the object pushes it with ({:.4g}, {:.4g}, {:.4g}) N, torque "
        "({:.3g}, {:.3g}, {:.3g}) N m; {} contacts, deepest {:.3g} m inside\n",
        s.tool.kind, s.tool.position.x(), s.tool.position.y(), s.tool.position.z(), s.tool.force.x(), s.tool.force.y(),
        s.tool.force.z(), s.tool.torque.x(), s.tool.torque.y(), s.tool.torque.z(), s.tool.contacts, s.tool.penetration);
  if (s.cut.present) {
    std::string sizes;
    for (size_t p = 0; p < s.cut.piece_points.size(); ++p)
      sizes += fmt::format("{}{}", p ? ", " : "", s.cut.piece_points[p]);
    fmt::print(
        "cut             {} steps cut, severing {} neighbour pairs; {} piece(s) of {} points; an update took {:.2f} ms "
        "on average, {:.2f} ms at most; {} sheet triangles{}\n",
        s.cut.sweeps, s.cut.cut_pairs, s.cut.piece_points.size(), sizes, s.cut.mean_update_ms, s.cut.max_update_ms,
        s.cut.sheet_triangles,
        s.cut.surface_splits ? fmt::format(", the probe's surface split {} times (at most {:.1f} ms)",
                                           s.cut.surface_splits, s.cut.max_split_ms)
                             : "");
  }
  if (s.lod.enabled) {
    std::string bands;
    for (size_t b = 0; b < s.lod.band_count.size(); ++b)
      bands += fmt::format("{}{}/{}", b ? ", " : "", s.lod.band_selected[b], s.lod.band_count[b]);
    fmt::print(
        "levels of detail {} of {} points simulated ({} held around them, {} with wider supports); selected per "
        "band {}; {} selections, the last {:.2f} ms + {:.2f} ms to build; a re-selection held the simulation for {:.2f} ms at most\n",
        s.lod.selected, m.n_points, s.lod.frozen, s.lod.widened, bands, s.lod.selections, s.lod.selection_ms,
        s.lod.build_ms, s.lod.max_reselect_ms);
  }
  if (s.solver_kind == "static") fmt::print("timing          set-up {:.3f} s, solve {:.3f} s\n", setup_s, s.wall_s);
  else
    fmt::print(
        "timing          set-up {:.3f} s, stepping {:.3f} s, {:.3f} ms per step (longest {:.3f} ms), {:.0f} steps/s\n",
        setup_s, s.wall_s, s.step_ms_mean, s.step_ms_max, s.steps_per_s);
}

// SIGINT or SIGTERM during a run: every loop of the set-up and of the steps polls the stop request
// (run_control.hpp), so that it is honoured within 0.1 s wherever the time goes, and what was reached is
// written (issues 21 and 52)
std::atomic<bool> interrupted{false};
extern "C" void on_interrupt(int) {
  interrupted.store(true);
  ph::request_stop();
}

// `run`'s exit status (README, "Running a scene"): 0 a physical result; 1 an error, a solve that did not
// converge, a failed output or device; 3 steps that ended with inverted neighbourhoods; 130 interrupted
constexpr int exit_unphysical_steps = 3;

// An output that fails (a full disk) is reported, and the others are still written
struct OutputErrors {
  std::vector<std::string> messages;
  template <class Write>
  void attempt(Write&& write) {
    try {
      write();
    } catch (const ph::Error& e) {
      messages.push_back(e.what());
    }
  }
};

// a second or later hand's force log, beside the first's: force.csv -> force-left.csv
std::string hand_log_path(const std::string& force_log, const std::string& hand) {
  const std::filesystem::path p = force_log;
  return (p.parent_path() / (p.stem().string() + "-" + hand + p.extension().string())).string();
}

int run_command(const RunOptions& opt) {
  // the ParaView folder first (made with its parents, so other outputs may go beside it), then every output
  // is checked before anything is computed: a long run must not end in "cannot write"
  std::optional<ph::VtkSeries> vtk;
  if (!opt.vtk.empty()) vtk.emplace(opt.vtk);
  if (!opt.json.empty()) ph::check_output_path(opt.json, "--json");
  if (!opt.csv.empty()) ph::check_output_path(opt.csv, "--csv");
  if (!opt.surface.empty()) ph::check_output_path(opt.surface, "--surface");
  if (!opt.force_log.empty()) ph::check_output_path(opt.force_log, "--force-log");
  if (!opt.tool_log.empty()) ph::check_output_path(opt.tool_log, "--tool-log");
  ph::SessionOptions session_options;
  session_options.threads = opt.threads;
  session_options.max_memory = static_cast<double>(opt.max_memory);
  for (const std::string& setting : opt.settings) session_options.settings.push_back(ph::parse_scene_setting(setting));
  // from here a signal stops the run where it is, the set-up included; long work is announced and shown
  interrupted.store(false);
  ph::clear_stop_request();
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);
  ph::cli::PhaseProgress progress(opt.scene, !opt.quiet);
  ph::set_progress_sink(&progress);
  struct Restore {
    ~Restore() {
      ph::set_progress_sink(nullptr);
      std::signal(SIGINT, SIG_DFL);
      std::signal(SIGTERM, SIG_DFL);
    }
  } restore;
  std::optional<ph::SceneSession> opened;
  // the object's surface, for --surface and the ParaView frames, built before the run (a reconstruction
  // too fine for the machine is refused at once)
  // (after cuts, split along them: cut_surface.hpp)
  std::optional<ph::CutSurface> surface;
  try {
    opened.emplace(ph::open_scene_file(opt.scene, session_options));
    if (!opt.surface.empty() || vtk)
      surface.emplace(ph::build_object_surface(opened->scene, opened->simulation->model()));
  } catch (const ph::Interrupted& e) {
    // stopped in the set-up: the result says so, with the model if there is one
    progress.finish();
    ph::RunSummary summary;
    summary.interrupted = true;
    summary.failure = e.what();
    if (!opt.json.empty()) {
      if (opened) ph::write_result_json(opt.json, opened->simulation->model(), opened->simulation->state(), summary);
      else ph::write_result_json(opt.json, ph::Model{}, ph::State{}, summary);
    }
    fmt::print(stderr, "pointhaptics: {}: {} (the set-up){}\n", opt.scene, e.what(),
               opened ? "" : "; no model was built");
    return 130;
  }
  ph::SceneSession& session = *opened;
  const ph::Scene& scene = session.scene;
  ph::Simulation& sim = *session.simulation;
  const double setup_s = session.setup_seconds;
  auto vtk_surface = [&]() -> const ph::ObjectSurface* {
    return surface ? &surface->at(sim.model(), sim.cut_sheets()) : nullptr;
  };
  // with several bodies, a series per body beside the object's
  std::vector<ph::VtkSeries> body_vtk = vtk ? ph::body_vtk_series(opt.vtk, sim.model()) : std::vector<ph::VtkSeries>{};
  if (vtk) ph::add_vtk_frame(*vtk, sim, vtk_surface(), &body_vtk);  // the initial state
  const double start_time = sim.time();
  const bool options_real_time = !opt.deterministic;
  ph::InteractiveResult interactive;
  OutputErrors errors;
  // a probe driven by a device runs the haptic loop; a tool held at a position is part of the scene's solve
  const bool haptic = scene.probe.present && !scene.probe.held();
  if (haptic) {
    // with a probe: the haptic loop at 1 kHz and the simulation, in real time unless asked otherwise
    ph::InteractiveOptions options = session.interactive;
    options.real_time = !opt.deterministic;
    options.stop = &interrupted;
    // the force log is streamed to its file as the run goes: any length in bounded memory
    options.log = false;
    std::optional<ph::TextOutput> force_log;
    // every other hand's beside it: force.csv, force-finger.csv, ... (a deque: the sinks hold their addresses)
    std::deque<ph::TextOutput> hand_logs;
    if (!opt.force_log.empty()) {
      force_log.emplace(opt.force_log, "--force-log");
      ph::print_haptic_log_header(*force_log);
      options.log_sink = [&force_log](const ph::HapticLogRow& row) { ph::print_haptic_log_row(*force_log, row); };
      for (ph::HandOptions& hand : options.other_hands) {
        ph::TextOutput& log = hand_logs.emplace_back(hand_log_path(opt.force_log, hand.name), "--force-log");
        ph::print_haptic_log_header(log);
        hand.log_sink = [&log](const ph::HapticLogRow& row) { ph::print_haptic_log_row(log, row); };
      }
    }
    // ParaView frames every --vtk-every steps (default: the first and last states only, since a real-time
    // run's step count is not known in advance)
    if (vtk && opt.vtk_every > 0)
      options.after_step = [&](long long step) {
        if (step % opt.vtk_every == 0) errors.attempt([&] { ph::add_vtk_frame(*vtk, sim, vtk_surface(), &body_vtk); });
      };
    interactive = ph::run_interactive(sim, *session.device, options);
    if (force_log) errors.attempt([&] { force_log->commit(); });
    for (ph::TextOutput& log : hand_logs) errors.attempt([&] { log.commit(); });
    const auto dropped = [&](const std::string& path, long long ticks) {
      if (ticks > 0)
        errors.messages.push_back(fmt::format(
            "--force-log {}: {} haptic ticks were not logged (the simulation thread fell behind)", path, ticks));
    };
    dropped(opt.force_log, interactive.log_dropped);
    if (!opt.force_log.empty())
      for (const ph::HandResult& hand : interactive.other_hands)
        dropped(hand_log_path(opt.force_log, hand.name), hand.log_dropped);
  } else {
    // the posed tools' forces at every step (and the start): t, tool, force, its friction part, contacts, depth
    std::optional<ph::TextOutput> tool_log;
    const auto log_tools = [&] {
      for (const auto& [name, load] : sim.posed_tool_loads())
        tool_log->print("{:.9g},{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{},{:.9g}\n", sim.time(), name,
                        load.force.x(), load.force.y(), load.force.z(), load.friction.x(), load.friction.y(),
                        load.friction.z(), load.contacts, load.penetration);
    };
    if (!opt.tool_log.empty()) {
      tool_log.emplace(opt.tool_log, "--tool-log");
      tool_log->print("t,tool,fx,fy,fz,friction_x,friction_y,friction_z,contacts,penetration\n");
      log_tools();
    }
    ph::cli::ProgressBar bar(!opt.quiet);
    const auto stepping = std::chrono::steady_clock::now();
    const long long n_steps = sim.steps_in(scene.solver.duration);
    const bool explicit_steps = scene.solver.kind == ph::SolverKind::EXPLICIT;
    long long steps_done = 0;
    bool estimated = false;
    // `done`: steps done, a long step's share of its sub-steps included. After a second, a run that will take
    // long says so, with what it costs and what would be faster: within its first step if that is long
    const auto observe = [&](double done) {
      bar.update(done / static_cast<double>(n_steps));
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - stepping).count();
      if (estimated || elapsed <= 1.0 || !(done > 0) || done >= static_cast<double>(n_steps)) return;
      estimated = true;
      const double total = elapsed / done * static_cast<double>(n_steps);
      if (total <= 60) return;
      const double stable = explicit_steps ? sim.stable_dt() : 0.0;
      bar.finish();
      fmt::print(stderr,
                 "pointhaptics: {}: this run will take about {} ({} steps of {:.3g} s at {} each{}){}; Ctrl-C stops it "
                 "and writes the state reached\n",
                 opt.scene, ph::format_duration(total), n_steps, scene.solver.dt, ph::format_duration(elapsed / done),
                 explicit_steps ? fmt::format(", in sub-steps below the stable step {:.3g} s", stable) : std::string(),
                 explicit_steps && scene.solver.dt > 4 * stable
                     ? "; a stiff object: solver.kind = \"implicit\" takes steps of any size"
                     : "");
    };
    progress.within_step = [&](double fraction) { observe(static_cast<double>(steps_done) + fraction); };
    try {
      sim.run(scene.solver.duration, [&](long long step, long long /*n_steps*/) {
        steps_done = step;
        observe(static_cast<double>(step));
        // frames: every vtk_every steps (default: about 50 over the run), and the last state below
        const long long every = opt.vtk_every > 0 ? opt.vtk_every : std::max<long long>(1, n_steps / 50);
        if (vtk && step % every == 0 && step < n_steps)
          errors.attempt([&] { ph::add_vtk_frame(*vtk, sim, vtk_surface(), &body_vtk); });
        if (tool_log) log_tools();
        return !interrupted.load();
      });
    } catch (const ph::Interrupted&) {
      // inside a step: the state is the step's start (Newton), its last sub-step (explicit) or its last
      // converged load increment (static), not a completed step; the summary says so (Simulation::step)
    }
    progress.within_step = nullptr;
    if (tool_log) errors.attempt([&] { tool_log->commit(); });
  }
  // the last state (an interactive run writes only the first and the last)
  if (vtk) errors.attempt([&] { ph::add_vtk_frame(*vtk, sim, vtk_surface(), &body_vtk); });
  if (!opt.csv.empty()) errors.attempt([&] { ph::write_points_csv(opt.csv, sim); });
  if (!opt.surface.empty())
    errors.attempt([&] {
      const ph::ObjectSurface& cut = surface->at(sim.model(), sim.cut_sheets());
      ph::write_mesh(opt.surface, ph::TriangleMesh{ph::deformed_surface(cut, sim.state().u), cut.mesh.F}, "--surface");
    });
  ph::RunSummary summary = sim.summary();
  summary.interrupted = summary.interrupted || interrupted.load() || interactive.interrupted;
  if (haptic) ph::add_interactive_summary(summary, interactive);
  if (!opt.json.empty()) errors.attempt([&] { ph::write_result_json(opt.json, sim.model(), sim.state(), summary); });
  if (!opt.quiet) {
    print_summary(sim, summary, setup_s);
    if (haptic) {
      const ph::HapticStats& h = interactive.haptic;
      fmt::print(
          "haptics         {} ticks at {:.0f} Hz, period error p50 {:.0f} us, p99 {:.0f} us, max {:.0f} us; "
          "longest tick {:.1f} us, spin-wait {:.0f} us on average; max force {:.3g} N; up to {} points in contact; "
          "{} simulation steps\n",
          h.ticks, h.rate_hz, h.period_p50_us, h.period_p99_us, h.period_max_us, h.tick_max_us, h.spin_mean_us,
          h.max_force_n, interactive.max_contacts, interactive.simulation_steps);
      fmt::print(
          "passivity       observed energy at its least {:.3g} J (below 0: the object gave back more than the hand put in); the "
          "controller dissipated {:.3g} J on {} ticks\n",
          h.min_observed_energy, h.passivity_dissipated, h.passivity_ticks);
      const ph::LocalModelSummary& m = interactive.local_model;
      if (m.updates > 0)
        fmt::print(
            "local model     over {} updates in contact (mean force {:.3g} N) it strayed from the next by {:.3g} N on "
            "average, {:.3g} N at most (held force: {:.3g} N; the contact's own stiffness: {:.3g} N)\n",
            m.updates, m.force_mean_n, m.rendered_mean_n, m.rendered_max_n, m.hold_mean_n, m.held_object_mean_n);
      if (options_real_time && interactive.simulation_wall_s > 0) {
        // a real-time run whose simulation could not keep up with the wall clock says by how much
        const double simulated = sim.time() - start_time;
        if (simulated < 0.95 * interactive.simulation_wall_s)
          fmt::print(
              "warning         the simulation fell behind the wall clock: {:.3g} s simulated in {:.3g} s ({:.0f}% of real "
              "time); the hand felt a slower object (fewer points, levels of detail, or the implicit solver)\n",
              simulated, interactive.simulation_wall_s, 100 * simulated / interactive.simulation_wall_s);
      }
      if (h.period_max_us > 1000)
        fmt::print("warning         a haptic period was {:.0f} us off its 1 ms (p99 {:.0f} us): the machine was busy\n",
                   h.period_max_us, h.period_p99_us);
    }
  }
  for (const std::string& message : errors.messages) fmt::print(stderr, "pointhaptics: error: {}\n", message);
  if (summary.interrupted) {
    fmt::print(stderr, "pointhaptics: {}: interrupted at t = {:.6g} s; the outputs hold the state reached\n", opt.scene,
               sim.time());
    return 130;
  }
  if (!errors.messages.empty()) return 1;
  if (haptic && interactive.haptic.device_failed) {
    fmt::print(stderr, "pointhaptics: {}: the device failed: {} (force set to zero, run stopped)\n", opt.scene,
               interactive.haptic.device_error);
    return 1;
  }
  if (!summary.converged) {
    fmt::print(stderr, "pointhaptics: {}: {}\n", opt.scene,
               summary.failure.empty() ? "the solver did not converge" : summary.failure);
    return 1;
  }
  // the exit status is the whole run's, not its last step's (issue 52: a press whose steps were inverted three
  // times in four exited 0 or 1 by the chance of its last step)
  if (summary.inverted_steps > 0) {
    fmt::print(stderr,
               "pointhaptics: {}: {} of {} steps ended with inverted neighbourhoods (det F <= 0): not a physical "
               "result there (a finer spacing, a softer press, or the neo_hookean material)\n",
               opt.scene, summary.inverted_steps, summary.steps);
    return exit_unphysical_steps;
  }
  return 0;
}

}  // namespace

int cli_main(int argc, char** argv) {
  // --threads of every command: 0 (all) to 1024; CLI11's NonNegativeNumber printed its range with 309 digits
  const CLI::Range thread_count(0, 1024);
  CLI::App app{"PointHaptics: point-based deformable objects with haptic rendering", "pointhaptics"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "pointhaptics 0.1.0");

  RunOptions run;
  CLI::App* run_cmd = app.add_subcommand("run", "Simulate a scene file as it says (headless)");
  run_cmd->add_option("scene", run.scene, "Scene file (TOML)")->required();
  run_cmd->add_option("--json", run.json, "Write the result JSON to FILE");
  run_cmd
      ->add_option(
          "--max-memory", run.max_memory,
          "Refuse an object whose model would need more memory than this (e.g. 4GB; default: the memory available)")
      ->transform(CLI::AsSizeValue(false));
  run_cmd->add_flag("--quiet,-q", run.quiet, "Print nothing but errors");
  run_cmd->add_option("--force-log", run.force_log,
                      "With a [probe]: write the haptic log (CSV, one row per tick) to FILE; with several hands, "
                      "each other hand's beside it, named FILE's stem-HAND (force.csv, force-left.csv)");
  run_cmd->add_option("--tool-log", run.tool_log,
                      "With [[tool]] tables held or moved by the scene: write each tool's force at every step (CSV: t, "
                      "tool, fx, fy, fz, friction_x, friction_y, friction_z, contacts, penetration)");
  run_cmd->add_option("--vtk", run.vtk, "Write a ParaView time series (DIR/frame.pvd and DIR/frame_*.vtp)");
  run_cmd->add_option("--csv", run.csv,
                      "Write the final state as CSV, one row per point (x, y, z, u, stress, energy, flags)");
  run_cmd->add_option("--surface", run.surface,
                      "Write the object's deformed surface at the end (FILE.stl, .ply or .obj)");
  run_cmd->add_option("--vtk-every", run.vtk_every, "Steps between VTK frames (default: about 50 frames per run)")
      ->check(CLI::PositiveNumber);
  run_cmd->add_flag("--deterministic", run.deterministic,
                    "With a [probe]: interleave haptic ticks and simulation steps on one thread in simulated time");
  run_cmd->add_option("--threads", run.threads, "Threads for the force evaluation (0: all)")->check(thread_count);
  run_cmd
      ->add_option("--set", run.settings,
                   "Change a key of the scene: KEY=VALUE, a dotted path and a TOML value (material.young=2e5, "
                   "load.0.total=[0,-0.02,0]); repeatable")
      ->allow_extra_args(false);

#ifdef PH_HAVE_VIEWER
  ph::viewer::ViewerOptions view;
  CLI::App* view_cmd =
      app.add_subcommand("view", "Open the interactive viewer (mouse or device probe); --screenshot renders headless");
  view_cmd->add_option("scene", view.scene,
                       "Scene file (TOML); default: the seed's beam held at both ends, with a probe");
  view_cmd->add_option(
      "--screenshot", view.screenshot,
      "Write a PNG and exit: without --run-for, one frame rendered without a window (EGL); with it, the "
      "window's last frame");
  view_cmd
      ->add_option("--time", view.time,
                   "Headless: simulated seconds before the frame (deterministic; the scene's "
                   "scripted probe moves if it has one)")
      ->check(CLI::NonNegativeNumber);
  view_cmd->add_option("--run-for", view.run_for, "Close the window after this many seconds")
      ->check(CLI::PositiveNumber);
  view_cmd->add_option("--info", view.info, "With --screenshot: write the frame's camera, viewport and probe as JSON");
  view_cmd->add_option("--width", view.width, "Window or image width in pixels (default 1280)")
      ->check(CLI::Range(16, 8192));
  view_cmd->add_option("--height", view.height, "Window or image height in pixels (default 800)")
      ->check(CLI::Range(16, 8192));
  view_cmd
      ->add_option("--probe", view.probe,
                   "What drives the probe: auto (a device if present, else the mouse), mouse, "
                   "script (the scene's trajectory), device")
      ->check(CLI::IsMember({"auto", "mouse", "script", "device"}));
  view_cmd->add_option("--tool", view.tool,
                       "The device-driven [[tool]] the mouse (or --probe's source) drives; the scene's other hands "
                       "keep their own devices (default: the first)");
  view_cmd
      ->add_option("--colour", view.colour,
                   "Colour the object by displacement, von Mises stress or level-of-detail band (seed Fig. 6)")
      ->check(CLI::IsMember({"displacement", "von_mises", "band"}));
  view_cmd
      ->add_option("--draw", view.draw,
                   "Draw the object's surface (boxes, spheres, half-spheres, meshes) or its points")
      ->check(CLI::IsMember({"surface", "points"}));
  view_cmd->add_flag(
      "--no-panels", [&view](std::int64_t) { view.panels = false; }, "Only the 3-D view");
  view_cmd->add_option("--frames", view.frames, "Headless: draw this many frames and report the time per frame")
      ->check(CLI::Range(1, 100000));
  view_cmd->add_option("--threads", view.threads, "Threads for the force evaluation (0: all)")->check(thread_count);
#endif

  ph::bench::BenchOptions bench;
  CLI::App* bench_cmd =
      app.add_subcommand("bench", "Run the performance suite (forces and explicit steps) and print a table");
  bench_cmd->add_option("--json", bench.json_path, "Write the results as JSON to FILE");
  bench_cmd->add_option("--filter", bench.filter,
                        "Only benchmarks whose name matches this regex, e.g. 'forces/points:10000'");
  bench_cmd->add_option("--min-time", bench.min_time, "Seconds per benchmark")->check(CLI::PositiveNumber);
  bench_cmd->add_option("--sizes", bench.sizes, "Approximate point counts")->check(CLI::PositiveNumber);
  bench_cmd->add_option("--threads", bench.threads, "Thread counts")->check(CLI::Range(1, 1024));
  bench_cmd
      ->add_option("--repetitions", bench.repetitions,
                   "Run each benchmark N times in random order and report medians (steadier on a shared machine)")
      ->check(CLI::PositiveNumber);

  ph::experiments::CantileverOptions cantilever;
  CLI::App* experiment_cmd =
      app.add_subcommand("experiment", "Reproduce a seed experiment: CSV, markdown summary, PNG plots");
  experiment_cmd->require_subcommand(1);
  CLI::App* cantilever_cmd = experiment_cmd->add_subcommand(
      "cantilever", "Seed Fig. 3-4: the cantilever against CalculiX (ccx) and Timoshenko beam theory");
  cantilever_cmd->add_option("--out", cantilever.out, "Output folder")->required();
  cantilever_cmd->add_flag("--quick", cantilever.quick, "Two spacings, two loads and coarse FEM meshes (seconds)");
  cantilever_cmd->add_option("--threads", cantilever.threads, "Threads for the point model and ccx (0: all)")
      ->check(thread_count);
  cantilever_cmd->add_option("--plot-script", cantilever.plot_script, "plot_cantilever.py to use");

  ph::experiments::MaterialsOptions materials;
  CLI::App* materials_cmd = experiment_cmd->add_subcommand(
      "materials", "Each material model against CalculiX's own: the cantilever and a flat punch's force against depth");
  materials_cmd->add_option("--out", materials.out, "Output folder")->required();
  materials_cmd->add_flag("--quick", materials.quick, "Coarse CalculiX meshes only");
  materials_cmd->add_option("--threads", materials.threads, "Threads for the point model and ccx (0: all)")
      ->check(thread_count);
  materials_cmd->add_option("--plot-script", materials.plot_script, "plot_materials.py to use");
  materials_cmd->add_option("--models", materials.models, "Only these models (svk, neo_hookean, mooney_rivlin)")
      ->delimiter(',');
  materials_cmd
      ->add_option("--punch-meshes", materials.punch_meshes,
                   "CalculiX's punch meshes, elements across the block (even), coarse to fine; the point model is "
                   "compared with the finest (default 10,20,40; --quick: 10)")
      ->delimiter(',')
      ->check(CLI::Range(2, 200));

  ph::experiments::BeamOptions beam;
  CLI::App* beam_cmd = experiment_cmd->add_subcommand(
      "beam-4x1x1", "The 4 x 1 x 1 m benchmark beam: settled sag vs CalculiX, compute s per simulated s");
  beam_cmd->add_option("--out", beam.out, "Output folder")->required();
  beam_cmd->add_option("--scene", beam.scene, "Scene file")->required()->check(CLI::ExistingFile);
  beam_cmd->add_option("--duration", beam.duration, "Simulated seconds of the dynamic runs")
      ->check(CLI::PositiveNumber);
  beam_cmd->add_flag("!--no-implicit", beam.implicit, "Skip the (slow) implicit runs");
  beam_cmd
      ->add_option("--modes", beam.modes,
                   "The point_reduced row's basis size r ([reduction] modes; default 20, 0: no reduced row)")
      ->check(CLI::Range(0, 200));

  ph::experiments::ContactOptions contact;
  CLI::App* contact_cmd = experiment_cmd->add_subcommand(
      "contact",
      "A rigid sphere pressed into a block through the object's surface: force against depth beside Hertz, first "
      "contact, sliding");
  contact_cmd->add_option("--out", contact.out, "Output folder")->required();
  contact_cmd->add_flag("--quick", contact.quick, "The first spacing only, three depths (seconds)");
  contact_cmd->add_option("--spacings", contact.per_radius, "Spacings as R / n: the n (default 4,8)")
      ->delimiter(',')
      ->check(CLI::Range(2, 64));
  contact_cmd->add_option("--threads", contact.threads, "Threads (0: all)")->check(thread_count);
  contact_cmd
      ->add_option("--refine", contact.refine,
                   "The first spacing once more with points at R / n near the contact ([[refine]]; default 8, 0: none)")
      ->check(CLI::Range(0, 64));
  contact_cmd
      ->add_option("--surface-map", contact.surface_map,
                   "The contact's surface map: exact (default) | non_negative ([probe] surface_map)")
      ->check(CLI::IsMember({"exact", "non_negative"}));
  contact_cmd->add_option("--friction", contact.friction, "Coulomb's coefficient of the friction run (default 0.3)")
      ->check(CLI::Range(0.01, 2.0));
  contact_cmd
      ->add_option(
          "--drag-steps", contact.drag_steps,
          "Quasi-static steps per spacing of the friction runs' drag, one run each (default 8,16,32; --quick: the last)")
      ->delimiter(',')
      ->check(CLI::Range(1, 256));
  contact_cmd->add_option("--material", contact.material,
                          "The block's material: neo_hookean (default), svk or mooney_rivlin");
  contact_cmd
      ->add_option("--fem-meshes", contact.fem_per_radius,
                   "CalculiX's element sizes at the contact as R / n, the last the reference (default 10,20,40)")
      ->delimiter(',')
      ->check(CLI::Range(2, 200));
  contact_cmd->add_option("--plot-script", contact.plot_script, "plot_contact.py to use");

  ph::experiments::CutOptions cut_experiment;
  CLI::App* cut_cmd = experiment_cmd->add_subcommand(
      "cut",
      "Cutting: a device's blade cuts the cantilever through near its root, a scripted one cuts a slit that opens under load");
  cut_cmd->add_option("--out", cut_experiment.out, "Output folder")->required();
  cut_cmd->add_option("--threads", cut_experiment.threads, "Threads (0: all)")->check(thread_count);

  ph::experiments::ReductionOptions reduction_experiment;
  CLI::App* reduction_cmd = experiment_cmd->add_subcommand(
      "reduction",
      "The reduced model against the full point model and CalculiX NLGEOM on two cantilevers: static tip "
      "displacement up to 20% of the length, a sudden load's history and the first natural frequency, against the "
      "number of modes");
  reduction_cmd->add_option("--out", reduction_experiment.out, "Output folder")->required();
  reduction_cmd->add_flag("--quick", reduction_experiment.quick,
                          "A coarser check beam, two loads, r = 6, 12, 20 and one CalculiX mesh (about a minute)");
  reduction_cmd->add_option("--modes", reduction_experiment.modes, "The basis sizes r (default 6,10,15,20,30,40)")
      ->delimiter(',')
      ->check(CLI::Range(1, 200));
  reduction_cmd
      ->add_option("--checked-modes", reduction_experiment.checked_modes,
                   "The r checked against the goals: 2% static and dynamic, 1% frequency (default 20)")
      ->check(CLI::Range(1, 200));
  reduction_cmd->add_option("--threads", reduction_experiment.threads, "Threads (0: all)")->check(thread_count);
  reduction_cmd->add_option("--plot-script", reduction_experiment.plot_script, "plot_reduction.py to use");

  ph::experiments::ContactPairsOptions pairs;
  CLI::App* pairs_cmd = experiment_cmd->add_subcommand(
      "contact-pairs",
      "Contact pairs against statics: a block on a table, a block on a block, two tools pinching a sample (slipping "
      "below W / 2N), two jaws lifting it, a cut piece falling onto a table");
  pairs_cmd->add_option("--out", pairs.out, "Output folder")->required();
  pairs_cmd->add_option("--threads", pairs.threads, "Threads (0: all)")->check(thread_count);
  pairs_cmd->add_option("--plot-script", pairs.plot_script, "plot_contact_pairs.py to use");

  ph::experiments::ForceProfileOptions profile;
  CLI::App* profile_cmd = experiment_cmd->add_subcommand(
      "force-profile", "Seed Fig. 2c: the force felt while dragging a point of the beam and letting it go");
  profile_cmd->add_option("--out", profile.out, "Output folder")->required();
  profile_cmd->add_flag("--real-time", profile.real_time,
                        "Run the haptic thread on the wall clock (default: simulated time)");

  ph::experiments::LodExperimentOptions lod_table, propagation, lod_error;
  auto lod_options = [&thread_count](CLI::App* cmd, ph::experiments::LodExperimentOptions& o) {
    cmd->add_option("--out", o.out, "Output folder")->required();
    cmd->add_flag("--quick", o.quick, "Small objects and short runs (seconds)");
    cmd->add_option("--threads", o.threads, "Threads (0: all)")->check(thread_count);
    cmd->add_option("--seconds", o.seconds, "Wall seconds per timed configuration")->check(CLI::PositiveNumber);
  };
  CLI::App* lod_table_cmd = experiment_cmd->add_subcommand(
      "lod-table", "Seed Table 1: steps per second with levels of detail, 224 to 100k points, against the full model");
  lod_options(lod_table_cmd, lod_table);
  CLI::App* propagation_cmd = experiment_cmd->add_subcommand(
      "propagation", "Seed Fig. 8-9: a constant pull at point 111, one propagation level at weight 0.4 and 0.2");
  lod_options(propagation_cmd, propagation);
  CLI::App* lod_error_cmd = experiment_cmd->add_subcommand(
      "lod-error", "Displacement error against speed-up: the seed's random selection and the dithered one");
  lod_options(lod_error_cmd, lod_error);
  lod_error_cmd->add_option("--points", lod_error.points, "Points in the half-sphere (default 10000; --quick 1200)")
      ->check(CLI::Range(100, 2000000));
  lod_error_cmd->add_option("--load", lod_error.load, "pull: 0.01 N at the pole | indent: the pole pushed 1 mm in")
      ->check(CLI::IsMember({"pull", "indent"}));
  lod_error_cmd->add_option(
      "--config", lod_error.levels,
      "One configuration instead of the sweep, both schemes: \"k1,k2[,min_neighbours];P1:K1;P2:K2\" "
      "(units of h; P = 0: the whole object)");

  // studies and fits: Python's argparse reads their options (`pointhaptics study --help`)
  CLI::App* study_cmd = app.add_subcommand(
      "study",
      "Run a parameter study on Dask: study.toml --out DIR [--scheduler tcp://HOST:PORT] [--workers N] (docs/studies.md)");
  CLI::App* fit_cmd = app.add_subcommand(
      "fit",
      "Fit material parameters to a measured indentation curve: measured.csv --scene S --params K1,K2 --out DIR (docs/studies.md)");
  for (CLI::App* cmd : {study_cmd, fit_cmd}) {
    cmd->set_help_flag();
    cmd->prefix_command();
  }

  CLI11_PARSE(app, argc, argv);
  if (*study_cmd) return ph::cli::run_python_module("pointhaptics.studies", study_cmd->remaining());
  if (*fit_cmd) return ph::cli::run_python_module("pointhaptics.identification", fit_cmd->remaining());
  try {
    if (*run_cmd) return run_command(run);
#ifdef PH_HAVE_VIEWER
    if (*view_cmd) {
      if (!view.info.empty() && view.screenshot.empty()) throw ph::Error("view: --info needs --screenshot");
      return view.screenshot.empty() || view.run_for > 0 ? ph::viewer::run_window(view)
                                                         : ph::viewer::render_screenshot(view);
    }
#endif
    if (*bench_cmd) return ph::bench::run_bench_suite(bench);
    if (*cantilever_cmd) return ph::experiments::run_cantilever_experiment(cantilever);
    if (*materials_cmd) return ph::experiments::run_materials_experiment(materials);
    if (*beam_cmd) return ph::experiments::run_beam_experiment(beam);
    if (*contact_cmd) return ph::experiments::run_contact_experiment(contact);
    if (*profile_cmd) return ph::experiments::run_force_profile_experiment(profile);
    if (*cut_cmd) return ph::experiments::run_cut_experiment(cut_experiment);
    if (*pairs_cmd) return ph::experiments::run_contact_pairs_experiment(pairs);
    if (*reduction_cmd) return ph::experiments::run_reduction_experiment(reduction_experiment);
    if (*lod_table_cmd) return ph::experiments::run_lod_table_experiment(lod_table);
    if (*propagation_cmd) return ph::experiments::run_propagation_experiment(propagation);
    if (*lod_error_cmd) return ph::experiments::run_lod_error_experiment(lod_error);
  } catch (const ph::Error& e) {
    std::fprintf(stderr, "pointhaptics: error: %s\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(
        stderr,
        "pointhaptics: error: out of memory: this run needs more memory than the machine could give (a coarser "
        "spacing, fewer points or --max-memory to refuse such runs before they start)\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pointhaptics: internal error: %s\n", e.what());
    return 2;
  }
  return 0;
}

int main(int argc, char** argv) {
  const int status = cli_main(argc, argv);
  // a stopped run may leave a library call (CHOLMOD's factorisation) ending on a thread of its own
  // (core/stoppable_call.hpp): the outputs are written and closed by now, and the process leaves without running
  // static destructors (the BLAS's buffers) under it
  if (ph::abandoned_work_running() > 0) {
    std::fflush(nullptr);
    std::_Exit(status);
  }
  return status;
}
