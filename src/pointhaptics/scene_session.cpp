#include <pointhaptics/scene_session.hpp>

#include <pointhaptics/haptics/devices/openhaptics_device.hpp>
#include <pointhaptics/haptics/devices/replay_device.hpp>
#include <pointhaptics/haptics/devices/virtual_device.hpp>
#include <pointhaptics/io/haptic_log.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/object_surface.hpp>
#include <pointhaptics/scene_builder.hpp>

#include <fmt/format.h>

#include <chrono>

namespace pointhaptics {

SceneSession open_scene(Scene scene, const SessionOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  SceneSession s;
  s.simulation =
      std::make_unique<Simulation>(build_scene_model(scene, options.max_memory), scene.solver, options.threads);
  if (scene.lod.present) s.simulation->enable_lod(scene.lod.params, scene_lod_contact(scene, s.simulation->model()));
  for (const CutSpec& cut : scene.cuts) s.simulation->add_scripted_cut(cut);
  if (scene.probe.held()) {
    // a tool held at a position, touching the object's surface
    const ObjectSurface surface = build_object_surface(scene, s.simulation->model());
    ToolShape shape;
    shape.kind = scene.probe.capsule ? ToolKind::CAPSULE : ToolKind::SPHERE;
    shape.radius = scene.probe.radius;
    shape.length = scene.probe.length;
    const auto& q = scene.probe.orientation;
    SurfaceContactParams contact;
    contact.friction = scene.probe.friction;
    contact.non_negative_weights = scene.probe.non_negative_surface_map;
    contact.sample_spacing = scene.probe.sample_spacing;
    s.simulation->hold_tool(shape, ToolPose{scene.probe.position, Eigen::Quaterniond(q[0], q[1], q[2], q[3])},
                            surface.mesh, surface.map, contact);
  } else if (scene.probe.present) {
    s.interactive = scene_interactive_options(scene, s.simulation->model());
    // the probe pushes on the object's surface (with levels of detail, on the part the active set carries)
    s.interactive.surface = std::make_shared<const ObjectSurface>(build_object_surface(scene, s.simulation->model()));
    if (options.make_device) s.device = make_scene_device(scene);
  }
  s.scene = std::move(scene);
  s.setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return s;
}

SceneSession open_scene_file(const std::string& path, const SessionOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  Scene scene = read_scene_file(path, options.settings);
  const double reading = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  SceneSession s = open_scene(std::move(scene), options);
  s.setup_seconds += reading;
  return s;
}

namespace {

DeviceSpecs scene_device_specs(const DeviceSpec& d) {
  if (d.specs != "custom") return known_device_specs(d.specs);
  return {"custom", d.max_force, d.max_stiffness, d.max_damping, d.workspace_radius, d.max_torque};
}

}  // namespace

std::unique_ptr<Device> make_scene_device(const Scene& scene) {
  const DeviceSpecs specs = scene_device_specs(scene.device);
  if (scene.device.kind == "replay") return std::make_unique<ReplayDevice>(read_haptic_log(scene.device.log), specs);
  if (scene.device.kind == "openhaptics")
    return std::make_unique<OpenHapticsDevice>(scene.device.library);  // its own specs
  if (scene.device.kind != "virtual")
    throw Error(fmt::format("{}: device.kind = \"{}\" is not available", scene.path, scene.device.kind));
  if (!scene.probe.trajectory.empty())
    return std::make_unique<VirtualDevice>(Trajectory::from_csv(scene.probe.trajectory), specs);
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
  o.probe.mode = scene.probe.grab ? ProbeMode::GRAB : scene.probe.cut ? ProbeMode::CUT : ProbeMode::PUSH;
  o.probe.cut_resistance = scene.probe.cut_resistance;
  o.probe.stiffness = scene.probe.stiffness;
  o.probe.object_stiffness = scene.probe.object_stiffness;
  o.probe.non_negative_surface_map = scene.probe.non_negative_surface_map;
  o.probe.sample_spacing = scene.probe.sample_spacing;
  o.probe.friction = scene.probe.friction;
  o.probe.length = scene.probe.capsule ? scene.probe.length : 0.0;
  const auto& q = scene.probe.orientation;
  o.probe.orientation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
  o.mapping.scale = scene.probe.scale;
  if (scene.probe.origin.allFinite()) {
    o.mapping.origin = scene.probe.origin;
  } else {
    const Vec3 lo = model.X.rowwise().minCoeff(), hi = model.X.rowwise().maxCoeff();
    o.mapping.origin = Vec3(0.5 * (lo.x() + hi.x()), hi.y() + 2 * scene.probe.radius, 0.5 * (lo.z() + hi.z()));
  }
  o.duration = scene.solver.duration;
  o.rules.passivity_control = scene.device.passivity_control;
  return o;
}

}  // namespace pointhaptics
