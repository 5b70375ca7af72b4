#include "viewer_session.hpp"

#include <pointhaptics/haptics/devices/openhaptics_device.hpp>
#include <pointhaptics/session/scene_session.hpp>

#include <fmt/format.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <limits>

namespace pointhaptics::viewer {

ProbeSource probe_source_of(const std::string& name) {
  if (name == "auto") return ProbeSource::AUTO;
  if (name == "mouse") return ProbeSource::MOUSE;
  if (name == "script") return ProbeSource::SCRIPT;
  if (name == "device") return ProbeSource::DEVICE;
  throw Error(fmt::format("--probe {}: expected auto, mouse, script or device", name));
}

namespace {

std::unique_ptr<Device> make_device(const Scene& scene, ProbeSource source, const DeviceSpecs& mouse_specs,
                                    MouseDevice*& mouse, std::string& name) {
  if (source == ProbeSource::SCRIPT) {
    if (scene.probe.keyframes.empty() && scene.probe.trajectory.empty() && scene.device.kind != "replay")
      throw Error(
          fmt::format("{}: --probe script needs [probe] keyframes or a trajectory, or a replay device", scene.path));
    name = scene.device.kind == "replay" ? "replay of " + scene.device.log : "scripted hand";
    return make_scene_device(scene);
  }
  if (source == ProbeSource::AUTO || source == ProbeSource::DEVICE) {
    try {
      auto device = std::make_unique<OpenHapticsDevice>(scene.device.library);
      name = "OpenHaptics device";
      return device;
    } catch (const Error& e) {
      if (source == ProbeSource::DEVICE) throw;
    }
  }
  auto device = std::make_unique<MouseDevice>(mouse_specs);
  mouse = device.get();
  name = "mouse";
  return device;
}

}  // namespace

std::vector<index_t> visible_shell(const Csr& neighbours) {
  // the points with a less full neighbourhood than the fullest, and their neighbours: on a lattice the two
  // outer layers (the second shows through the gaps between the first's spheres)
  const index_t n = neighbours.n_rows();
  index_t fullest = 0;
  for (index_t i = 0; i < n; ++i) fullest = std::max(fullest, neighbours.row_size(i));
  std::vector<char> seen(static_cast<std::size_t>(n), 0);
  for (index_t i = 0; i < n; ++i) {
    if (neighbours.row_size(i) == fullest) continue;
    seen[static_cast<std::size_t>(i)] = 1;
    for (index_t e = neighbours.begin(i); e < neighbours.end(i); ++e)
      seen[static_cast<std::size_t>(neighbours.index[static_cast<std::size_t>(e)])] = 1;
  }
  std::vector<index_t> shell;
  for (index_t i = 0; i < n; ++i)
    if (seen[static_cast<std::size_t>(i)]) shell.push_back(i);
  return shell;
}

std::unique_ptr<Prepared> prepare(const Scene& scene_in, ProbeSource source, int threads) {
  auto p = std::make_unique<Prepared>();
  p->scene = scene_in;
  Scene& scene = p->scene;
  if (scene.solver.kind == SolverKind::STATIC) {
    // a probe needs dynamics: the static scene is shown under implicit dynamics, which settles to the same
    // equilibrium
    scene.solver.kind = SolverKind::IMPLICIT;
    scene.solver.dt = 2e-3;
    p->note = "static solver shown with implicit dynamics (dt = 2 ms)";
  }
  // the viewer always has a probe (the scene's [probe] values, else the defaults): levels of detail start
  // under it. A tool held at a position becomes the mouse's probe (a sphere of its radius).
  if (scene.probe.held()) {
    scene.probe.position = Vec3::Constant(NAN);
    scene.probe.capsule = false;
    scene.probe.length = 0;
    p->note += std::string(p->note.empty() ? "" : "; ") + "the held tool is the mouse's probe here";
  }
  scene.probe.present = true;
  SessionOptions session_options;
  session_options.threads = threads;
  session_options.make_device = false;  // the viewer's own: the mouse, a device, or the scene's script
  SceneSession session = open_scene(scene, session_options);
  p->simulation = std::move(session.simulation);
  p->options = session.interactive;
  const Model& model = p->simulation->model();
  p->reference = model.X;
  p->fixed = model.fixed;
  p->point_radius = 0.5 * model.spacing;
  p->lo = model.X.rowwise().minCoeff();
  p->hi = model.X.rowwise().maxCoeff();
  p->shell = visible_shell(model.neighbours);
  try {
    p->surface = build_object_surface(p->scene, model);
  } catch (const Error& e) {  // the points are drawn instead, and the panel says why
    p->note += std::string(p->note.empty() ? "" : "; ") + "no surface: " + e.what();
  }
  if (p->surface) p->surface_point = heaviest_points(p->surface->map);
  // the mouse pushes, and grabs while its button is held; a scene's grab mode grabs only, its blade cuts and its
  // grasper closes while the button is held
  if (!scene.probe.grab && !scene.probe.cut && !scene.probe.grasper) p->options.probe.mode = ProbeMode::PUSH_GRAB;
  p->options.duration = std::numeric_limits<double>::infinity();
  p->options.log = false;
  p->options.real_time = true;
  p->options.display_period = 1.0 / 120.0;  // twice the frame rate: fresh frames without copying every step
  // the mouse moves a hand anywhere in the scene: the workspace is the scene's
  DeviceSpecs mouse_specs = known_device_specs(scene.device.specs == "custom" ? "touch" : scene.device.specs);
  mouse_specs.name = "mouse";
  p->device = make_device(scene, source, mouse_specs, p->mouse, p->device_name);
  p->hand_names.push_back(scene.probe_name.empty() ? "probe" : scene.probe_name);
  for (const SceneHand& h : scene.other_hands) p->hand_names.push_back(h.name);
  if (p->mouse) {
    // every hand a mouse of its own, starting at its workspace's origin: the cursor drives one at a time
    p->mice.push_back(p->mouse);
    for (HandOptions& hand : p->options.other_hands) {
      auto mouse = std::make_unique<MouseDevice>(mouse_specs);
      p->mice.push_back(mouse.get());
      hand.device = mouse.get();
      p->other_devices.push_back(std::move(mouse));
    }
  } else {
    p->other_devices = make_other_hand_devices(scene, p->options);
  }
  DisplayFrame initial;
  initial.u = Points::Zero(3, p->reference.cols());
  initial.probe = p->options.mapping.origin;
  initial.device = p->options.mapping.origin;
  initial.simulated = p->simulation->simulated_model().n_points;
  p->display = std::make_unique<TripleBuffer<DisplayFrame>>(initial);
  return p;
}

void drive_hand(Prepared& p, std::size_t hand) {
  if (p.mice.empty()) throw Error("view: the hands are not the mouse's (--probe script or device)");
  if (hand >= p.mice.size())
    throw Error(fmt::format("view: hand {} of {}: the scene has no such device-driven tool", hand + 1, p.mice.size()));
  p.driven = hand;
  p.mouse = p.mice[hand];
}

Vec3 hand_origin(const Prepared& p, std::size_t hand) {
  return hand == 0 ? p.options.mapping.origin : p.options.other_hands.at(hand - 1).mapping.origin;
}

Vec3 device_of_scene(const Prepared& p, const Vec3& scene, std::size_t hand) {
  const WorkspaceMapping& m = hand == 0 ? p.options.mapping : p.options.other_hands.at(hand - 1).mapping;
  return (scene - m.origin) / m.scale;
}

std::vector<index_t> heaviest_points(const SurfaceMap& map) {
  std::vector<index_t> point(static_cast<std::size_t>(map.n_vertices()), 0);
  for (index_t v = 0; v < map.n_vertices(); ++v) {
    if (map.points.end(v) == map.points.begin(v)) continue;
    index_t heaviest = map.points.begin(v);
    for (index_t e = map.points.begin(v); e < map.points.end(v); ++e)
      if (map.weight[e] > map.weight[heaviest]) heaviest = e;
    point[static_cast<std::size_t>(v)] = map.points.index[heaviest];
  }
  return point;
}

void split_surface_now(Prepared& p, const DisplayFrame& frame) {
  if (!p.surface || frame.cut_revision == p.cut_revision || frame.cut_sheets.empty()) return;
  p.cut_surface = split_surface(*p.surface, p.simulation->model(), frame.cut_sheets);
  p.cut_surface_point = heaviest_points(p.cut_surface->map);
  p.cut_revision = frame.cut_revision;
}

DisplayFrame simulate_frame(Prepared& p, double time) {
  DisplayFrame frame = p.display->front();
  if (!(time > 0)) return frame;
  InteractiveOptions o = p.options;
  o.real_time = false;
  o.duration = time;
  o.display = p.display.get();
  run_interactive(*p.simulation, *p.device, o);
  p.display->update();
  split_surface_now(p, p.display->front());
  return p.display->front();
}

ViewerSession::ViewerSession(std::unique_ptr<Prepared> prepared, ProbeSource source, int threads)
    : prepared_(std::move(prepared)), source_(source), threads_(threads) {}

ViewerSession::~ViewerSession() {
  stop();
  if (pending_.valid()) pending_.wait();
  if (split_.valid()) split_.wait();
}

void ViewerSession::start() {
  stop();
  stop_.store(false);
  finished_.store(false);
  run_error_.clear();
  thread_ = std::thread([this] {
    try {
      InteractiveOptions o = prepared_->options;
      o.display = prepared_->display.get();
      o.stop = &stop_;
      const InteractiveResult r = run_interactive(*prepared_->simulation, *prepared_->device, o);
      if (r.haptic.device_failed) run_error_ = "the device failed: " + r.haptic.device_error;
      if (prepared_->simulation->diagnostics().failed) run_error_ = prepared_->simulation->diagnostics().failure;
    } catch (const std::exception& e) {
      run_error_ = e.what();
    }
    finished_.store(true, std::memory_order_release);
  });
}

void ViewerSession::stop() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  if (!run_error_.empty()) error_ = run_error_;
}

void ViewerSession::rebuild(const Scene& scene) {
  if (pending_.valid()) return;  // one at a time; the panel shows that one is in flight
  pending_ = std::async(std::launch::async,
                        [scene, source = source_, threads = threads_] { return prepare(scene, source, threads); });
}

bool ViewerSession::poll() {
  prepared_->display->update();
  if (finished_.load(std::memory_order_acquire) && thread_.joinable()) stop();  // collect the error
  poll_cut_surface();
  if (!pending_.valid() || pending_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return false;
  std::unique_ptr<Prepared> next;
  try {
    next = pending_.get();
  } catch (const std::exception& e) {
    error_ = e.what();
    return false;
  }
  stop();
  if (split_.valid()) split_.get();  // a split for the old object: it reads it
  prepared_ = std::move(next);
  error_.clear();
  start();
  return true;
}

void ViewerSession::poll_cut_surface() {
  Prepared& p = *prepared_;
  if (split_.valid()) {
    if (split_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
    Split done = split_.get();
    if (done.of == &p && done.revision != p.cut_revision) {
      p.cut_surface = std::move(done.surface);
      p.cut_surface_point = heaviest_points(p.cut_surface->map);
      p.cut_revision = done.revision;
    }
  }
  const DisplayFrame& frame = p.display->front();
  if (!p.surface || frame.cut_revision == p.cut_revision || frame.cut_sheets.empty()) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_split_ < std::chrono::milliseconds(250)) return;
  last_split_ = now;
  // on a worker, on one thread (the simulation and the haptic loop have the cores); the model's reference
  // positions, kernel and supports, all the split reads of it, do not change while it runs
  split_ = std::async(std::launch::async, [&p, sheets = frame.cut_sheets, revision = frame.cut_revision] {
    tbb::task_arena one_thread(1);
    return one_thread.execute([&] {
      return Split{split_surface(*p.surface, p.simulation->model(), sheets), &p, revision};
    });
  });
}

Vec3 ViewerSession::device_of_scene(const Vec3& scene) const {
  return viewer::device_of_scene(*prepared_, scene, prepared_->driven);
}

}  // namespace pointhaptics::viewer
