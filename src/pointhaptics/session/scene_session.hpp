#pragma once
/// @file One scene made ready to run, the same way for the command line, the viewer and Python: the model
/// built, the simulation with its levels of detail, and with a [probe] its device and interactive options.
/// Every default a run depends on is set here once.
#include <pointhaptics/session/interactive.hpp>
#include <pointhaptics/io/scene.hpp>
#include <pointhaptics/io/scene_toml.hpp>

#include <memory>
#include <vector>

namespace pointhaptics {

struct SessionOptions {
  int threads = 0;                     ///< for the force evaluation (0: all hardware threads)
  double max_memory = 0;               ///< bytes a model may take (0: the memory available); a larger one is refused
  bool make_device = true;             ///< with a [probe]: open the scene's device (a viewer or Python brings its own)
  std::vector<SceneSetting> settings;  ///< open_scene_file(): keys set over the file's (`--set`, a study's parameters)
};

struct SceneSession {
  Scene scene;
  std::unique_ptr<Simulation> simulation;
  /// With a [probe] and options.make_device: the device the scene names (make_scene_device()).
  std::unique_ptr<Device> device;
  /// ... and the devices of its other device-driven tools (two hands), in interactive.other_hands' order (which
  /// point to them)
  std::vector<std::unique_ptr<Device>> other_devices;
  /// With a [probe]: the probe, workspace mapping and duration of the scene (scene_interactive_options()).
  InteractiveOptions interactive;
  double setup_seconds =
      0;  ///< reading the scene file (open_scene_file), building the model, the solver and the first active set, s
};

/// Build `scene`: its model (refused beyond options.max_memory), its simulation, levels of detail around
/// [lod] contact, and with a [probe] its interactive options and (options.make_device) its device. Throws
/// Error naming the scene and the problem.
SceneSession open_scene(Scene scene, const SessionOptions& options = {});
/// open_scene() of a scene file.
SceneSession open_scene_file(const std::string& path, const SessionOptions& options = {});

/// The device a scene's [probe] and [device] describe: a virtual device following the trajectory or
/// keyframes, a replay of a recorded log, or an OpenHaptics device. Throws Error naming the scene and the problem.
std::unique_ptr<Device> make_scene_device(const Scene& scene);
/// The same for any device-driven tool of the scene (the first is scene.probe and scene.device; the others are in
/// scene.other_hands).
std::unique_ptr<Device> make_hand_device(const Scene& scene, const ProbeSpec& probe, const DeviceSpec& device);
/// Make the device-driven tool named `tool` the scene's first hand (its probe and device), the one a viewer's mouse
/// drives; the first moves to its place among the other hands. Throws Error naming the device-driven tools when
/// none is named so.
void put_hand_first(Scene& scene, const std::string& tool);
/// The devices of the scene's other hands (scene.other_hands), each given to its hand in `options`
/// (scene_interactive_options() of the scene).
std::vector<std::unique_ptr<Device>> make_other_hand_devices(const Scene& scene, InteractiveOptions& options);
/// The interactive options of a scene: probe, workspace mapping (the device origin defaults to 2 probe
/// radii above the centre of the object's top), duration (solver.duration; a replay defaults to its log), and
/// its other hands (without devices: open_scene() gives them theirs).
InteractiveOptions scene_interactive_options(const Scene& scene, const Model& model);

}  // namespace pointhaptics
