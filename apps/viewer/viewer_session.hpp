#pragma once
/// @file What the viewer shows and drives: a scene's simulation stepping on its own thread in real time
/// with the 1 kHz haptic loop on another, a probe driven by the mouse (or a real device, or the scene's
/// script), and rebuilds from edited parameters on a worker thread while the old run goes on.
#include <pointhaptics/haptics/devices/mouse_device.hpp>
#include <pointhaptics/session/interactive.hpp>
#include <pointhaptics/surface/object_surface.hpp>

#include <atomic>
#include <chrono>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <thread>

namespace pointhaptics::viewer {

/// What drives the probe. AUTO: a haptic device if one answers (OpenHaptics), else the mouse.
enum class ProbeSource { AUTO, MOUSE, SCRIPT, DEVICE };
/// Parses "auto", "mouse", "script", "device"; throws Error naming the value otherwise.
ProbeSource probe_source_of(const std::string& name);

/// Everything of one build: the simulation, its device, and what the viewer keeps of the object
/// (read-only on the viewer's thread while the simulation runs).
struct Prepared {
  Scene scene;
  std::unique_ptr<Simulation> simulation;
  std::unique_ptr<Device> device;
  MouseDevice* mouse = nullptr;  ///< the device the cursor drives now (mice[driven]), when the mouse drives
  std::string device_name;       ///< what drives the probe, for the panel
  /// The scene's other device-driven tools' devices (two hands). With the mouse, each is a mouse device of its own
  /// (mice), of which the cursor drives one at a time (drive_hand()) and the others stay where it left them; with a
  /// script or a device, the scene's devices.
  std::vector<std::unique_ptr<Device>> other_devices;
  std::vector<MouseDevice*> mice;  ///< with the mouse: every hand's, in the hands' order (0: `device`'s); else empty
  std::size_t driven = 0;          ///< the hand the cursor drives (mice's index)
  std::vector<std::string> hand_names;  ///< every device-driven tool's name, in the hands' order
  InteractiveOptions options;
  Points reference;  ///< the object's points, m
  std::vector<unsigned char> fixed;
  double point_radius = 0;  ///< spheres drawn for points, m
  /// The points that can be seen from outside: those with fewer neighbours than the fullest neighbourhood,
  /// and their neighbours (the two outer layers of a lattice sampling; every point of an irregular cloud).
  /// An opaque object hides the rest, and not drawing them is 2-4x less to draw at 100k points.
  std::vector<index_t> shell;
  /// The object's surface (docs/surface.md) when it has one, and each vertex's point of largest weight
  /// (whose flags, band and grab the vertex shows).
  std::optional<ObjectSurface> surface;
  std::vector<index_t> surface_point;
  /// After cuts: the surface split along their sheets (cut_surface.hpp) as of the frame's cut_revision, drawn
  /// instead of `surface`, and its vertices' points of largest weight.
  std::optional<ObjectSurface> cut_surface;
  std::vector<index_t> cut_surface_point;
  long long cut_revision = 0;

  /// The surface drawn (the cut one after cuts), or null; and its vertices' points of largest weight.
  const ObjectSurface* drawn_surface() const { return cut_surface ? &*cut_surface : surface ? &*surface : nullptr; }
  const std::vector<index_t>& drawn_surface_point() const { return cut_surface ? cut_surface_point : surface_point; }
  Vec3 lo, hi;       ///< bounding box of the reference configuration
  std::string note;  ///< what was changed to run the scene here (a static solver), else empty
  std::unique_ptr<TripleBuffer<DisplayFrame>> display;
};

/// The points of a model that can be seen from outside (Prepared::shell), from its neighbour lists.
std::vector<index_t> visible_shell(const Csr& neighbours);

/// Build a scene for viewing; throws Error for a scene that cannot be built.
std::unique_ptr<Prepared> prepare(const Scene& scene, ProbeSource source, int threads);

/// With the mouse: the cursor drives hand `hand` from now on (prepared.mouse is its device); the hand it drove
/// stays where it left it. Throws Error for a hand that is not there or without the mouse.
void drive_hand(Prepared& prepared, std::size_t hand);
/// Device frame of a scene point for hand `hand` (the inverse of its workspace mapping), for the mouse.
Vec3 device_of_scene(const Prepared& prepared, const Vec3& scene, std::size_t hand);
/// Scene position of hand `hand`'s workspace origin, m: where its mouse starts.
Vec3 hand_origin(const Prepared& prepared, std::size_t hand);

/// Each vertex's point of largest weight in `map`.
std::vector<index_t> heaviest_points(const SurfaceMap& map);

/// Split prepared.surface along `frame`'s cut sheets now, if the frame has newer ones than prepared.cut_surface.
void split_surface_now(Prepared& prepared, const DisplayFrame& frame);

/// The display frame after `time` s of the scene, simulated deterministically (no threads, no wall
/// clock) with the scene's scripted probe if it has one, else with the probe resting at its origin.
DisplayFrame simulate_frame(Prepared& prepared, double time);

class ViewerSession {
 public:
  ViewerSession(std::unique_ptr<Prepared> prepared, ProbeSource source, int threads);
  ~ViewerSession();  ///< stops the run

  /// Start the real-time run on a thread (the haptic loop starts its own).
  void start();
  void stop();
  /// Build `scene` on a worker thread; poll() swaps it in and restarts when it is ready.
  void rebuild(const Scene& scene);
  /// Viewer thread, once a frame: true if a rebuild took over (a new object: new point count).
  bool poll();
  bool rebuilding() const { return pending_.valid(); }

  Prepared& current() { return *prepared_; }
  /// The latest frame the simulation published (updated by poll()).
  const DisplayFrame& frame() const { return prepared_->display->front(); }
  /// The run or the last rebuild failed: the message (the old run goes on after a failed rebuild).
  const std::string& error() const { return error_; }
  bool running() const { return thread_.joinable() && !finished_.load(std::memory_order_acquire); }
  /// Device frame of a scene point for the hand the cursor drives (the inverse of its workspace mapping).
  Vec3 device_of_scene(const Vec3& scene) const;

 private:
  /// Take a finished split of the surface along the cuts, and start one if the frame has newer cuts.
  void poll_cut_surface();

  std::unique_ptr<Prepared> prepared_;
  ProbeSource source_;
  int threads_;
  std::thread thread_;
  std::atomic<bool> stop_{false}, finished_{false};
  std::future<std::unique_ptr<Prepared>> pending_;
  /// The surface split along a frame's cut sheets on a worker (poll() takes it), for the Prepared it was made
  /// for, of that frame's cut revision.
  struct Split {
    ObjectSurface surface;
    const Prepared* of = nullptr;
    long long revision = 0;
  };
  std::future<Split> split_;
  /// When the last split started: the next waits a quarter of a second after it, so that a stroke of the blade
  /// (new sheets every step) does not keep a core busy that the simulation and the haptic loop need.
  std::chrono::steady_clock::time_point last_split_{};
  std::string error_, run_error_;
};

}  // namespace pointhaptics::viewer
