#include <pointhaptics/session/scene_session.hpp>

#include <pointhaptics/core/run_control.hpp>
#include <pointhaptics/haptics/devices/haply_device.hpp>
#include <pointhaptics/haptics/devices/openhaptics_device.hpp>
#include <pointhaptics/haptics/devices/replay_device.hpp>
#include <pointhaptics/haptics/devices/virtual_device.hpp>
#include <pointhaptics/io/haptic_log.hpp>
#include <pointhaptics/io/scene_toml.hpp>
#include <pointhaptics/surface/object_surface.hpp>
#include <pointhaptics/session/scene_builder.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <tuple>
#include <utility>

namespace pointhaptics {
namespace {

// an [[obstacle]] as the rigid shape its contact presses on; a box's edges are rounded by a quarter of the
// object's spacing (or of its thinnest half size), below what the surface resolves
std::pair<ToolShape, ToolPose> obstacle_shape(const ObstacleSpec& o, double spacing) {
  ToolShape shape;
  ToolPose pose;
  switch (o.shape) {
    case ObstacleShape::PLANE:
      shape.kind = ToolKind::PLANE;
      shape.radius = spacing;
      pose.position = o.point;
      pose.orientation = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), o.normal);
      break;
    case ObstacleShape::BOX: {
      const Vec3 half = 0.5 * (o.box.max - o.box.min);
      shape.kind = ToolKind::BOX;
      shape.radius = 0.25 * std::min(spacing, half.minCoeff());
      shape.half_core = half.array() - shape.radius;
      pose.position = 0.5 * (o.box.max + o.box.min);
      break;
    }
    case ObstacleShape::SPHERE:
      shape.kind = ToolKind::SPHERE;
      shape.radius = o.radius;
      pose.position = o.centre;
      break;
    case ObstacleShape::CAPSULE: {
      const Vec3 axis = o.ends[1] - o.ends[0];
      shape.kind = axis.norm() > 0 ? ToolKind::CAPSULE : ToolKind::SPHERE;
      shape.radius = o.radius;
      shape.length = axis.norm();
      pose.position = 0.5 * (o.ends[0] + o.ends[1]);
      if (axis.norm() > 0) pose.orientation = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), axis);
      break;
    }
  }
  return {shape, pose};
}

// a held or posed tool's shape, pose (at its position; NaN without one) and contact, from its [probe] or [[tool]]
// keys
std::tuple<ToolShape, ToolPose, SurfaceContactParams> held_tool_shape(const ProbeSpec& p) {
  ToolShape shape;
  shape.kind = p.capsule ? ToolKind::CAPSULE : ToolKind::SPHERE;
  shape.radius = p.radius;
  shape.length = p.length;
  const auto& q = p.orientation;
  SurfaceContactParams contact;
  contact.friction = p.friction;
  contact.non_negative_weights = p.non_negative_surface_map;
  contact.sample_spacing = p.sample_spacing;
  return {shape, ToolPose{p.position, Eigen::Quaterniond(q[0], q[1], q[2], q[3])}, contact};
}

}  // namespace

SceneSession open_scene(Scene scene, const SessionOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  SceneSession s;
  s.simulation =
      std::make_unique<Simulation>(build_scene_model(scene, options.max_memory), scene.solver, options.threads);
  if (scene.lod.present) s.simulation->enable_lod(scene.lod.params, scene_lod_contact(scene, s.simulation->model()));
  for (const CutSpec& cut : scene.cuts) s.simulation->add_scripted_cut(cut);
  // the object's surface, built once for the obstacles, a held tool and a device's probe alike
  std::shared_ptr<const ObjectSurface> object_surface;
  const auto surface_of_object = [&]() -> const std::shared_ptr<const ObjectSurface>& {
    if (!object_surface)
      object_surface = std::make_shared<const ObjectSurface>(build_object_surface(scene, s.simulation->model()));
    return object_surface;
  };
  // several bodies touch on their surfaces (each carried by its own points), and so do the pieces a cut makes of
  // one (not yet with levels of detail: an active set carries part of the surface)
  const bool cuts =
      !scene.cuts.empty() || scene.probe.cut ||
      std::any_of(scene.other_hands.begin(), scene.other_hands.end(), [](const SceneHand& h) { return h.probe.cut; });
  if (s.simulation->model().n_bodies() > 1 || (cuts && !scene.lod.present)) {
    BodyContactParams contact;
    const std::size_t n = scene.bodies.size();
    contact.pair_friction.assign(n * n, scene.contact.friction);
    const auto index_of = [&](const std::string& name) {
      std::size_t k = 0;
      while (scene.bodies[k].name != name) ++k;  // the reader checked the names
      return k;
    };
    for (const ContactSpec::Pair& p : scene.contact.pairs) {
      const std::size_t a = index_of(p.bodies[0]), b = index_of(p.bodies[1]);
      contact.pair_friction[a * n + b] = contact.pair_friction[b * n + a] = p.friction;
    }
    s.simulation->add_body_contact(*surface_of_object(), contact);
  }
  for (std::size_t k = 0; k < scene.obstacles.size(); ++k) {
    const ObstacleSpec& o = scene.obstacles[k];
    // static rigid bodies the object's surface presses on
    const double spacing = s.simulation->model().spacing;
    const auto [shape, pose] = obstacle_shape(o, spacing);
    SurfaceContactParams contact;
    contact.friction = o.friction;
    contact.sample_spacing = spacing;
    contact.tolerance = 1e-3 * spacing;  // at rest inside it by at most a thousandth of the spacing
    const ObjectSurface& surface = *surface_of_object();
    try {
      std::vector<Keyframe> frames;
      for (const auto& k : o.keyframes) frames.push_back({k[0], Vec3(k[1], k[2], k[3]), false});
      s.simulation->add_obstacle(o.name, shape, pose, surface.mesh, surface.map, contact,
                                 frames.empty() ? Trajectory() : Trajectory(std::move(frames)));
    } catch (const Interrupted&) {
      throw;
    } catch (const Error& e) {
      throw Error(fmt::format("{}:{}: obstacle[{}]: {}", scene.path, o.line, k, e.what()));
    }
  }
  for (std::size_t k = 0; k < scene.tools.size(); ++k) {
    // tools the scene poses: held at a position, or moved along keyframes (where they are, scene axes)
    const ToolSpec& t = scene.tools[k];
    const ObjectSurface& surface = *surface_of_object();
    const auto [shape, pose, contact] = held_tool_shape(t.probe);
    std::vector<Keyframe> frames;
    for (const auto& f : t.path) frames.push_back({f[0], Vec3(f[1], f[2], f[3]), false});
    ToolPose start = pose;
    if (!frames.empty()) start.position.setZero();
    try {
      const Trajectory path = frames.empty() ? Trajectory() : Trajectory(std::move(frames));
      if (t.probe.grasper) {
        // its jaws' gap, held or one per keyframe
        std::vector<Keyframe> gaps;
        for (std::size_t f = 0; f < t.opening.size(); ++f)
          gaps.push_back({t.path.empty() ? 0.0 : t.path[f][0], Vec3(t.opening[f], 0, 0), false});
        s.simulation->add_grasper(t.name, shape, start, Trajectory(std::move(gaps)), surface.mesh, surface.map, contact,
                                  path);
      } else {
        s.simulation->add_posed_tool(t.name, shape, start, surface.mesh, surface.map, contact, path);
      }
    } catch (const Interrupted&) {
      throw;
    } catch (const Error& e) {
      throw Error(fmt::format("{}:{}: tool[{}]: {}", scene.path, t.line, k, e.what()));
    }
  }
  if (!scene.probe_name.empty()) s.simulation->set_tool_name(scene.probe_name);
  if (scene.probe.held()) {
    // a tool held at a position, touching the object's surface
    const ObjectSurface& surface = *surface_of_object();
    const auto [shape, pose, contact] = held_tool_shape(scene.probe);
    s.simulation->hold_tool(shape, pose, surface.mesh, surface.map, contact);
  } else if (scene.probe.present) {
    s.interactive = scene_interactive_options(scene, s.simulation->model());
    // the probe pushes on the object's surface (with levels of detail, on the part the active set carries)
    s.interactive.surface = surface_of_object();
    for (HandOptions& hand : s.interactive.other_hands) hand.surface = surface_of_object();
    if (options.make_device) {
      s.device = make_scene_device(scene);
      s.other_devices = make_other_hand_devices(scene, s.interactive);
    }
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

std::unique_ptr<Device> make_hand_device(const Scene& scene, const ProbeSpec& probe, const DeviceSpec& device) {
  const DeviceSpecs specs = scene_device_specs(device);
  if (device.kind == "replay") return std::make_unique<ReplayDevice>(read_haptic_log(device.log), specs);
  if (device.kind == "openhaptics")
    return std::make_unique<OpenHapticsDevice>(device.library, device.hd_device);  // its own specs
  if (device.kind == "haply") {                                                    // its own specs
    HaplyOptions haply;
    haply.host = device.host;
    haply.port = device.port;
    haply.device_id = device.device_id;
    return std::make_unique<HaplyDevice>(haply);
  }
  if (device.kind != "virtual")
    throw Error(fmt::format("{}: device.kind = \"{}\" is not available", scene.path, device.kind));
  if (!probe.trajectory.empty()) return std::make_unique<VirtualDevice>(Trajectory::from_csv(probe.trajectory), specs);
  std::vector<Keyframe> frames;
  for (const auto& k : probe.keyframes) frames.push_back({k[0], Vec3(k[1], k[2], k[3]), k[4] != 0});
  try {
    return std::make_unique<VirtualDevice>(Trajectory(std::move(frames)), specs);
  } catch (const Error& e) {
    throw Error(fmt::format("{}:{}: probe.keyframes: {}", scene.path, probe.line, e.what()));
  }
}

std::unique_ptr<Device> make_scene_device(const Scene& scene) {
  return make_hand_device(scene, scene.probe, scene.device);
}

void put_hand_first(Scene& scene, const std::string& tool) {
  const std::string first = scene.probe_name.empty() ? "probe" : scene.probe_name;
  if (scene.probe.present && !scene.probe.held() && tool == first) return;
  for (SceneHand& hand : scene.other_hands)
    if (hand.name == tool) {
      std::swap(hand.probe, scene.probe);
      std::swap(hand.device, scene.device);
      hand.name = first;
      scene.probe_name = tool;
      return;
    }
  std::string names = scene.probe.present && !scene.probe.held() ? "\"" + first + "\"" : "";
  for (const SceneHand& hand : scene.other_hands) names += (names.empty() ? "\"" : ", \"") + hand.name + "\"";
  throw Error(fmt::format("{}: no device-driven tool is named \"{}\" ({})", scene.path, tool,
                          names.empty() ? std::string("the scene has none") : "the device-driven tools: " + names));
}

std::vector<std::unique_ptr<Device>> make_other_hand_devices(const Scene& scene, InteractiveOptions& options) {
  if (options.other_hands.size() != scene.other_hands.size())
    throw Error(fmt::format("{}: the interactive options are not the scene's (other hands)", scene.path));
  std::vector<std::unique_ptr<Device>> devices;
  for (std::size_t k = 0; k < scene.other_hands.size(); ++k) {
    devices.push_back(make_hand_device(scene, scene.other_hands[k].probe, scene.other_hands[k].device));
    options.other_hands[k].device = devices.back().get();
  }
  return devices;
}

namespace {

// a device-driven tool's probe and workspace mapping (the device origin defaults to 2 probe radii above the
// centre of the object's top)
void hand_options(const ProbeSpec& p, const Model& model, ProbeParams& probe, WorkspaceMapping& mapping) {
  probe.radius = p.radius;
  probe.mode = p.grasper ? ProbeMode::GRASP : p.grab ? ProbeMode::GRAB : p.cut ? ProbeMode::CUT : ProbeMode::PUSH;
  probe.opening = p.opening;
  probe.grip = p.grip;
  probe.grip_time = p.grip_time;
  probe.cut_resistance = p.cut_resistance;
  probe.stiffness = p.stiffness;
  probe.object_stiffness = p.object_stiffness;
  probe.non_negative_surface_map = p.non_negative_surface_map;
  probe.sample_spacing = p.sample_spacing;
  probe.friction = p.friction;
  probe.length = p.capsule ? p.length : 0.0;
  const auto& q = p.orientation;
  probe.orientation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
  mapping.scale = p.scale;
  if (p.origin.allFinite()) {
    mapping.origin = p.origin;
  } else {
    const Vec3 lo = model.X.rowwise().minCoeff(), hi = model.X.rowwise().maxCoeff();
    mapping.origin = Vec3(0.5 * (lo.x() + hi.x()), hi.y() + 2 * p.radius, 0.5 * (lo.z() + hi.z()));
  }
}

}  // namespace

InteractiveOptions scene_interactive_options(const Scene& scene, const Model& model) {
  InteractiveOptions o;
  hand_options(scene.probe, model, o.probe, o.mapping);
  for (const SceneHand& h : scene.other_hands) {
    HandOptions& hand = o.other_hands.emplace_back();
    hand.name = h.name;
    hand_options(h.probe, model, hand.probe, hand.mapping);
  }
  o.duration = scene.solver.duration;
  o.rules.passivity_control = scene.device.passivity_control;
  return o;
}

}  // namespace pointhaptics
