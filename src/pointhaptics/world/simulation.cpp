#include <pointhaptics/world/simulation.hpp>

#include <pointhaptics/core/stage_timer.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/core/run_control.hpp>
#include <pointhaptics/mechanics/energy.hpp>
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/mechanics/inversion.hpp>
#include <pointhaptics/mechanics/viscoelasticity.hpp>
#include <pointhaptics/reduction/reduced_solver.hpp>
#include <pointhaptics/solvers/reactions.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>

namespace pointhaptics {

Simulation::Simulation(Model model, const SolverSpec& solver, int n_threads)
    : object_(std::make_unique<ModelSimulation>(std::move(model), solver, n_threads)) {}

Simulation::~Simulation() = default;
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;

// ---- the step pipeline: the active set here, the rest in ModelSimulation::step() -----------------------

const StepReport& Simulation::step() {
  const StepReport& report = step_unwritten();
  core().state();  // written whole (a reduced model's): the caller may hold it (Python's arrays are views of it)
  return report;
}

const StepReport& Simulation::step_unwritten() {
  interrupted_step_.clear();
  try {
    return run_step_stages();
  } catch (const Interrupted& e) {
    interrupted_step_ = e.what();
    throw;
  }
}

const StepReport& Simulation::run_step_stages() {
  const StageClock clock;
  // the inputs were filled by the caller (inputs()); the active set follows the last step's contact
  double selecting = 0;
  timed_stage(selecting, [&] {
    if (lod_) lod_->follow_probe();
  });
  ModelSimulation& sim = core();  // (the new active set's, when it changed)
  sim.diagnostics().active_set_seconds += selecting;
  sim.diagnostics().step_seconds += selecting;
  // the scripted blades cut what they sweep during this step
  if (!scripted_cuts_.empty()) apply_scripted_cuts();
  // the tools, the solver, the finite check and the diagnostics
  const StepReport& report = sim.step();
  if (lod_) {
    lod_->carry_cuts();  // a blade's cut in the active set reaches the object
    lod_->mark_stale();
  }
  StepDiagnostics& d = core().diagnostics();  // (the active set's simulation: it may have changed above)
  d.max_step_seconds = std::max(d.max_step_seconds, clock.seconds());
  return report;
}

void Simulation::add_scripted_cut(const CutSpec& cut) {
  const Model& model = this->model();
  index_t body = -1;
  if (model.n_bodies() > 1) {
    const auto named = std::find(model.body_names.begin(), model.body_names.end(), cut.object);
    if (named == model.body_names.end())
      throw Error(fmt::format(
          "cut: {} (with several bodies a cut names the one it cuts)",
          cut.object.empty() ? std::string("no object named") : fmt::format("no body is named \"{}\"", cut.object)));
    body = static_cast<index_t>(named - model.body_names.begin());
  }
  scripted_cuts_.push_back({cut, 0.0, body});
}

CutReport Simulation::cut(std::span<const BladeSweep> sweeps) {
  CutReport report = core().cut(sweeps);
  if (lod_) lod_->carry_cuts();
  return report;
}

void Simulation::apply_scripted_cuts() {
  const SolverSpec& spec = solver();
  // the blade reaches, by the end of this step, the share of its sweep its script gives at that time
  const double t_end = time() + (spec.kind == SolverKind::STATIC ? 0.0 : spec.dt);
  for (ScriptedCut& c : scripted_cuts_) {
    const CutSpec& s = c.spec;
    double share = 1.0;
    if (spec.kind != SolverKind::STATIC) {
      if (t_end < s.start) continue;
      share = s.duration > 0 ? std::min(1.0, (t_end - s.start) / s.duration) : 1.0;
    }
    if (share <= c.done) continue;
    // this step's strip, and the trail before it near the edge: the material moves between steps, and a pair
    // that crossed back over a strip already passed would escape the blade; far behind the edge the blade's
    // body would keep the material from crossing, so nothing there is cut (a linear script's trail is one quad)
    auto at = [&](int end, double u) -> Vec3 { return s.edge[end] + u * (s.to[end] - s.edge[end]); };
    const Model& model = this->model();
    const double reach = model.support.size() ? model.support.maxCoeff() : model.h;
    const BladeSweep trail{at(0, 0.0), at(1, 0.0), at(0, c.done), at(1, c.done), reach, c.body};
    const BladeSweep strip{
        at(0, c.done), at(1, c.done), at(0, share), at(1, share), std::numeric_limits<double>::infinity(), c.body};
    if (c.done > 0) {
      const std::array<BladeSweep, 2> both{trail, strip};
      cut(both);
    } else {
      cut(strip);
    }
    c.done = share;
  }
  // a piece the cuts set free has no equilibrium: say so before the static solve fails on it (with several
  // bodies it may rest on another by contact)
  if (spec.kind == SolverKind::STATIC && this->model().n_bodies() == 1) {
    const Model& model = lod_ ? lod_->settled_object_model() : object_->model();
    std::vector<index_t> piece_of;
    const std::vector<index_t> size = piece_sizes(model, piece_of);
    std::vector<char> held(size.size(), 0);
    for (index_t i = 0; i < model.n_points; ++i) held[piece_of[i]] |= model.fixed[i];
    for (std::size_t p = 0; p < size.size(); ++p)
      if (!held[p])
        throw Error(fmt::format(
            "cut: the cuts leave piece {} of {} ({} points) held nowhere: a static solve has no equilibrium "
            "for it (use solver.kind = \"explicit\" or \"implicit\", or hold it)",
            p + 1, size.size(), size[p]));
  }
}

long long Simulation::steps_in(double duration) const {
  const SolverSpec& spec = solver();
  if (spec.kind == SolverKind::STATIC) return 1;
  const double steps = std::ceil(duration / spec.dt - 1e-9);
  if (!(duration >= 0) || !(steps <= max_run_steps))
    throw Error(fmt::format("run: a duration of {:.6g} s is {} (at most {:.0e} steps of dt = {:.3g} s, {:.3g} s)",
                            duration, duration >= 0 ? "too long" : "not a duration", max_run_steps, spec.dt,
                            max_run_steps * spec.dt));
  return std::max<long long>(0, std::llround(steps));
}

void Simulation::run(double duration, const std::function<bool(long long, long long)>& after_step) {
  const long long n_steps = steps_in(duration);
  // the state written whole at the end (a reduced model writes it only when read: after_step reads it through
  // state(), which writes it then), however the run ends
  struct WrittenAtTheEnd {
    Simulation& sim;
    ~WrittenAtTheEnd() { sim.core().state(); }
  } written{*this};
  for (long long k = 1; k <= n_steps; ++k) {
    if (step_unwritten().status == StepStatus::FAILED) return;
    if (after_step && !after_step(k, n_steps)) return;
  }
}

const Model& Simulation::model() const { return lod_ ? lod_->object_model() : object_->model(); }
const State& Simulation::state() const { return lod_ ? lod_->object_state() : object_->state(); }

void Simulation::set_state(const State& state) {
  if (lod_) lod_->set_object_state(state);
  else object_->set_state(state);
}

void Simulation::attach_probe(const ProbeParams& params, double coupling_stiffness, double max_force,
                              bool asynchronous_lod, std::shared_ptr<const ObjectSurface> surface, std::string name) {
  ModelSimulation& sim = core();
  if (!sim.hands().empty()) {
    if (lod_)
      throw Error(
          "probe: a second hand with levels of detail is not supported yet (the active set follows one "
          "contact)");
    if (name.empty()) name = fmt::format("hand{}", sim.hands().size() + 1);
    for (std::size_t k = 0; k < sim.hands().size(); ++k)
      if (hand_name(k) == name) throw Error(fmt::format("probe: \"{}\" is already the name of a hand", name));
  }
  if (sim.solver().kind == SolverKind::STATIC) throw Error("probe: needs a dynamic solver (explicit or implicit)");
  if (params.mode == ProbeMode::CUT && !(params.length > 0))
    throw Error("probe: a blade is a capsule whose axis is its edge: give it a length");
  if (sim.held_tool()) throw Error("probe: the simulation already holds a tool (one tool at a time)");
  const bool grasper = params.mode == ProbeMode::GRASP;
  if (grasper && (!(params.length > 0) || !surface || lod_ || !(params.grip < params.opening)))
    throw Error(
        "probe: a grasper's jaws are capsules (give a length) that press on the bodies' surface (not with levels of "
        "detail), and its grip is narrower than its opening");
  SurfaceContactParams contact;
  // the contact no stiffer on a point than the point spheres' springs were (E x spacing): explicit steps keep
  // their stable sub-step, implicit ones their linearly implicit springs. The probe's multipliers, advanced
  // once a step (ProbeTool::after_step), keep it on the surface
  contact.max_point_stiffness = sim.model().material.young * sim.model().spacing;
  contact.friction = params.friction;
  contact.non_negative_weights = params.non_negative_surface_map;
  contact.sample_spacing = params.sample_spacing;
  // friction's penalty a tenth of the normal one (SurfaceContactParams::tangential_share): sliding, the
  // friction then measured 0.288 of the pressure for mu = 0.3 (0.286 with a hundredth, where new contacts
  // stuck for tens of steps; the full penalty made explicit steps chatter: 0.217)
  contact.tangential_share = 0.1;
  // the probe carries only the vertices it can reach within a step: its placement tries positions up to two radii
  // from where the step found it (ProbeTool::place), and reads the triangles there (carrying every vertex of
  // three 10k-point bodies for two hands at every sub-step was a fifth of the step)
  contact.cull_far_vertices = true;
  contact.cull_margin = 2.5 * params.radius + params.length;
  if (surface && lod_) {
    // every active set's part of the surface presses as the whole surface does on the object's points (after a
    // cut, as the unsplit one did: the split adds vertices only along the cut, the one place this is approximate)
    // (without samples: only its penalty and its points' stiffness are wanted, and a thin tool would sample the
    // whole object's surface; the parts' samples press no stiffer on a point than their vertices would)
    SurfaceContactParams whole_params = contact;
    whole_params.sample_spacing = -1;
    const SurfaceContact whole(lod_->object_model(), surface->mesh, surface->map, probe_shape(params), whole_params);
    contact.penalty = whole.per_area_penalty();
    contact.object_point_stiffness =
        std::make_shared<const std::vector<double>>(whole.point_stiffness(lod_->object_model().n_points));
  }
  std::optional<SurfaceContact> on_surface;
  if (surface && grasper) {
    // its jaws: posed tools the simulation moves with the hand (ModelSimulation::pose_grasper_jaws), far away until
    // the device's first point; their contact a posed tool's (friction with its multipliers in implicit steps)
    SurfaceContactParams jaw_contact;
    jaw_contact.friction = params.friction;
    jaw_contact.non_negative_weights = params.non_negative_surface_map;
    jaw_contact.sample_spacing = params.sample_spacing;
    const ToolPose away{Vec3::Constant(1e3), params.orientation};
    const int hand = static_cast<int>(sim.hands().size());
    for (const int side : {-1, +1})
      add_posed_body(PosedBody::Role::TOOL, name.empty() ? tool_name_ : name, probe_shape(params), away, surface->mesh,
                     surface->map, jaw_contact, {}, side, {}, hand);
    surface = nullptr;  // the tool itself touches nothing
  } else if (surface) {
    on_surface.emplace(probe_surface_contact(*surface, contact, probe_shape(params), sim.model(),
                                             lod_ ? &lod_->active_set() : nullptr));
  }
  sim.add_hand(ProbeAttachment{ProbeTool(sim.model(), params, coupling_stiffness, max_force, std::move(on_surface)),
                               asynchronous_lod,
                               std::move(surface),
                               contact,
                               0,
                               nullptr,
                               nullptr,
                               nullptr,
                               {}});
  hand_names_.resize(sim.hands().size());
  hand_names_.back() = std::move(name);
}

const std::string& Simulation::hand_name(std::size_t hand) const {
  if (hand >= hands()) throw Error(fmt::format("probe: no hand {} (the simulation has {})", hand, hands()));
  return hand == 0 ? tool_name_ : hand_names_[hand];
}

void Simulation::hold_tool(const ToolShape& shape, const ToolPose& pose, const TriangleMesh& mesh, SurfaceMap map,
                           const SurfaceContactParams& params) {
  if (lod_)
    throw Error("tool: a held tool with levels of detail is not available yet (its surface map is the object's)");
  ModelSimulation& sim = core();
  if (sim.probe()) throw Error("tool: the simulation already has a probe (one tool at a time)");
  SurfaceContactParams contact = params;
  // explicit steps: no stiffer on a point than E x spacing, or the stable sub-step would shrink with it
  if (sim.solver().kind == SolverKind::EXPLICIT && contact.max_point_stiffness <= 0)
    contact.max_point_stiffness = sim.model().material.young * sim.model().spacing;
  sim.held_tool() = std::make_unique<HeldTool>(SurfaceContact(sim.model(), mesh, std::move(map), shape, contact));
  sim.held_tool()->set_pose(pose);
  // (in dynamics a penalty, its multipliers never updated, as before [[tool]]: a [probe] held 0.5 mm deep on a
  // block on a table with friction took 60 Newton iterations in one implicit step with the updates, above the
  // default limit; the posed tools of [[tool]] tables have them)
}

void Simulation::add_obstacle(std::string name, const ToolShape& shape, const ToolPose& pose, const TriangleMesh& mesh,
                              SurfaceMap map, const SurfaceContactParams& params, const Trajectory& path) {
  add_posed_body(PosedBody::Role::OBSTACLE, std::move(name), shape, pose, mesh, std::move(map), params, path);
}

void Simulation::add_posed_tool(std::string name, const ToolShape& shape, const ToolPose& pose,
                                const TriangleMesh& mesh, SurfaceMap map, const SurfaceContactParams& params,
                                const Trajectory& path) {
  add_posed_body(PosedBody::Role::TOOL, std::move(name), shape, pose, mesh, std::move(map), params, path);
}

void Simulation::add_grasper(std::string name, const ToolShape& jaw, const ToolPose& pose, const Trajectory& opening,
                             const TriangleMesh& mesh, SurfaceMap map, const SurfaceContactParams& params,
                             const Trajectory& path) {
  if (jaw.kind != ToolKind::CAPSULE || !(jaw.length > 0)) throw Error("grasper: its jaws are capsules (give a length)");
  if (opening.keyframes().empty()) throw Error("grasper: give its opening");
  add_posed_body(PosedBody::Role::TOOL, name, jaw, pose, mesh, map, params, path, -1, opening);
  add_posed_body(PosedBody::Role::TOOL, std::move(name), jaw, pose, mesh, std::move(map), params, path, +1, opening);
}

void Simulation::add_posed_body(PosedBody::Role role, std::string name, const ToolShape& shape, const ToolPose& pose,
                                const TriangleMesh& mesh, SurfaceMap map, const SurfaceContactParams& params,
                                const Trajectory& path, int jaw, const Trajectory& opening, int hand) {
  const bool obstacle = role == PosedBody::Role::OBSTACLE;
  const char* what = obstacle ? "obstacle" : "tool";
  if (lod_)
    throw Error(
        fmt::format("{}: not yet with levels of detail (an active set carries only part of the surface)", what));
  ModelSimulation& sim = core();
  if (jaw <= 0 && hand < 0)  // (a grasper's second jaw shares its first's name; a hand's jaws are named as the hand)
    for (const PosedBody& o : sim.posed_bodies())
      if (o.role == role && o.name == name) throw Error(fmt::format("\"{}\" is already the name of a {}", name, what));
  SurfaceContactParams contact = params;
  contact.cull_far_vertices = true;  // (an obstacle or a posed tool reads only the vertices that can touch it)
  // explicit steps: as a held tool's (hold_tool())
  if (sim.solver().kind == SolverKind::EXPLICIT && contact.max_point_stiffness <= 0)
    contact.max_point_stiffness = sim.model().material.young * sim.model().spacing;
  HeldTool held(SurfaceContact(sim.model(), mesh, std::move(map), shape, contact));
  // a tool in implicit dynamics: its multipliers and friction's anchors follow over the steps
  // (HeldTool::after_step), so that jaws can lift a body. Explicit steps keep the penalty alone (a multiplier
  // raised once a step over many sub-steps set a dropped block bouncing on a table: 0.13 m/s after 0.4 s against
  // under 0.01), and so do obstacles: a table's friction in implicit dynamics, under a block squeezed by jaws
  // sliding up its sides, stalled an implicit step's Newton (its residual at 3e-3 after 300 iterations; the
  // same with the table frictionless converged), not yet understood
  held.update_after_step(!obstacle && sim.solver().kind == SolverKind::IMPLICIT);
  PosedBody body{std::move(name), role, std::move(held), path, pose, jaw, opening, hand};
  body.contact.set_pose(body.pose_at(sim.state().time));
  // an obstacle may not start inside the object: its surface's vertices (the reference ones) stay out of it (a
  // tool may: an indentation)
  const ToolLoad at_rest = body.contact.load(sim.model(), Points::Zero(3, sim.model().n_points));
  if (obstacle && at_rest.penetration > body.contact.contact().tolerance())
    throw Error(
        fmt::format("\"{}\" starts inside the object: its surface lies up to {:.3g} m inside it "
                    "(move it out, or the object)",
                    body.name, at_rest.penetration));
  sim.posed_bodies().push_back(std::move(body));
}

namespace {

// a posed tool's load, a grasper's two jaws summed into one (its torque about the midpoint of the jaws, its position)
struct PosedToolLoad {
  std::string name;
  ToolLoad load;
  Vec3 position = Vec3::Zero();
  const PosedBody* body = nullptr;  ///< the first of its bodies
};
std::vector<PosedToolLoad> posed_tool_loads_of(ModelSimulation& sim, PosedBody::Role role) {
  std::vector<PosedToolLoad> loads;
  for (PosedBody& o : sim.posed_bodies()) {
    if (o.role != role || o.hand >= 0) continue;  // (a device's grasper is reported as its hand)
    const ToolLoad load = o.contact.load(sim.model(), sim.state().u);
    const Vec3 at = o.contact.pose().position;
    if (o.jaw > 0 && !loads.empty() && loads.back().name == o.name) {  // the grasper's second jaw
      PosedToolLoad& g = loads.back();
      const Vec3 first = g.position, centre = 0.5 * (first + at);
      g.load = grasper_load(g.load, first, load, at, centre);
      g.position = centre;
      continue;
    }
    loads.push_back({o.name, load, at, &o});
  }
  return loads;
}

}  // namespace

std::vector<std::pair<std::string, ToolLoad>> Simulation::posed_tool_loads() {
  ModelSimulation& sim = core();
  std::vector<std::pair<std::string, ToolLoad>> loads;
  for (PosedToolLoad& t : posed_tool_loads_of(sim, PosedBody::Role::TOOL)) loads.emplace_back(t.name, t.load);
  return loads;
}

void Simulation::add_body_contact(const ObjectSurface& surface, const BodyContactParams& params) {
  ModelSimulation& sim = core();
  if (lod_) throw Error("body contact: not yet with levels of detail (an active set is one body's)");
  if (sim.body_contact()) throw Error("body contact: already on");
  BodyContactParams contact = params;
  if (sim.solver().kind == SolverKind::EXPLICIT && contact.max_point_stiffness <= 0)
    contact.max_point_stiffness = sim.model().material.young * sim.model().spacing;
  // explicit steps: multipliers that move slowly, or they pump the contact's ringing (BodyContactParams::friction_rate)
  if (sim.solver().kind == SolverKind::EXPLICIT) {
    const BodyContactParams defaults;
    if (contact.multiplier_rate == defaults.multiplier_rate) contact.multiplier_rate = explicit_contact_rate;
    if (contact.friction_rate == defaults.friction_rate) contact.friction_rate = explicit_contact_rate;
  }
  contact.update_after_step = sim.solver().kind != SolverKind::STATIC;
  sim.set_body_contact(std::make_shared<const ObjectSurface>(surface), contact);
}

BodyContact* Simulation::body_contact() { return core().body_contact(); }

void Simulation::set_tool_pose(const ToolPose& pose) {
  if (!core().held_tool()) throw Error("tool: no held tool to move");
  core().held_tool()->set_pose(pose);
}

HeldTool* Simulation::held_tool() { return core().held_tool().get(); }

void Simulation::detach_probe() {
  core().remove_hands();
  hand_names_.clear();
}

const ProbeTool* Simulation::probe(std::size_t hand) const {
  const std::vector<ProbeAttachment>& hands = core().hands();
  return hand < hands.size() ? &hands[hand].tool : nullptr;
}

void Simulation::grabbed_points(std::vector<index_t>& out, std::size_t hand) const {
  out.clear();
  const ProbeTool* p = probe(hand);
  if (!p) return;
  const ActiveSet* active = active_set();
  for (const index_t i : p->contact().grabbed()) out.push_back(active ? active->full_of[i] : i);
}

void Simulation::enable_lod(const LodParams& params, const Vec3& contact) {
  if (lod_) throw Error("lod: levels of detail are already on");
  lod_ = std::make_unique<LevelsOfDetail>(std::move(*object_), params, contact);
  object_.reset();
}

std::vector<index_t> Simulation::update_lod(const Vec3& contact, bool onset, bool asynchronous) {
  if (!lod_) throw Error("lod: levels of detail are off");
  return lod_->update(contact, onset, asynchronous);
}

Vec3 Simulation::lod_contact_of_probe(const Vec3& probe, const std::vector<index_t>& grabbed,
                                      const std::vector<index_t>& touched) const {
  if (!lod_) return probe;
  return lod_->contact_of_probe(probe, grabbed, touched);
}

const ActiveSet* Simulation::active_set() const { return lod_ ? &lod_->active_set() : nullptr; }
const Selection* Simulation::lod_selection() const { return lod_ ? &lod_->selection() : nullptr; }
long long Simulation::lod_selections() const { return lod_ ? lod_->selections() : 0; }

namespace {

// The end state is no result when neighbourhoods are inverted, or when a held group with a prescribed
// displacement is pulled along by the body instead of pushing it (its support force against its motion: the
// body gives work back, as a collapsed block does). ws holds the end state's gradients and s its reactions.
void check_physical(const Model& model, Workspace& ws, const StepDiagnostics& d, RunSummary& s) {
  s.inverted = count_inverted(model, ws);
  s.inverted_steps = d.inverted_steps;
  for (std::size_t g = 0; g < model.fixed_groups.size() && g < s.reactions.size(); ++g) {
    const Vec3 motion = model.fixed_groups[g].displacement;
    const Vec3& reaction = s.reactions[g];
    if (motion.norm() > 0 && reaction.dot(motion) < -1e-6 * reaction.norm() * motion.norm())
      s.collapsed.push_back(model.fixed_groups[g].name);
  }
  if (s.inverted == 0 && s.collapsed.empty()) return;
  s.converged = false;
  if (!s.failure.empty()) return;
  if (s.inverted > 0)
    s.failure = fmt::format(
        "{} of {} neighbourhoods are inverted (det F <= 0): the state is not physical (try "
        "model = \"neo_hookean\", a finer load ramp or a finer spacing)",
        s.inverted, model.stencil_end());
  else
    s.failure = fmt::format(
        "{}: the support force opposes the prescribed motion (the body collapsed: its stress fell "
        "instead of rising; try model = \"neo_hookean\")",
        s.collapsed.front());
}

}  // namespace

namespace {

const char* tool_kind_name(const ToolShape& shape) {
  switch (shape.kind) {
    case ToolKind::CAPSULE: return "capsule";
    case ToolKind::BOX: return "box";
    case ToolKind::PLANE: return "plane";
    case ToolKind::SPHERE: break;
  }
  return "sphere";
}

}  // namespace

ToolSummary Simulation::tool_summary(std::size_t hand) {
  ModelSimulation& sim = core();
  if (HeldTool* tool = sim.held_tool().get(); tool && hand == 0) {
    const ToolLoad load = tool->load(sim.model(), sim.state().u);
    return {true,
            tool_kind_name(tool->shape()),
            tool->pose().position,
            load.force,
            load.torque,
            load.contacts,
            load.penetration,
            load.friction};
  }
  if (const ProbeTool* probe = this->probe(hand)) {
    // the probe's local model at the last step's end: the force the object exerts on it there; on the surface
    // its load there, with the torque, the friction and the deepest vertex
    const ContactModel& c = probe->contact_model();
    if (probe->grasper()) {  // its jaws' load, summed
      const ToolLoad& load = probe->grasp_load();
      return {true, "grasper", probe->probe(), load.force, load.torque, load.contacts, load.penetration, load.friction};
    }
    if (const SurfaceContact* surface = probe->surface_contact()) {
      const ToolLoad& load = surface->last_load();
      return {true,
              tool_kind_name(surface->shape()),
              probe->probe(),
              c.f0,
              load.torque,
              c.contacts,
              load.penetration,
              load.friction};
    }
    return {true, "sphere", probe->probe(), c.f0, Vec3::Zero(), c.contacts, 0.0, Vec3::Zero()};
  }
  return {};
}

namespace {

// each body's block: its points, mass, motion, held groups and what the others do to it
// each body's block (with several) and the contact between them and between the pieces of a cut one
void body_summaries(const Model& model, const State& state, const BodyContact* contact,
                    const std::vector<BodySleep>& sleep, RunSummary& s) {
  const BodyLoads loads = contact ? contact->loads(model, state.u) : BodyLoads{};
  if (contact) {
    s.body_contact.present = true;
    s.body_contact.pairs = contact->pairs();
    s.body_contact.contacts = loads.contacts;
    s.body_contact.penetration = loads.penetration;
  }
  if (model.n_bodies() < 2) return;
  for (index_t k = 0; k < model.n_bodies(); ++k) {
    BodySummary b;
    b.name = model.body_names[static_cast<std::size_t>(k)];
    const index_t first = model.body_start[static_cast<std::size_t>(k)],
                  end = model.body_start[static_cast<std::size_t>(k) + 1];
    b.points = end - first;
    b.mass = model.mass.segment(first, end - first).sum();
    Vec3 moment = Vec3::Zero();
    for (index_t i = first; i < end; ++i) {
      moment += model.mass[i] * state.u.col(i);
      b.max_displacement = std::max(b.max_displacement, state.u.col(i).norm());
    }
    b.mean_displacement = b.mass > 0 ? Vec3(moment / b.mass) : Vec3::Zero();
    if (contact) b.contact_force = loads.force[static_cast<std::size_t>(k)];
    for (std::size_t g = 0; g < model.fixed_groups.size(); ++g)
      if (!model.fixed_groups[g].points.empty() && model.body_of(model.fixed_groups[g].points.front()) == k)
        b.constraints.push_back(static_cast<int>(g));
    if (static_cast<std::size_t>(k) < sleep.size()) {
      b.asleep = sleep[static_cast<std::size_t>(k)].asleep;
      b.slept_steps = sleep[static_cast<std::size_t>(k)].slept_steps;
    }
    s.bodies.push_back(std::move(b));
  }
}

}  // namespace

RunSummary Simulation::summary() {
  ModelSimulation& sim = core();
  const Model& model = sim.model();
  const State& state = sim.state();
  Workspace& ws = sim.workspace();
  const StepDiagnostics& d = sim.diagnostics();
  RunSummary s;
  s.solver_kind = std::string(to_string(sim.solver().kind));
  if (const auto* reduced = dynamic_cast<const ReducedSolver*>(&sim.solver_impl())) {
    const ModalBasis& b = reduced->basis();
    ReductionSummary& r = s.reduction;
    r.modes = static_cast<int>(b.U.cols());
    r.linear_modes = b.linear_modes;
    r.derivatives = b.derivatives;
    r.load_vectors = b.load_vectors;
    r.basis_spacing = sim.solver().reduction.basis_spacing;
    r.setup_s = reduced->setup_s();
    r.factorise_s = b.factorise_s;
    r.modes_s = b.modes_s;
    r.derivatives_s = b.derivatives_s;
    r.polynomial_s = reduced->polynomial().build_s();
    r.factor_bytes = b.factor_bytes;
    r.tables_bytes = reduced->polynomial().bytes();
    r.first_frequency_hz = reduced->first_frequency_hz();
    r.cache_file = reduced->cache_file();
    r.from_cache = reduced->from_cache();
    r.cache_note = reduced->cache_note();
    if (const ContactPatch* patch = reduced->contact_patch()) {
      r.contact_points = patch->largest_free_points();
      r.contact_patches = patch->rebuilds();
      r.contact_hessians = patch->hessians();
    }
  }
  s.converged = state.u.allFinite() && !d.failed && interrupted_step_.empty();
  s.failure = interrupted_step_.empty() ? d.failure : interrupted_step_;
  s.interrupted = !interrupted_step_.empty();
  s.steps = d.steps;
  s.substeps = d.substeps;
  s.iterations = d.iterations;
  s.cg_iterations = d.cg_iterations;
  if (sim.solver().kind != SolverKind::EXPLICIT) s.preconditioner = std::string(enum_name(sim.solver().preconditioner));
  s.factorisations = d.factorisations;
  s.background_factorisations = d.background_factorisations;
  s.factor_bytes = d.factor_bytes;
  s.coarse_points = d.coarse_points;
  s.budget_steps = d.budget_steps;
  s.stable_dt = sim.stable_dt();
  // a viscoelastic material's stress at the state: its history's, not the last step's in ws
  viscous_stress_at_state(model, state, ws, sim.solver().kind == SolverKind::STATIC);
  compute_internal_forces(model, state.u, ws);
  // a held tool's contact is one of the forces in balance (the probe's, in dynamics, is reported below)
  HeldTool* tool = sim.held_tool().get();
  if (tool) tool->add(model, state, ws.f_int);
  for (PosedBody& o : sim.posed_bodies()) o.contact.add(model, state, ws.f_int);
  if (sim.body_contact()) sim.body_contact()->add(model, state, ws.f_int);
  s.reactions = support_reactions(model, ws.f_int);
  check_physical(model, ws, d, s);
  // dynamics is out of balance by the inertia; its Newton residual includes it
  s.residual = sim.solver().kind == SolverKind::IMPLICIT ? d.residual : relative_residual(model, ws.f_int);
  s.strain_energy = strain_energy(model, state.u).total();
  s.kinetic_energy = kinetic_energy(model, state.velocity);
  s.wall_s = d.step_seconds;
  s.step_ms_mean = d.steps > 0 ? 1e3 * d.step_seconds / static_cast<double>(d.steps) : 0;
  s.step_ms_max = 1e3 * d.max_step_seconds;
  s.steps_per_s = d.step_seconds > 0 ? static_cast<double>(d.steps) / d.step_seconds : 0;
  s.active_set_s = d.active_set_seconds;
  s.tools_s = d.tools_seconds;
  s.solve_s = d.solve_seconds;
  s.contact_s = d.contact_seconds;
  if (lod_) lod_->fill(s.lod);
  s.tool = tool_summary();
  s.tool_name = tool_name_;
  for (std::size_t k = 1; k < hands(); ++k) s.tools.emplace_back(hand_names_[k], tool_summary(k));
  for (const PosedBody::Role role : {PosedBody::Role::OBSTACLE, PosedBody::Role::TOOL})
    for (const PosedToolLoad& t : posed_tool_loads_of(sim, role)) {
      const ToolLoad& load = t.load;
      const std::string kind = t.body->jaw != 0 ? "grasper" : tool_kind_name(t.body->contact.shape());
      (role == PosedBody::Role::OBSTACLE ? s.obstacles : s.tools)
          .emplace_back(t.name, ToolSummary{true, kind, t.position, load.force, load.torque, load.contacts,
                                            load.penetration, load.friction});
    }
  body_summaries(model, state, sim.body_contact(), sim.body_sleep(), s);
  if (d.cuts > 0 || !scripted_cuts_.empty()) {
    // the object's cut (with levels of detail every cut of an active set reaches it)
    const Model& object = lod_ ? lod_->settled_object_model() : model;
    s.cut.present = true;
    s.cut.sweeps = d.cuts;
    s.cut.cut_pairs = object.diagnostics.severed_pairs;
    s.cut.max_update_ms = 1e3 * d.max_cut_seconds;
    s.cut.mean_update_ms = d.cuts > 0 ? 1e3 * d.cut_seconds / static_cast<double>(d.cuts) : 0.0;
    s.cut.sheet_triangles = static_cast<long long>(cut_sheets().triangles.size());
    s.cut.surface_splits = d.surface_splits;
    s.cut.max_split_ms = 1e3 * d.max_split_seconds;
    std::vector<index_t> piece_of;
    s.cut.piece_points = piece_sizes(object, piece_of);
  }
  return s;
}

}  // namespace pointhaptics
