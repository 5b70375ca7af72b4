#pragma once
/// @file The simulation of an object, as its users see it: the step pipeline of a ModelSimulation, with levels
/// of detail as an optional layer in between (LevelsOfDetail). Everything it shows speaks the object's point
/// indices: model() and state() are the whole object's, whatever is simulated.
#include <pointhaptics/io/result_json.hpp>
#include <pointhaptics/io/scene.hpp>
#include <pointhaptics/world/levels_of_detail.hpp>
#include <pointhaptics/world/model_simulation.hpp>
#include <pointhaptics/surface/object_surface.hpp>

#include <functional>
#include <memory>
#include <vector>

namespace pointhaptics {

class Simulation {
 public:
  /// Take the model (never written again) and prepare the solver; n_threads = 0: all hardware threads.
  Simulation(Model model, const SolverSpec& solver, int n_threads = 0);
  ~Simulation();
  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) noexcept;

  /// One step, as a table of contents: the inputs (filled by the caller) -> the active set (levels of
  /// detail follow the probe) -> the tools placed -> the solver (forces and time integration, held
  /// points) -> the finite check -> the diagnostics; model_simulation.cpp has the stages after the active
  /// set. Dynamics: dt (explicit: sub-stepped below the stable step); static: the equilibrium under the full
  /// load (later calls start from the last solution). Never throws for a step that fails numerically: the
  /// report says FAILED and why, diagnostics() keeps it, and the state is not a result. Throws Error for a
  /// step after a failed one. Throws Interrupted for a stop requested inside it (run_control.hpp): until the next
  /// step completes, summary() says interrupted and not converged, with the loop it stopped in.
  const StepReport& step();
  /// Dynamics: step until time() reaches `duration` (ceil(duration / dt) steps); static: one solve.
  /// Stops at a failed step (diagnostics().failed says so). after_step(step, n_steps), if given, is called
  /// after each step; returning false stops the run there (an interrupted run keeps the state reached).
  /// A stop requested inside a step (run_control.hpp) throws Interrupted out of it, the state left where the
  /// step's solver stopped: its start (implicit), its last sub-step (explicit, the time advanced to it) or the
  /// last converged load increment (static). Throws Error for a duration that is negative, not finite or more
  /// than max_run_steps steps.
  void run(double duration, const std::function<bool(long long step, long long n_steps)>& after_step = {});
  /// The steps run(duration) takes (1 for a static solve); throws Error as run() does.
  long long steps_in(double duration) const;
  static constexpr double max_run_steps = 1e12;
  /// Filled by the caller before a step (MuJoCo's step1/step2), per hand (0: the first probe). Throws Error for a
  /// hand the simulation does not have.
  StepInputs& inputs(std::size_t hand = 0) { return core().inputs(hand); }
  const StepDiagnostics& diagnostics() const { return core().diagnostics(); }

  /// The object and its state (with levels of detail: the active state carried back to the object, absorbed
  /// points following their selected point by first-order MLS, the rest at their last displacement).
  const Model& model() const;
  const State& state() const;
  double time() const { return core().state().time; }
  /// Replace the object's state (with levels of detail the active set takes its points' values).
  void set_state(const State& state);
  const SolverSpec& solver() const { return core().solver(); }
  /// The explicit stable step of the simulated model at rest, s.
  double stable_dt() const { return core().stable_dt(); }
  /// What is simulated: the object, or with levels of detail the active set (its own indices; map them with
  /// active_set()->full_of). For experiments that measure the simulated set itself.
  const Model& simulated_model() const { return core().model(); }
  const State& simulated_state() const { return core().state(); }

  /// A probe from now on (dynamics only): placed at every step on a coupling spring of `coupling_stiffness`
  /// (N/m) toward inputs().device, its force capped at `max_force` (N), pushing or grabbing the points.
  /// With levels of detail the active set follows its contact point, re-selected on a worker thread when
  /// `asynchronous_lod` (real time) and in place otherwise (reproducible runs). Throws Error for a static solver.
  /// `surface`: the object's surface, which the probe then pushes on (issue 16) instead of the point
  /// spheres; with levels of detail the part of it that the active set carries (scenes do not ask for it:
  /// a slow real-time run diverged with it, tests/integration/realtime_lod_soak.py).
  /// A second call adds a second hand (issue 47: two devices, each its own probe, placed toward inputs(1)), and so
  /// on; each touches every body. `name`: what summary() reports a second or later hand under (empty: "hand2",
  /// ...; the first is reported under set_tool_name()'s). Throws Error for a second hand with levels of detail
  /// (the active set follows one contact) or a name already taken.
  void attach_probe(const ProbeParams& params, double coupling_stiffness, double max_force, bool asynchronous_lod,
                    std::shared_ptr<const ObjectSurface> surface = nullptr, std::string name = {});
  /// Every hand detached.
  void detach_probe();
  /// The hand's probe (nullptr without it; 0: the first): its position and last local contact model. Its
  /// contact's point indices are the simulated model's; grabbed_points() gives the object's.
  const ProbeTool* probe(std::size_t hand = 0) const;
  /// Hands attached (attach_probe()).
  std::size_t hands() const { return core().hands().size(); }
  /// The name a hand is reported under.
  const std::string& hand_name(std::size_t hand) const;
  /// A tool held at `pose` against the object's surface (`mesh`, carried by `map` over the object's points),
  /// for any solver: the static solver finds the equilibrium with it there; set_tool_pose() moves it between
  /// steps. Throws Error with levels of detail or a probe (one tool at a time).
  void hold_tool(const ToolShape& shape, const ToolPose& pose, const TriangleMesh& mesh, SurfaceMap map,
                 const SurfaceContactParams& params = {});
  /// A static rigid obstacle touching the object's surface (`mesh`, carried by `map`), by name: a plane, box,
  /// sphere or capsule (ToolShape) at `pose`. Its contact is a held tool's (hold_tool()); its force is in
  /// summary().obstacles. Throws Error for a name already taken, with levels of detail, or when it starts inside
  /// the object (its surface deeper in it than the contact's tolerance). `path`: its translation from `pose`
  /// over time, applied at each step's end (empty: static).
  void add_obstacle(std::string name, const ToolShape& shape, const ToolPose& pose, const TriangleMesh& mesh,
                    SurfaceMap map, const SurfaceContactParams& params = {}, const Trajectory& path = {});
  /// A tool the scene poses ([[tool]] with a position or keyframes), by name: as an obstacle, except that it may
  /// start pressed into the object (an indentation) and its force is in summary().tools. `path`: where it is
  /// over time, added to `pose` (empty: held at `pose`). Any number of them, beside a probe or held tool.
  void add_posed_tool(std::string name, const ToolShape& shape, const ToolPose& pose, const TriangleMesh& mesh,
                      SurfaceMap map, const SurfaceContactParams& params = {}, const Trajectory& path = {});
  /// The obstacles and posed tools, in the order they were added.
  const std::vector<PosedBody>& posed_bodies() const { return core().posed_bodies(); }
  /// A grasper the scene poses ([[tool]] shape = "grasper"), by name: two capsule jaws of `jaw` (a capsule) either
  /// side of `pose` along its local x, their axes along its local z, `opening` apart (the gap between their surfaces
  /// over time: x of its keyframes, m), moved along `path` as a posed tool. Each jaw is a posed tool's contact,
  /// friction included; the grasper is reported as one tool (their forces summed, about its centre).
  void add_grasper(std::string name, const ToolShape& jaw, const ToolPose& pose, const Trajectory& opening,
                   const TriangleMesh& mesh, SurfaceMap map, const SurfaceContactParams& params = {},
                   const Trajectory& path = {});
  /// What the bodies exert on each posed tool ([[tool]] with a position or keyframes) now, by name, in the order
  /// they were added: the rows of `run --tool-log`.
  std::vector<std::pair<std::string, ToolLoad>> posed_tool_loads();
  /// The name the probe or held tool is reported under (summary().tool_name): its [[tool]]'s; "probe" by default.
  void set_tool_name(std::string name) { tool_name_ = std::move(name); }
  /// Contact between the model's bodies (Model::body_start) on their surfaces (`surface`, with its bodies'
  /// vertices and triangles), and between the pieces cuts make of one, on the surface split along the cuts once
  /// they stop: contact/body_contact.hpp. One body touches nothing until a cut parts it. Explicit steps lower its
  /// penalty to E x spacing per point, as a held tool's. Throws Error with levels of detail, or when it is already on.
  void add_body_contact(const ObjectSurface& surface, const BodyContactParams& params = {});
  /// The contact between the bodies (nullptr without one).
  BodyContact* body_contact();
  void set_tool_pose(const ToolPose& pose);
  /// The held tool (nullptr without one).
  HeldTool* held_tool();
  /// The object's points the hand's probe holds (cleared first; allocates only to grow).
  void grabbed_points(std::vector<index_t>& out, std::size_t hand = 0) const;

  /// A scripted blade from now on (a scene's [[cut]]): every dynamic step first cuts where the trail its edge has
  /// swept by the end of the step crosses the object (so material that moved back over the trail is cut too);
  /// a static solve first cuts its whole sweep. With several bodies it cuts only cut.object's (an Error names an
  /// unknown one, or a missing one).
  void add_scripted_cut(const CutSpec& cut);
  /// Cut now, between steps, where the sweeps cross the object at its current positions (ModelSimulation::cut).
  /// With levels of detail the active model is cut, and the cut reaches the object
  /// (LevelsOfDetail::carry_cuts()); the report is the active model's.
  CutReport cut(std::span<const BladeSweep> sweeps);
  CutReport cut(const BladeSweep& sweep) { return cut(std::span<const BladeSweep>(&sweep, 1)); }
  /// The sheets the cuts swept so far, in the reference configuration (ModelSimulation::cut_sheets): the
  /// object's surface split along them (split_surface()) is the cut object's.
  const CutSheets& cut_sheets() const { return core().cut_sheets(); }

  /// Levels of detail (seed §3): from now on simulate only the points selected around `contact` (the
  /// reference configuration, m; snapped to the nearest point of the object). Throws Error on bad
  /// parameters, or if they are on already.
  void enable_lod(const LodParams& params, const Vec3& contact);
  bool lod_enabled() const { return lod_ != nullptr; }
  /// LevelsOfDetail::update(): re-select around `contact` if it moved far enough; the renumbering of the
  /// simulated points when a new active set took over (see there). Throws Error without levels of detail.
  std::vector<index_t> update_lod(const Vec3& contact, bool onset = false, bool asynchronous = false);
  /// LevelsOfDetail::contact_of_probe() (`grabbed`, `touched`: simulated indices).
  Vec3 lod_contact_of_probe(const Vec3& probe, const std::vector<index_t>& grabbed = {},
                            const std::vector<index_t>& touched = {}) const;
  /// The index map of the active set (nullptr without levels of detail).
  const ActiveSet* active_set() const;
  /// The selection the active set was built from (nullptr without levels of detail).
  const Selection* lod_selection() const;
  /// Selections made so far (0 without levels of detail): a new one means a new active set.
  long long lod_selections() const;

  /// The tool (held, or the hand's probe) at the current state: what the object does to it. Not present without
  /// one.
  ToolSummary tool_summary(std::size_t hand = 0);
  /// Results at the current state: energies (of what is simulated), reactions, residual, timing, and the
  /// levels of detail.
  RunSummary summary();

 private:
  void add_posed_body(PosedBody::Role role, std::string name, const ToolShape& shape, const ToolPose& pose,
                      const TriangleMesh& mesh, SurfaceMap map, const SurfaceContactParams& params,
                      const Trajectory& path, int jaw = 0, const Trajectory& opening = {}, int hand = -1);
  ModelSimulation& core() { return lod_ ? lod_->active() : *object_; }
  const ModelSimulation& core() const { return lod_ ? lod_->active() : *object_; }

  std::unique_ptr<ModelSimulation> object_;  ///< without levels of detail
  std::unique_ptr<LevelsOfDetail> lod_;      ///< with them (then object_ is empty)
  std::string tool_name_ = "probe";
  std::vector<std::string> hand_names_;  ///< per hand (the first's unused: it is tool_name_)
  struct ScriptedCut {
    CutSpec spec;
    double done = 0;    ///< the share of its sweep already cut
    index_t body = -1;  ///< the body it cuts (spec.object's; -1: the one object)
  };
  std::vector<ScriptedCut> scripted_cuts_;
  void apply_scripted_cuts();
  /// step()'s stages; step() notes a stop inside them
  const StepReport& run_step_stages();
  /// step() without writing a reduced model's state whole at its end (run() writes it when read, and at its end)
  const StepReport& step_unwritten();
  /// What the last step was stopped in (a stop request inside it), else empty: the state is then not a step's
  /// result, and summary() never reports it as converged
  std::string interrupted_step_;
};

}  // namespace pointhaptics
