#include <pointhaptics/interactive.hpp>

#include <pointhaptics/core/run_control.hpp>
#include <pointhaptics/io/haptic_log.hpp>
#include <pointhaptics/haptics/local_model_stray.hpp>

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

namespace pointhaptics {
namespace {

// What a viewer shows of the step just made.
void publish_display(Simulation& sim, const HapticFrame& haptic, long long step, TripleBuffer<DisplayFrame>& display) {
  const ProbeTool& probe = *sim.probe();
  DisplayFrame& d = display.back();
  d.time = sim.time();
  d.step = step;
  d.u = sim.state().u;  // same size every time: no allocation
  d.probe = probe.probe();
  d.device = haptic.device;
  d.force = haptic.force;
  d.haptic_ticks = haptic.tick;
  d.contacts = probe.contact_model().contacts;
  const ActiveSet* active = sim.active_set();
  d.simulated = active ? active->n_selected : sim.simulated_model().n_points;
  sim.grabbed_points(d.grabbed);
  if (active && d.lod_selections != sim.lod_selections()) {  // a new active set (rare): each slot catches up once
    const Selection& selection = *sim.lod_selection();
    d.lod_band.assign(sim.model().n_points, -1);
    for (const index_t i : selection.selected) d.lod_band[i] = selection.band[i];
    d.lod_selections = sim.lod_selections();
  }
  if (d.cut_revision != sim.cut_sheets().revision) {  // after a cut (each slot catches up once)
    d.cut_sheets = sim.cut_sheets().triangles;
    d.cut_revision = sim.cut_sheets().revision;
  }
  display.publish();
}

// One simulation step with the latest device point; then the local contact model is published for the
// haptic loop (run_interactive publishes the display frames, at most one per display_period).
// `stray` compares each model with the one before.
int simulation_step(Simulation& sim, HapticLoop& loop, LocalModelStray& stray) {
  loop.frames().update();
  const HapticFrame& frame = loop.frames().front();
  sim.inputs().device = frame.device;
  sim.inputs().button = frame.button;
  sim.inputs().orientation = frame.orientation;
  sim.step();
  const ProbeTool& probe = *sim.probe();
  loop.contact_models().back() = probe.contact_model();
  loop.contact_models().publish();
  stray.add(probe.contact_model(), probe.held_stiffness());
  return probe.contact_model().contacts;
}

}  // namespace

InteractiveResult run_interactive(Simulation& sim, Device& device, const InteractiveOptions& options) {
  if (!(options.duration >= 0) || !(options.haptic_rate > 0))
    throw Error("interactive run: bad duration or haptic rate");
  if (sim.solver().kind == SolverKind::STATIC)
    throw Error("interactive run: needs a dynamic solver (explicit or implicit)");
  if (options.display && options.display->back().u.cols() != sim.model().n_points)
    throw Error("interactive run: the display frames must be sized for the model's points (3 x n)");
  const CouplingGains gains = coupling_budget(device.specs(), options.mapping.scale, options.coupling_safety);
  // in real time levels of detail are built on a worker thread and taken over at the first step after they
  // are ready; in deterministic runs in place, so that a run is reproducible
  sim.attach_probe(options.probe, gains.stiffness, device.specs().max_force, options.real_time, options.surface);
  struct Detach {  // the probe belongs to this run
    Simulation& sim;
    ~Detach() { sim.detach_probe(); }
  } detach{sim};
  const bool streamed = static_cast<bool>(options.log_sink);
  if (options.log && !streamed && !std::isfinite(options.duration))
    throw Error("interactive run: a force log kept in memory needs a finite duration (stream it to a file)");
  // the loop holds a few seconds of rows; this thread takes them after every step
  HapticLoop loop(device, options.mapping, gains, options.rules, options.haptic_rate,
                  options.log || streamed ? static_cast<std::size_t>(4 * options.haptic_rate) + 64 : 0);
  InteractiveResult result;
  LocalModelStray stray;
  const auto take_log = [&] {
    if (streamed) loop.take_log(options.log_sink);
    else if (options.log) loop.take_log([&](const HapticLogRow& row) { result.log.push_back(row); });
  };
  const auto stopped = [&options] {
    return stop_requested() || (options.stop && options.stop->load(std::memory_order_acquire));
  };
  const auto start = std::chrono::steady_clock::now();
  const double t0 = sim.time();
  // display frames: at most one per display_period (of wall time in real time, else of simulated time),
  // and the last step's
  double last_display = -std::numeric_limits<double>::infinity();
  long long last_display_step = -1;
  const auto display = [&](bool last) {
    if (!options.display || result.simulation_steps == 0 || last_display_step == result.simulation_steps) return;
    const double t = options.real_time ? std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
                                       : sim.time();
    if (!last && t - last_display < options.display_period) return;
    last_display = t;
    last_display_step = result.simulation_steps;
    publish_display(sim, loop.frames().front(), result.simulation_steps - 1, *options.display);
  };
  // a stop requested inside a step ends the run there (the state is that of the step's start, or of its last
  // explicit sub-step); the haptic loop is stopped either way
  try {
    if (options.real_time) {
      loop.start();
      for (;;) {
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (wall >= options.duration || loop.device_failed() || stopped() || sim.diagnostics().failed) break;
        if (sim.time() - t0 > wall) {  // ahead of the wall clock: wait for it
          std::this_thread::sleep_for(std::chrono::duration<double>(sim.time() - t0 - wall));
          continue;
        }
        result.max_contacts = std::max(result.max_contacts, simulation_step(sim, loop, stray));
        ++result.simulation_steps;
        display(false);
        take_log();
        if (options.after_step) options.after_step(result.simulation_steps);
      }
      loop.stop();
    } else {
      const double h = 1.0 / options.haptic_rate;
      if (!(options.duration >= 0) || !(options.duration * options.haptic_rate <= Simulation::max_run_steps))
        throw Error(
            fmt::format("interactive run: a deterministic run needs a finite duration of at most {:.3g} s (not "
                        "{:.6g} s)",
                        Simulation::max_run_steps / options.haptic_rate, options.duration));
      const auto n_ticks = static_cast<long long>(std::llround(options.duration * options.haptic_rate));
      for (long long k = 1; k <= n_ticks && !stopped() && !sim.diagnostics().failed; ++k) {
        const double t = k * h;
        if (!loop.tick(t, h)) break;
        take_log();
        while (sim.time() - t0 < t - 1e-12 && !sim.diagnostics().failed) {
          result.max_contacts = std::max(result.max_contacts, simulation_step(sim, loop, stray));
          ++result.simulation_steps;
          display(false);
          if (options.after_step) options.after_step(result.simulation_steps);
        }
      }
    }
  } catch (const Interrupted&) {
    loop.stop();
  }
  result.interrupted = stopped();
  display(true);
  result.simulation_wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.haptic = loop.stats();
  take_log();
  result.log_dropped = loop.log_dropped();
  result.tool = sim.tool_summary();  // before the probe is detached
  result.local_model = stray.summary();
  return result;
}

void add_interactive_summary(RunSummary& summary, const InteractiveResult& interactive) {
  summary.tool = interactive.tool;
  summary.haptic_ticks = interactive.haptic.ticks;
  summary.haptic_rate_hz = interactive.haptic.rate_hz;
  summary.haptic_period_p99_us = interactive.haptic.period_p99_us;
  summary.haptic_max_force_n = interactive.haptic.max_force_n;
  summary.haptic_min_observed_energy = interactive.haptic.min_observed_energy;
  summary.haptic_passivity_dissipated = interactive.haptic.passivity_dissipated;
  summary.haptic_passivity_ticks = interactive.haptic.passivity_ticks;
  summary.local_model = interactive.local_model;
}

}  // namespace pointhaptics
