#pragma once
/// @file An interactive run: the simulation and the haptic loop together, a probe driven by a device.
#include <pointhaptics/haptics/haptic_loop.hpp>
#include <pointhaptics/haptics/device.hpp>
#include <pointhaptics/world/simulation.hpp>

#include <atomic>
#include <functional>
#include <memory>

namespace pointhaptics {

/// A displacement frame the simulation publishes for the output or graphics side.
struct DisplayFrame {
  double time = 0;
  long long step = 0;
  Points u;  ///< displacements, m (3 x n)
  Vec3 probe = Vec3::Constant(NAN);
  Vec3 device = Vec3::Constant(NAN);  ///< scene position of the device point, m
  Vec3 force = Vec3::Zero();          ///< force the haptic loop rendered last, N
  int contacts = 0;                   ///< points the probe touches or holds
  long long haptic_ticks = 0;         ///< haptic ticks so far (a rate meter for the reader)
  std::vector<index_t> grabbed;       ///< held by the probe (indices of the whole object)
  /// Levels of detail: per point of the object the band of a simulated (selected) point, -1 for the
  /// others; empty without levels of detail. Rewritten only when lod_selections changes.
  std::vector<std::int8_t> lod_band;
  long long lod_selections = 0;
  index_t simulated = 0;  ///< points simulated (the active set with levels of detail)
  /// The cuts' sheets (reference configuration; cut_surface.hpp), rewritten only when cut_revision changes:
  /// a viewer splits the object's surface along them.
  std::vector<SheetTriangle> cut_sheets;
  long long cut_revision = 0;
  /// The rigid shapes besides the first probe, where they are: the other hands' probes, the obstacles and the posed
  /// tools (a viewer draws them)
  struct RigidShape {
    ToolShape shape;
    ToolPose pose;
    bool hand = false;  ///< a device's probe (else an obstacle or a posed tool)
  };
  std::vector<RigidShape> rigid;
};

/// A second (or later) hand of an interactive run (issue 47): its own device, probe and workspace, its own haptic
/// loop and local contact model; it touches every body as the first does.
struct HandOptions {
  Device* device = nullptr;  ///< not owned; must outlive the run
  std::string name;          ///< what the result reports it under (empty: "hand2", ...)
  ProbeParams probe;
  std::shared_ptr<const ObjectSurface> surface;  ///< as InteractiveOptions::surface
  WorkspaceMapping mapping;
  /// If set, this hand's force log (one row per haptic tick of its own loop) is streamed here, as
  /// InteractiveOptions::log_sink streams the first hand's.
  std::function<void(const HapticLogRow&)> log_sink;
};

struct InteractiveOptions {
  ProbeParams probe;
  /// The object's surface: the probe pushes on it (issue 16) instead of on the point spheres (null: the
  /// point spheres; with levels of detail the probe keeps them).
  std::shared_ptr<const ObjectSurface> surface;
  WorkspaceMapping mapping;
  double duration = 1.0;         ///< s
  double haptic_rate = 1000.0;   ///< Hz
  double coupling_safety = 0.5;  ///< fraction of the device's stable stiffness the coupling may use
  ForceRules rules;
  bool real_time = true;  ///< threads on the wall clock; false: one thread, deterministic, simulated time
  bool log = true;        ///< keep the force log (one row per haptic tick) in the result
  /// If set, the force log is streamed here instead (on the simulation's thread, as the run goes), so that
  /// a run of any length logs in bounded memory (a --force-log file).
  std::function<void(const HapticLogRow&)> log_sink;
  /// If set, the simulation publishes a DisplayFrame after every step here (lock-free; the reader, e.g. a
  /// viewer thread, calls update() and reads front()). Its frames must be sized for the object's points
  /// (all of them, with levels of detail too).
  TripleBuffer<DisplayFrame>* display = nullptr;
  /// Publish a display frame at most once per this many seconds (of wall time in real time, of simulated
  /// time otherwise; 0: after every step), and after the last step. Each frame carries the whole object's displacements (with levels of detail, the
  /// absorbed points followed by MLS): a viewer wants about 100 a second, not one per step.
  double display_period = 0;
  /// If set, called on the simulation's thread after every step with the number of steps so far (e.g. to
  /// write output frames); it holds up the simulation while it runs, not the haptic loop.
  std::function<void(long long)> after_step;
  /// If set, the run also ends (at the next step) once this becomes true: a viewer's window closed.
  const std::atomic<bool>* stop = nullptr;
  /// More hands beside the first (whose device run_interactive() takes and whose probe, surface and mapping are
  /// above): each ticks its own haptic loop at the haptic rate, none waits on another or on the simulation.
  /// Without levels of detail.
  std::vector<HandOptions> other_hands;
};

/// A second or later hand's figures at the end of a run.
struct HandResult {
  std::string name;
  HapticStats haptic;
  ToolSummary tool;  ///< its probe at the end, with its haptic figures
  int max_contacts = 0;
  LocalModelSummary local_model;
  long long log_dropped = 0;  ///< ticks its log_sink did not get (the simulation thread did not take them in time)
};

struct InteractiveResult {
  HapticStats haptic;
  std::vector<HapticLogRow> log;  ///< with options.log and no log_sink
  long long log_dropped = 0;      ///< ticks not logged: the simulation thread did not take them in time
  long long simulation_steps = 0;
  double simulation_wall_s = 0;
  int max_contacts = 0;
  ToolSummary tool;                     ///< the probe at the end (the result JSON's tool block)
  LocalModelSummary local_model;        ///< how far each local model strayed from the next update
  bool interrupted = false;             ///< a stop was requested (run_control.hpp): the run ended at the state reached
  std::vector<HandResult> other_hands;  ///< InteractiveOptions::other_hands', in their order
};

/// Run the simulation with a probe driven by `device` (and one more per options.other_hands) for options.duration. Real time: the haptic loop
/// ticks on its own thread at the haptic rate while this thread steps the simulation as fast as it can
/// (but never ahead of the wall clock), exchanging the probe and the local contact model through
/// lock-free buffers. Deterministic (real_time = false): the same exchange, interleaved on one thread in
/// simulated time (a haptic tick every 1/rate s, a simulation step every dt), for tests and experiments.
/// A device that fails stops the run with zero force; the result says so. A step that fails stops the run
/// (sim.diagnostics() says why). A stop request (options.stop, or request_stop() from anywhere, honoured inside
/// a step too) ends the run at the state reached, with `interrupted` set. Throws Error on bad options.
InteractiveResult run_interactive(Simulation& sim, Device& device, const InteractiveOptions& options);

/// A run's summary with its interactive session's: the probe's tool block and the haptic loop's figures, and
/// every other hand's tool block (in `tools`) with its own haptic figures.
void add_interactive_summary(RunSummary& summary, const InteractiveResult& interactive);

}  // namespace pointhaptics
