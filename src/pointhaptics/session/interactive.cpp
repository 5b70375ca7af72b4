#include <pointhaptics/session/interactive.hpp>

#include <pointhaptics/core/run_control.hpp>
#include <pointhaptics/io/haptic_log.hpp>
#include <pointhaptics/haptics/local_model_stray.hpp>

#include <fmt/format.h>

#include <algorithm>
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
  d.rigid.clear();  // the same shapes every frame: no allocation once each slot has held them
  for (std::size_t k = 1; k < sim.hands(); ++k) {
    const ProbeTool& hand = *sim.probe(k);
    const SurfaceContact* on_surface = hand.surface_contact();
    d.rigid.push_back(
        {on_surface ? on_surface->shape() : probe_shape(hand.contact().params()),
         ToolPose{hand.probe(), on_surface ? on_surface->pose().orientation : Eigen::Quaterniond::Identity()}, true});
  }
  for (const PosedBody& body : sim.posed_bodies())
    d.rigid.push_back({body.contact.shape(), body.contact.pose(), false});
  if (d.cut_revision != sim.cut_sheets().revision) {  // after a cut (each slot catches up once)
    d.cut_sheets = sim.cut_sheets().triangles;
    d.cut_revision = sim.cut_sheets().revision;
  }
  display.publish();
}

// A hand of the run: its device's haptic loop, and how far its local models strayed.
struct RunningHand {
  std::unique_ptr<HapticLoop> loop;
  LocalModelStray stray;
  int max_contacts = 0;
};

// One simulation step with each hand's latest device point; then each hand's local contact model is published for
// its haptic loop (run_interactive publishes the display frames, at most one per display_period). `stray` compares
// each model with the one before.
void simulation_step(Simulation& sim, std::vector<RunningHand>& hands) {
  for (std::size_t k = 0; k < hands.size(); ++k) {
    TripleBuffer<HapticFrame>& frames = hands[k].loop->frames();
    frames.update();
    const HapticFrame& frame = frames.front();
    StepInputs& inputs = sim.inputs(k);
    inputs.device = frame.device;
    inputs.button = frame.button;
    inputs.orientation = frame.orientation;
  }
  sim.step();
  for (std::size_t k = 0; k < hands.size(); ++k) {
    const ProbeTool& probe = *sim.probe(k);
    RunningHand& hand = hands[k];
    hand.loop->contact_models().back() = probe.contact_model();
    hand.loop->contact_models().publish();
    hand.stray.add(probe.contact_model(), probe.held_stiffness());
    hand.max_contacts = std::max(hand.max_contacts, probe.contact_model().contacts);
  }
}

}  // namespace

InteractiveResult run_interactive(Simulation& sim, Device& device, const InteractiveOptions& options) {
  if (!(options.duration >= 0) || !(options.haptic_rate > 0))
    throw Error("interactive run: bad duration or haptic rate");
  if (sim.solver().kind == SolverKind::STATIC)
    throw Error("interactive run: needs a dynamic solver (explicit or implicit)");
  if (options.display && options.display->back().u.cols() != sim.model().n_points)
    throw Error("interactive run: the display frames must be sized for the model's points (3 x n)");
  if (!options.other_hands.empty() && sim.lod_enabled())
    throw Error("interactive run: a second hand with levels of detail is not supported yet");
  for (const HandOptions& h : options.other_hands)
    if (!h.device) throw Error(fmt::format("interactive run: hand \"{}\" has no device", h.name));
  const bool streamed = static_cast<bool>(options.log_sink);
  if (options.log && !streamed && !std::isfinite(options.duration))
    throw Error("interactive run: a force log kept in memory needs a finite duration (stream it to a file)");
  // each hand's probe, and its haptic loop (the first keeps the force log: a few seconds of rows, which this
  // thread takes after every step). In real time levels of detail are built on a worker thread and taken over at
  // the first step after they are ready; in deterministic runs in place, so that a run is reproducible
  struct Detach {  // the probes belong to this run
    Simulation& sim;
    ~Detach() { sim.detach_probe(); }
  } detach{sim};
  std::vector<RunningHand> hands(1 + options.other_hands.size());
  const auto attach = [&](std::size_t k, Device& device, const ProbeParams& probe,
                          std::shared_ptr<const ObjectSurface> surface, const WorkspaceMapping& mapping,
                          const std::string& name) {
    const CouplingGains gains = coupling_budget(device.specs(), mapping.scale, options.coupling_safety);
    sim.attach_probe(probe, gains.stiffness, device.specs().max_force, options.real_time, std::move(surface), name);
    const bool logged = k == 0 ? options.log || streamed : static_cast<bool>(options.other_hands[k - 1].log_sink);
    const std::size_t log_rows = logged ? static_cast<std::size_t>(4 * options.haptic_rate) + 64 : 0;
    hands[k].loop = std::make_unique<HapticLoop>(device, mapping, gains, options.rules, options.haptic_rate, log_rows);
  };
  attach(0, device, options.probe, options.surface, options.mapping, {});
  for (std::size_t k = 0; k < options.other_hands.size(); ++k) {
    const HandOptions& h = options.other_hands[k];
    attach(k + 1, *h.device, h.probe, h.surface, h.mapping, h.name);
  }
  HapticLoop& loop = *hands.front().loop;
  InteractiveResult result;
  const auto take_log = [&] {
    if (streamed) loop.take_log(options.log_sink);
    else if (options.log) loop.take_log([&](const HapticLogRow& row) { result.log.push_back(row); });
    for (std::size_t k = 1; k < hands.size(); ++k)
      if (options.other_hands[k - 1].log_sink) hands[k].loop->take_log(options.other_hands[k - 1].log_sink);
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
  const auto device_failed = [&hands] {
    return std::any_of(hands.begin(), hands.end(), [](const RunningHand& h) { return h.loop->device_failed(); });
  };
  const auto stop_loops = [&hands] {
    for (RunningHand& h : hands) h.loop->stop();
  };
  try {
    if (options.real_time) {
      for (RunningHand& h : hands) h.loop->start();
      for (;;) {
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (wall >= options.duration || device_failed() || stopped() || sim.diagnostics().failed) break;
        if (sim.time() - t0 > wall) {  // ahead of the wall clock: wait for it
          std::this_thread::sleep_for(std::chrono::duration<double>(sim.time() - t0 - wall));
          continue;
        }
        simulation_step(sim, hands);
        ++result.simulation_steps;
        display(false);
        take_log();
        if (options.after_step) options.after_step(result.simulation_steps);
      }
      stop_loops();
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
        // every hand's tick at t (a hand whose device failed ends the run)
        if (!std::all_of(hands.begin(), hands.end(), [&](RunningHand& hand) { return hand.loop->tick(t, h); })) break;
        take_log();
        while (sim.time() - t0 < t - 1e-12 && !sim.diagnostics().failed) {
          simulation_step(sim, hands);
          ++result.simulation_steps;
          display(false);
          if (options.after_step) options.after_step(result.simulation_steps);
        }
      }
    }
  } catch (const Interrupted&) {
    stop_loops();
  }
  result.interrupted = stopped();
  display(true);
  result.simulation_wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.haptic = loop.stats();
  take_log();
  result.log_dropped = loop.log_dropped();
  // before the probes are detached
  result.max_contacts = hands.front().max_contacts;
  // each hand's tool block with its own loop's figures
  const auto with_haptics = [](ToolSummary tool, const HapticStats& haptic) {
    tool.haptic_ticks = haptic.ticks;
    tool.haptic_period_p99_us = haptic.period_p99_us;
    tool.haptic_max_force_n = haptic.max_force_n;
    return tool;
  };
  result.tool = with_haptics(sim.tool_summary(), result.haptic);
  result.local_model = hands.front().stray.summary();
  for (std::size_t k = 1; k < hands.size(); ++k) {
    const HapticStats haptic = hands[k].loop->stats();
    result.other_hands.push_back({sim.hand_name(k), haptic, with_haptics(sim.tool_summary(k), haptic),
                                  hands[k].max_contacts, hands[k].stray.summary(), hands[k].loop->log_dropped()});
  }
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
  for (const HandResult& hand : interactive.other_hands) {
    const auto same = [&](const auto& named) { return named.first == hand.name; };
    const auto it = std::find_if(summary.tools.begin(), summary.tools.end(), same);
    if (it != summary.tools.end()) it->second = hand.tool;
    else summary.tools.emplace_back(hand.name, hand.tool);
  }
}

}  // namespace pointhaptics
