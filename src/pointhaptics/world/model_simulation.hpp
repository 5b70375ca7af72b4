#pragma once
/// @file An ordinary simulation of one model: its State, the solver's Workspace and the Solver, the tools
/// that act on it, and the step pipeline. It knows nothing of levels of detail: the layer above
/// (levels_of_detail.hpp) drives one of these over the active model. Most users want Simulation.
#include <pointhaptics/bodies/body_sleep.hpp>
#include <pointhaptics/core/state.hpp>
#include <pointhaptics/core/workspace.hpp>
#include <pointhaptics/contact/body_contact.hpp>
#include <pointhaptics/tools/held_tool.hpp>
#include <pointhaptics/tools/probe_tool.hpp>
#include <pointhaptics/haptics/trajectory.hpp>
#include <pointhaptics/lod/active_set.hpp>
#include <pointhaptics/lod/active_surface.hpp>
#include <pointhaptics/mechanics/cut.hpp>
#include <pointhaptics/surface/cut_surface.hpp>
#include <pointhaptics/surface/object_surface.hpp>

#include <future>
#include <pointhaptics/solvers/force_set.hpp>
#include <pointhaptics/solvers/solver.hpp>

#include <array>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace pointhaptics {

/// What a step takes from outside the object. The caller fills it between steps (MuJoCo's step1/step2:
/// read the last step's outputs, set the inputs, step); the step reads it in its first stage.
struct StepInputs {
  Vec3 device = Vec3::Constant(NAN);  ///< the probe's device point in the scene, m (NaN: the probe is lifted off)
  bool button = false;                ///< the device's button (grab)
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< the device's (turns a capsule probe)
};

/// Counters and timers of the steps so far: the simulation's diagnostics, read by summary().
struct StepDiagnostics {
  long long steps = 0;       ///< steps taken (a static solve is one)
  long long substeps = 0;    ///< explicit sub-steps, static load increments
  long long iterations = 0;  ///< Newton iterations (explicit: sub-steps)
  long long cg_iterations = 0;
  long long factorisations = 0;             ///< preconditioner = "cholesky": numeric factorisations of the tangent
  long long background_factorisations = 0;  ///< ... of them, made on a worker thread
  double factor_bytes = 0;       ///< ... and the largest factor's size, bytes (two_level: the coarse factor's)
  long long coarse_points = 0;   ///< preconditioner = "two_level": the coarse level's points (the largest)
  long long budget_steps = 0;    ///< implicit steps the iteration budget ended above the tolerance
  double residual = 0;           ///< the last Newton residual
  long long inverted_steps = 0;  ///< steps that ended with inverted neighbourhoods (det F <= 0)
  index_t inverted = 0;          ///< inverted neighbourhoods at the end of the last step (of its last force
                                 ///< evaluation: explicit steps one sub-step before the end)
  StepStatus status = StepStatus::CONVERGED;  ///< of the last step
  bool failed = false;                        ///< a step failed: the state is not a result, and no step follows
  std::string failure;                        ///< why
  double max_step_seconds = 0;  ///< the longest step, s (Simulation::step: the active set's selection included)
  double step_seconds = 0;      ///< wall time in steps, s, and in its stages:
  double active_set_seconds = 0, tools_seconds = 0, solve_seconds = 0;
  /// the part of solve_seconds the contacts took (every tool's, obstacle's and the bodies': ForceSet::take_seconds)
  double contact_seconds = 0;
  long long cuts = 0;                 ///< cut updates (ModelSimulation::cut: a blade step's sweeps)
  double max_cut_seconds = 0;         ///< the longest of them, the stable step and the solver's rebuild included, s
  double cut_seconds = 0;             ///< all of them, s
  long long sleeping_body_steps = 0;  ///< steps a body slept (summed over the bodies), its stencils not evaluated
  long long surface_splits =
      0;  ///< a probe's or the bodies' contact surface split along the cuts' sheets (when they stop)
  double max_split_seconds = 0;  ///< the longest split, s (off the simulation's thread in real time)
};

/// A probe's surface split along the cuts' sheets of a revision (made on a worker thread in real time).
struct SurfaceSplit {
  std::shared_ptr<const ObjectSurface> surface;  ///< over the object's points
  std::optional<SurfaceContact> contact;         ///< over the model's, made with it without levels of detail
  long long revision = 0;
  double seconds = 0;
};

/// A device-driven tool (a hand) and its settings, as a simulation holds them (carried to the next active model).
struct ProbeAttachment {
  ProbeTool tool;
  /// The probe runs in real time: levels of detail are re-selected on a worker thread, and a background
  /// refactorisation of the Cholesky preconditioner is taken up as soon as it is ready.
  bool asynchronous_lod = false;
  /// The object's surface the probe pushes on (null: the point spheres), and its contact's settings: with
  /// levels of detail every new active set gets the part of it that it carries (probe_surface_contact()).
  std::shared_ptr<const ObjectSurface> surface;
  SurfaceContactParams contact;
  long long surface_revision =
      0;  ///< of the cut sheets the contact's surface is split along (ModelSimulation::cut_sheets)
  std::shared_ptr<const ObjectSurface> split;  ///< `surface` split along them (null before any cut)
  /// With levels of detail (set by LevelsOfDetail): the object's model, which carries the surface and along
  /// whose points it is split, and the active set the simulation's model is; null without.
  const Model* object_model = nullptr;
  const ActiveSet* active_set = nullptr;
  /// The contact with the surface split along the sheets of a revision, being made on a worker thread in real
  /// time (it reads the model, or with levels of detail the object's model: a hand is dropped before either)
  std::future<SurfaceSplit> split_in_flight;
};

/// The probe's contact with `surface` (of the object) over `model`'s points: the whole surface, or with
/// levels of detail (`active`: the active set `model` is) the part of it that the active set carries.
SurfaceContact probe_surface_contact(const ObjectSurface& surface, const SurfaceContactParams& params,
                                     const ToolShape& shape, const Model& model, const ActiveSet* active);
/// The same with the part already made (restrict_surface(), on the worker that built the active set).
SurfaceContact probe_surface_contact(ActiveSurface part, const SurfaceContactParams& params, const ToolShape& shape,
                                     const Model& model, const ActiveSet& active);

/// A rigid body the scene poses: an obstacle the bodies rest on or are pressed against (a table, a bone, a
/// keyframed plate), or a tool held at a position or moved along keyframes ([[tool]]). Either is a held tool
/// that no device moves, named for its reported force.
struct PosedBody {
  enum class Role { OBSTACLE, TOOL };
  std::string name;
  Role role = Role::OBSTACLE;
  HeldTool contact;
  /// Keyframed: its translation over time from `start` (empty keyframes: static)
  Trajectory path;
  ToolPose start;
  /// A grasper's jaw: its side (-1 or +1) along the grasper's local x (0: a whole body). The two jaws share the name;
  /// `opening` gives the gap between their surfaces over time (x of its keyframes, m).
  int jaw = 0;
  Trajectory opening;
  /// A device's grasper's jaw (ProbeTool::grasper()): driven by hand `hand`, posed at its probe, turned as its tool,
  /// `jaw` side, the tool's jaw_gap() apart (ModelSimulation::place_tools); -1: posed by the scene
  int hand = -1;
  /// Where it is at time t (s): start moved along path, and a jaw half the opening and its radius to its side.
  ToolPose pose_at(double t) const;
};

/// Two jaws' loads as one tool's: forces, friction, contacts and stiffness summed, the deepest penetration, the torque
/// about `centre` (each jaw's own about its position `at`, and its force's moment).
ToolLoad grasper_load(const ToolLoad& a, const Vec3& at_a, const ToolLoad& b, const Vec3& at_b, const Vec3& centre);

class ModelSimulation {
 public:
  /// Take the model (never written again) and prepare the solver; n_threads = 0: all hardware threads.
  /// stable_dt: the model's explicit stable step if already known (0: compute it). Held points start at
  /// their prescribed displacement unless a state is given.
  ModelSimulation(Model model, const SolverSpec& solver, int n_threads, double stable_dt = 0);

  /// The pipeline's stages from the tools on: tools placed (inputs) -> solver (forces, integration, held
  /// points) -> finite check -> diagnostics. Never throws for a step that fails numerically (the report
  /// says so); throws Error for a step after a failed one.
  const StepReport& step();

  const Model& model() const { return model_; }
  /// The object's state, made whole first when the solver left it to be written (Solver::publish(): a reduced
  /// model writes u = U q when something reads it).
  const State& state() const {
    publish_state();
    return state_;
  }
  /// Between steps, cut the object where `sweep` crosses it at the current positions (mechanics/cut.hpp).
  /// When pairs were severed, the solver is rebuilt on the cut model, and the explicit stable step shortens to
  /// what cut_lanczos_steps Lanczos steps started on the cut's points find, if that is shorter (a one-sided or
  /// thin stencil can be stiffer than a whole one; tests/simulation_test.cpp checks it against 40 steps).
  /// Several sweeps (a blade's strips) cut together at the same positions, with one check of the stable step;
  /// one update in the diagnostics.
  CutReport cut(std::span<const BladeSweep> sweeps);
  /// The stable step's check after a cut: Lanczos steps, on a patch of the cut's points and this many rings
  /// (8 steps find what 12 and 40 on the whole model find at 525 and 10k points: tests/simulation_test.cpp;
  /// no ring missed a chip's mode by 10%)
  static constexpr int cut_lanczos_steps = 8;
  static constexpr int cut_patch_rings = 1;
  CutReport cut(const BladeSweep& sweep) { return cut(std::span<const BladeSweep>(&sweep, 1)); }
  /// The sheets the cuts swept, in the reference configuration: of each cut near the object, its last sweep
  /// (a blade step's new strip; the others are the trail behind it), mapped back by the displacement of the
  /// points around it. split_surface() splits the object's surface along them; a probe that
  /// pushes on the surface gets the split surface when it is not cutting (one split per stroke of the blade).
  const CutSheets& cut_sheets() const { return cut_sheets_; }
  /// Replace the state (same model). Throws Error for a state of another size.
  void set_state(const State& state);
  /// What the caller sets for a hand (0: the first, the only one without probes) before a step. Throws Error for
  /// a hand the simulation does not have.
  StepInputs& inputs(std::size_t hand = 0);
  const SolverSpec& solver() const { return solver_; }
  /// The solver that steps the model (a ReducedSolver with [reduction]).
  const Solver& solver_impl() const { return *solver_impl_; }
  Solver& solver_impl() { return *solver_impl_; }
  /// The explicit stable step (computed at construction for explicit steps, else when first asked; from the
  /// simulation's own thread).
  double stable_dt() const;
  int n_threads() const { return n_threads_; }
  Workspace& workspace() { return ws_; }

  StepDiagnostics& diagnostics() { return diagnostics_; }
  const StepDiagnostics& diagnostics() const { return diagnostics_; }
  /// The device-driven tools (hands), each placed at every step toward its device point (inputs(hand)); the
  /// first is the probe. Add one with add_hand().
  std::vector<ProbeAttachment>& hands() { return hands_; }
  const std::vector<ProbeAttachment>& hands() const { return hands_; }
  /// The first hand (nullptr without one).
  ProbeAttachment* probe() { return hands_.empty() ? nullptr : &hands_.front(); }
  const ProbeAttachment* probe() const { return hands_.empty() ? nullptr : &hands_.front(); }
  /// A hand from now on, with inputs at rest (no device point: lifted off).
  void add_hand(ProbeAttachment hand);
  /// No hand from now on.
  void remove_hands();
  /// A tool held at a pose the program sets (a static indentation); at most one of it and the hands.
  std::unique_ptr<HeldTool>& held_tool() { return held_tool_; }
  const HeldTool* held_tool() const { return held_tool_.get(); }
  /// The obstacles and posed tools, pressed on by the bodies beside the probe or held tool.
  std::vector<PosedBody>& posed_bodies() { return posed_bodies_; }
  const std::vector<PosedBody>& posed_bodies() const { return posed_bodies_; }
  /// Contact between the model's bodies (several [[object]] tables); nullptr with one body.
  BodyContact* body_contact() { return body_contact_.get(); }
  /// Each body's sleep (SolverSpec::sleep; bodies/body_sleep.hpp): whether it sleeps now, and the steps it slept.
  const std::vector<BodySleep>& body_sleep() const { return sleep_; }
  /// Contact between the model's bodies over `surface` (every body's, ObjectSurface::body_vertex_start), from now
  /// on. Once the cuts stop (a step that adds no sheet), it takes the surface split along them
  /// (refresh_body_surface()): the pieces of a cut body touch the others by their own faces.
  void set_body_contact(std::shared_ptr<const ObjectSurface> surface, const BodyContactParams& params);

  // ---- for the layer above that carries a simulation's pipeline from one model to the next (levels of
  // detail: each active set is a new ModelSimulation)
  /// Moves the model out: this simulation is then only the carrier of its pipeline's state for continue_from().
  Model take_model() { return std::move(model_); }
  /// Take over `previous`'s pipeline (a simulation of another model of the same object): its solver's warm
  /// start and factors, diagnostics, inputs, probe, cuts' sheets and a surface split in flight; from then on
  /// the pairs the cuts sever are logged (severed()) for the layer above.
  void continue_from(ModelSimulation&& previous);
  /// The neighbour pairs the cuts severed since clear_severed() (logged after continue_from()).
  const std::vector<std::array<index_t, 2>>& severed() const { return severed_log_; }
  void clear_severed() { severed_log_.clear(); }

 private:
  void place_tools();
  void solve();
  void record_cut_sheet(const BladeSweep& sweep);
  /// places the hand's probe; a blade with its button held cuts (returns true)
  bool place_hand(ProbeAttachment& hand, const StepInputs& inputs);
  void refresh_probe_surface(ProbeAttachment& hand);
  /// a device's grasper's jaws where its hand is, their gap the hand's (before the solve)
  void pose_grasper_jaws();
  /// a device's grasper's hand feels what the bodies exert on its jaws (after the solve)
  void feel_grasper_jaws();
  /// the bodies' contact over their surface split along the cuts, each vertex the split kept carrying its
  /// multiplier over
  void refresh_body_surface();
  void check_finite(StepReport& report) const;
  /// a body at rest that nothing touches falls asleep, one whose contacts' force changed or that a hand touches
  /// or a cut reaches wakes (explicit steps of several bodies)
  void update_sleep();
  void count_inverted_neighbourhoods();
  void record(const StepReport& report, double seconds);

  /// what acts on the model beside its material this step: the hands or held tool, the posed bodies and the
  /// contact between the bodies
  /// (rebuilt each step from them; no allocation once it has held them all)
  DynamicForces* forces_this_step();
  ForceSet forces_;
  std::vector<PosedBody> posed_bodies_;
  std::unique_ptr<BodyContact> body_contact_;
  std::vector<BodySleep> sleep_;  ///< per body (sized at the first step that may put one to sleep)
  long long sleep_cuts_revision_ = 0;
  bool dynamic_forces_ = false;  ///< the last step had dynamic forces (ws_.acceleration holds their last sub-step's)
  std::shared_ptr<const ObjectSurface> body_surface_;  ///< every body's surface, uncut
  BodyContactParams body_contact_params_;
  long long body_surface_revision_ = 0;  ///< the cuts' revision body_contact_'s surface is split along
  long long cuts_seen_revision_ = 0;     ///< the cuts' revision at the last step (they stopped: it did not change)
  Model model_;
  SolverSpec solver_;
  State state_;
  /// Solver::publish() into state_ and ws_ when the solver left the state unwritten: logically const (the state is
  /// the object's whatever the solver keeps), so state() can give it whole.
  void publish_state() const;
  /// Whether anything acts on the object beside its loads: hands, a held tool, posed bodies, contact between bodies.
  bool has_tools() const { return !hands_.empty() || held_tool_ || !posed_bodies_.empty() || body_contact_; }
  Workspace ws_;
  int n_threads_ = 0;
  mutable double stable_dt_ = 0;          ///< 0: not computed yet (static and implicit kinds, until stable_dt())
  Points cut_positions_;                  ///< X + u at a cut (kept: no allocation per blade step)
  std::vector<BladeSweep> blade_strips_;  ///< a blade's strips this step
  CutSheets cut_sheets_;
  std::vector<index_t> sheet_points_;  ///< the points near a sheet being recorded (kept: no allocation per step)
  /// The pairs the cuts severed, kept for the layer above when it asks (levels of detail carry them to the
  /// object), and drained by it.
  bool log_severed_ = false;
  std::vector<std::array<index_t, 2>> severed_log_;
  std::optional<std::array<Vec3, 4>> sheet_edge_;  ///< the last sheet's end edge: where it is now, and mapped back
  std::unique_ptr<Solver> solver_impl_;
  std::vector<StepInputs> inputs_ = std::vector<StepInputs>(1);  ///< per hand, at least one
  StepReport report_;
  StepDiagnostics diagnostics_;
  std::unique_ptr<HeldTool> held_tool_;
  /// (declared last: destroyed first, a hand's surface split in flight waits for its worker, which reads model_
  /// or, with levels of detail, the object's model; moved to the next active model's simulation)
  std::vector<ProbeAttachment> hands_;
};

}  // namespace pointhaptics
