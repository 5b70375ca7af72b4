#include <pointhaptics/interactive.hpp>

#include <pointhaptics/haptics/devices/openhaptics_device.hpp>
#include <pointhaptics/haptics/devices/replay_device.hpp>
#include <pointhaptics/haptics/devices/virtual_device.hpp>
#include <pointhaptics/haptics/haptic_log.hpp>

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

namespace pointhaptics {
namespace {

// The probe's contact as forces on the points, evaluated at every explicit sub-step with the probe of
// the step; remembers the last local contact model.
class ContactForces : public DynamicForces {
 public:
  ContactForces(const Model& model, const ProbeParams& params, double coupling_stiffness, double max_force)
      : contact(model, params), k(coupling_stiffness), max_force(max_force), scratch(Points::Zero(3, model.n_points)) {}

  // Once per step: the probe is where the coupling spring (toward the device point, its force capped at
  // the device's maximum: the hand cannot push harder than it can feel) balances the contact forces at
  // the step's start; a few Newton steps on the local model from the last position. Within the step the
  // probe stays there (re-solving it at every sub-step let the contact set chatter and excite the lattice).
  void solve_probe(const Model& model, const State& state) {
    if (!device.allFinite()) {
      probe = device;
      return;
    }
    Vec3 p = probe.allFinite() ? probe : device;
    for (int it = 0; it < 8; ++it) {
      scratch.setZero();
      // the state is the same at every iteration: the positions and their grid are made once
      const ContactModel m = contact.apply(model, state.u, p, button, state.time, scratch, it > 0);
      Vec3 d = device;
      const auto solver = (k * Mat3::Identity() - m.K).ldlt();
      Vec3 next = solver.solve(k * d + m.f0 - m.K * p);
      const double pull = k * (d - next).norm();
      if (pull > max_force && next.allFinite()) {
        d = next + (d - next) * (max_force / pull);
        next = solver.solve(k * d + m.f0 - m.K * p);
      }
      if (!next.allFinite()) break;
      const bool settled = (next - p).norm() < 1e-9 + 1e-6 * contact.params().radius;
      p = next;
      if (settled) break;
    }
    probe = p;
  }
  void add(const Model& model, const State& state, Points& f) override {
    last = contact.apply(model, state.u, probe, button, state.time, f);
  }
  // levels of detail re-selected: the simulated points were renumbered
  void remap(const Model& model, const std::vector<index_t>& new_index) {
    contact.remap(model, new_index);
    scratch = Points::Zero(3, model.n_points);
  }
  double max_point_stiffness() const override { return contact.params().stiffness; }
  bool add_stiffness(const Model&, const State&, Eigen::Matrix<double, 9, Eigen::Dynamic>& springs) override {
    contact.add_stiffness(springs);
    return last.contacts > 0;
  }
  ProbeContact contact;
  double k, max_force;
  Vec3 device = Vec3::Constant(NAN);  ///< the device point of the latest haptic frame
  Vec3 probe = Vec3::Constant(NAN);   ///< the probe as the simulation solved it last
  bool button = false;
  ContactModel last;
  Points scratch;
};

// What a viewer shows of the step just made.
void publish_display(Simulation& sim, const ContactForces& contact, const HapticFrame& haptic, long long step,
                     TripleBuffer<DisplayFrame>& display) {
  DisplayFrame& d = display.back();
  d.time = sim.state().time;
  d.step = step;
  d.u = sim.full_state().u;  // same size every time: no allocation
  d.probe = contact.probe;
  d.device = haptic.device;
  d.force = haptic.force;
  d.haptic_ticks = haptic.tick;
  d.contacts = contact.last.contacts;
  const ActiveSet* active = sim.active_set();
  d.simulated = active ? active->n_selected : sim.model().n_points;
  d.grabbed.clear();
  for (const index_t i : contact.contact.grabbed()) d.grabbed.push_back(active ? active->full_of[i] : i);
  if (active && d.lod_selections != sim.lod_selections()) {  // a new active set (rare): each slot catches up once
    const Selection& selection = *sim.lod_selection();
    d.lod_band.assign(sim.full_model().n_points, -1);
    for (const index_t i : selection.selected) d.lod_band[i] = selection.band[i];
    d.lod_selections = sim.lod_selections();
  }
  display.publish();
}

// One simulation step with the latest probe; then the local model is published (run_interactive publishes
// the display frames, at most one per display_period).
int simulation_step(Simulation& sim, ContactForces& contact, HapticLoop& loop, bool real_time) {
  loop.frames().update();
  const HapticFrame& frame = loop.frames().front();
  contact.device = frame.device;
  contact.button = frame.button;
  contact.solve_probe(sim.model(), sim.state());
  const int contacts_before = contact.last.contacts;
  sim.step();
  loop.contact_models().back() = contact.last;
  loop.contact_models().publish();
  if (sim.lod_enabled()) {
    // levels of detail follow the contact point: at contact onset and when it moved far enough; on this
    // thread, while the haptic thread keeps rendering the local model just published
    const bool onset = contacts_before == 0 && contact.last.contacts > 0;
    // in real time built on a worker thread and taken over at the first step after it is ready; in
    // deterministic runs built here, so that a run is reproducible
    const std::vector<index_t> new_index =
        sim.update_lod(sim.lod_contact_of_probe(contact.probe, contact.contact.grabbed(), contact.contact.touched()), onset,
                       real_time);
    if (!new_index.empty()) contact.remap(sim.model(), new_index);
  }
  return contact.last.contacts;
}

}  // namespace

namespace {

DeviceSpecs scene_device_specs(const DeviceSpec& d) {
  if (d.specs != "custom") return known_device_specs(d.specs);
  return {"custom", d.max_force, d.max_stiffness, d.max_damping, d.workspace_radius};
}

}  // namespace

std::unique_ptr<Device> make_scene_device(const Scene& scene) {
  const DeviceSpecs specs = scene_device_specs(scene.device);
  if (scene.device.kind == "replay") return std::make_unique<ReplayDevice>(read_haptic_log(scene.device.log), specs);
  if (scene.device.kind == "openhaptics") return std::make_unique<OpenHapticsDevice>(scene.device.library);  // its own specs
  if (scene.device.kind != "virtual") throw Error(fmt::format("{}: device.kind = \"{}\" is not available", scene.path, scene.device.kind));
  if (!scene.probe.trajectory.empty()) return std::make_unique<VirtualDevice>(Trajectory::from_csv(scene.probe.trajectory), specs);
  std::vector<Keyframe> frames;
  for (const auto& k : scene.probe.keyframes) frames.push_back({k[0], Vec3(k[1], k[2], k[3]), k[4] != 0});
  try {
    return std::make_unique<VirtualDevice>(Trajectory(std::move(frames)), specs);
  } catch (const Error& e) {
    throw Error(fmt::format("{}:{}: probe.keyframes: {}", scene.path, scene.probe.line, e.what()));
  }
}

InteractiveOptions scene_interactive_options(const Scene& scene, const Model& model) {
  InteractiveOptions o;
  o.probe.radius = scene.probe.radius;
  o.probe.mode = scene.probe.grab ? ProbeMode::GRAB : ProbeMode::PUSH;
  o.probe.stiffness = scene.probe.stiffness;
  o.mapping.scale = scene.probe.scale;
  if (scene.probe.origin.allFinite()) {
    o.mapping.origin = scene.probe.origin;
  } else {
    const Vec3 lo = model.X.rowwise().minCoeff(), hi = model.X.rowwise().maxCoeff();
    o.mapping.origin = Vec3(0.5 * (lo.x() + hi.x()), hi.y() + 2 * scene.probe.radius, 0.5 * (lo.z() + hi.z()));
  }
  o.duration = scene.solver.duration;
  return o;
}

InteractiveResult run_interactive(Simulation& sim, Device& device, const InteractiveOptions& options) {
  if (!(options.duration >= 0) || !(options.haptic_rate > 0)) throw Error("interactive run: bad duration or haptic rate");
  if (sim.solver().kind == SolverKind::STATIC) throw Error("interactive run: needs a dynamic solver (explicit or implicit)");
  if (options.display && options.display->back().u.cols() != sim.full_model().n_points)
    throw Error("interactive run: the display frames must be sized for the model's points (3 x n)");
  const CouplingGains gains = coupling_budget(device.specs(), options.mapping.scale, options.coupling_safety);
  ContactForces contact(sim.model(), options.probe, gains.stiffness, device.specs().max_force);
  sim.set_dynamic_forces(&contact);
  struct Detach {  // the simulation must not keep a pointer to `contact` if a step throws
    Simulation& sim;
    ~Detach() { sim.set_dynamic_forces(nullptr); }
  } detach{sim};
  const bool streamed = static_cast<bool>(options.log_sink);
  if (options.log && !streamed && !std::isfinite(options.duration))
    throw Error("interactive run: a force log kept in memory needs a finite duration (stream it to a file)");
  // the loop holds a few seconds of rows; this thread takes them after every step
  HapticLoop loop(device, options.mapping, gains, options.rules, options.haptic_rate,
                  options.log || streamed ? static_cast<std::size_t>(4 * options.haptic_rate) + 64 : 0);
  InteractiveResult result;
  const auto take_log = [&] {
    if (streamed) loop.take_log(options.log_sink);
    else if (options.log) loop.take_log([&](const HapticLogRow& row) { result.log.push_back(row); });
  };
  const auto stopped = [&options] { return options.stop && options.stop->load(std::memory_order_acquire); };
  const auto start = std::chrono::steady_clock::now();
  const double t0 = sim.state().time;
  // display frames: at most one per display_period (of wall time in real time, else of simulated time),
  // and the last step's
  double last_display = -std::numeric_limits<double>::infinity();
  long long last_display_step = -1;
  const auto display = [&](bool last) {
    if (!options.display || result.simulation_steps == 0 || last_display_step == result.simulation_steps) return;
    const double t = options.real_time ? std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
                                       : sim.state().time;
    if (!last && t - last_display < options.display_period) return;
    last_display = t;
    last_display_step = result.simulation_steps;
    publish_display(sim, contact, loop.frames().front(), result.simulation_steps - 1, *options.display);
  };
  if (options.real_time) {
    loop.start();
    for (;;) {
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (wall >= options.duration || loop.device_failed() || stopped()) break;
      if (sim.state().time - t0 > wall) {  // ahead of the wall clock: wait for it
        std::this_thread::sleep_for(std::chrono::duration<double>(sim.state().time - t0 - wall));
        continue;
      }
      result.max_contacts = std::max(result.max_contacts, simulation_step(sim, contact, loop, options.real_time));
      ++result.simulation_steps;
      display(false);
      take_log();
      if (options.after_step) options.after_step(result.simulation_steps);
    }
    loop.stop();
  } else {
    const double h = 1.0 / options.haptic_rate;
    if (!std::isfinite(options.duration)) throw Error("interactive run: a deterministic run needs a finite duration");
    const auto n_ticks = static_cast<long long>(std::llround(options.duration * options.haptic_rate));
    for (long long k = 1; k <= n_ticks && !stopped(); ++k) {
      const double t = k * h;
      if (!loop.tick(t, h)) break;
      take_log();
      while (sim.state().time - t0 < t - 1e-12) {
        result.max_contacts =
            std::max(result.max_contacts, simulation_step(sim, contact, loop, options.real_time));
        ++result.simulation_steps;
        display(false);
        if (options.after_step) options.after_step(result.simulation_steps);
      }
    }
  }
  display(true);
  result.simulation_wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.haptic = loop.stats();
  take_log();
  result.log_dropped = loop.log_dropped();
  return result;
}

}  // namespace pointhaptics
