#include <pointhaptics/world/model_simulation.hpp>

#include <pointhaptics/reduction/reduced_solver.hpp>

#include <pointhaptics/lod/active_surface.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/core/stage_timer.hpp>
#include <pointhaptics/mechanics/cut.hpp>
#include <pointhaptics/mechanics/inversion.hpp>
#include <pointhaptics/solvers/explicit_solver.hpp>

#include <fmt/format.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

namespace pointhaptics {

SurfaceContact probe_surface_contact(const ObjectSurface& surface, const SurfaceContactParams& params,
                                     const ToolShape& shape, const Model& model, const ActiveSet* active) {
  if (!active) return SurfaceContact(model, surface.mesh, surface.map, shape, params);
  return probe_surface_contact(restrict_surface(surface.mesh, surface.map, *active, tool_reach(shape)), params, shape,
                               model, *active);
}

SurfaceContact probe_surface_contact(ActiveSurface part, const SurfaceContactParams& params, const ToolShape& shape,
                                     const Model& model, const ActiveSet& active) {
  // with the whole surface's stiffness per point, lowered below per point rather than uniformly: a thinned
  // band's point carries the vertices of the points it absorbed, and lowering the whole part until it met the cap
  // made the contact at the probe 12x softer than the whole surface's (the probe sank in and was held)
  SurfaceContactParams own = params;
  if (params.object_point_stiffness) own.max_point_stiffness = 0;
  SurfaceContact contact(model, part.mesh, std::move(part.map), shape, own);
  contact.set_vertex_ids(std::move(part.vertex_of));
  if (params.object_point_stiffness) {
    const std::vector<double>& whole = *params.object_point_stiffness;
    std::vector<double> limit(static_cast<std::size_t>(model.n_points), params.max_point_stiffness);
    for (std::size_t j = 0; j < limit.size() && j < active.full_of.size(); ++j) {
      const auto object = static_cast<std::size_t>(active.full_of[j]);
      if (object < whole.size()) limit[j] = whole[object];
    }
    contact.limit_point_stiffness(limit, params.max_point_stiffness);
  }
  return contact;
}

ToolLoad grasper_load(const ToolLoad& a, const Vec3& at_a, const ToolLoad& b, const Vec3& at_b, const Vec3& centre) {
  ToolLoad g = a;
  g.torque = (at_a - centre).cross(a.force) + a.torque + (at_b - centre).cross(b.force) + b.torque;
  g.force += b.force;
  g.friction += b.friction;
  g.contacts += b.contacts;
  g.penetration = std::max(a.penetration, b.penetration);
  g.stiffness += b.stiffness;
  return g;
}

ToolPose PosedBody::pose_at(double t) const {
  ToolPose pose = start;
  if (!path.keyframes().empty()) pose.position += path.position(t);
  if (jaw != 0) {
    const double gap = opening.keyframes().empty() ? 0.0 : opening.position(t).x();
    pose.position += jaw * (0.5 * gap + contact.shape().radius) * (pose.orientation * Vec3::UnitX());
  }
  return pose;
}

ModelSimulation::ModelSimulation(Model model, const SolverSpec& solver, int n_threads, double stable_dt)
    : model_(std::move(model)),
      solver_(solver),
      state_(State::at_rest(model_)),
      ws_(model_, n_threads),
      n_threads_(n_threads) {
  // explicit steps below it, so they need it now; the other kinds only report it, and it is computed when
  // first asked (its 40 Lanczos steps were a tenth of a 1,500-point static solve). On the simulation's
  // threads: a third of a 10^6-point set-up on one
  stable_dt_ = stable_dt > 0                          ? stable_dt
               : solver_.kind == SolverKind::EXPLICIT ? stable_time_step(model_, 0.8, 40, n_threads)
                                                      : 0.0;
  // a reduced model's solver makes its basis here (the set-up)
  solver_impl_ = solver_.reduction.modes > 0 ? std::make_unique<ReducedSolver>(model_, solver_, ws_)
                                             : make_solver(model_, solver_, stable_dt_);
  hold_points(model_, 0.0, state_.u);  // held points start at their prescribed displacement at t = 0
}

void ModelSimulation::continue_from(ModelSimulation&& previous) {
  solver_impl_->continue_from(*previous.solver_impl_);
  diagnostics_ = std::move(previous.diagnostics_);
  inputs_ = previous.inputs_;
  // the hands, with a split of the surface along the cuts' sheets in flight (it reads the object's model)
  hands_ = std::move(previous.hands_);
  cut_sheets_ = std::move(previous.cut_sheets_);
  cuts_seen_revision_ = previous.cuts_seen_revision_;
  sheet_edge_ = previous.sheet_edge_;
  log_severed_ = true;
}

StepInputs& ModelSimulation::inputs(std::size_t hand) {
  if (hand >= inputs_.size())
    throw Error(fmt::format("simulation: no hand {} (it has {})", hand, std::max<std::size_t>(hands_.size(), 1)));
  return inputs_[hand];
}

void ModelSimulation::add_hand(ProbeAttachment hand) {
  hands_.push_back(std::move(hand));
  inputs_.resize(std::max<std::size_t>(hands_.size(), 1));
  inputs_[hands_.size() - 1] = StepInputs{};
}

void ModelSimulation::remove_hands() {
  hands_.clear();
  inputs_.assign(1, StepInputs{});
}

double ModelSimulation::stable_dt() const {
  if (!(stable_dt_ > 0)) stable_dt_ = stable_time_step(model_, 0.8, 40, n_threads_);
  return stable_dt_;
}

void ModelSimulation::publish_state() const {
  if (solver_impl_ && solver_impl_->unpublished())
    solver_impl_->publish(const_cast<State&>(state_), const_cast<Workspace&>(ws_));
}

void ModelSimulation::set_state(const State& state) {
  if (state.u.cols() != model_.n_points || state.velocity.cols() != model_.n_points)
    throw Error("simulation: the state is for another model");
  publish_state();     // (a write left for later would overwrite the one given)
  state_.u = state.u;  // copied into the state's buffers: views of them stay valid
  state_.velocity = state.velocity;
  state_.time = state.time;
  // a viscoelastic history: the state's when it has one for this model, else at rest
  if (state.viscous.rows() == state_.viscous.rows() && state.viscous.cols() == state_.viscous.cols())
    state_.viscous = state.viscous;
  else state_.viscous.setZero();
  // a reduced model steps its own coordinates: they take the given state (its projection on the basis)
  if (auto* reduced = dynamic_cast<ReducedSolver*>(solver_impl_.get())) reduced->take_state(model_, state_);
}

CutReport ModelSimulation::cut(std::span<const BladeSweep> sweeps) {
  const StageClock clock;
  cut_positions_ = model_.X + state_.u;  // allocates only the first time
  // (explicit dynamics drops the hourglass diagonal: only Newton's preconditioner reads it)
  const CutReport report = pointhaptics::cut(model_, cut_positions_, sweeps, solver_.kind != SolverKind::EXPLICIT);
  if (log_severed_) severed_log_.insert(severed_log_.end(), report.severed.begin(), report.severed.end());
  if (report.severed_pairs > 0) {
    // a one-sided or thin stencil can be stiffer than a whole one: Lanczos on a patch around the cut's points
    // (the model's tangent restricted to it) finds the modes the cut made in a few steps, at the patch's cost
    // (elsewhere the model is as it was); implicit and static steps do not depend on the stable step. On one
    // thread: the patch is small, and two threads made it slower (0.9 against 1.2 ms a cut at 10k points)
    if (solver_.kind == SolverKind::EXPLICIT)
      stable_dt_ = std::min(stable_dt_,
                            local_stable_time_step(model_, report.cut_points, cut_patch_rings, 0.8, cut_lanczos_steps));
    std::unique_ptr<Solver> next = make_solver(model_, solver_, stable_dt_);
    next->continue_from(*solver_impl_);
    solver_impl_ = std::move(next);
  }
  // (also when this sweep severed nothing: pairs cross a blade's path unevenly, and a strip left out would
  // leave the surface whole across it)
  if (!sweeps.empty()) record_cut_sheet(sweeps.back());
  ++diagnostics_.cuts;
  const double seconds = clock.seconds();
  diagnostics_.max_cut_seconds = std::max(diagnostics_.max_cut_seconds, seconds);
  diagnostics_.cut_seconds += seconds;
  return report;
}

void ModelSimulation::record_cut_sheet(const BladeSweep& sweep) {
  // the points within two supports of the sweep's box (none: it passed beside the object, nothing to record)
  const double radius = 2.0 * (model_.support.size() ? model_.support.maxCoeff() : model_.h);
  Vec3 lo = sweep.a0.cwiseMin(sweep.b0).cwiseMin(sweep.a1).cwiseMin(sweep.b1).array() - radius;
  Vec3 hi = sweep.a0.cwiseMax(sweep.b0).cwiseMax(sweep.a1).cwiseMax(sweep.b1).array() + radius;
  sheet_points_.clear();  // allocates only to grow
  for (index_t j = 0; j < model_.n_points; ++j)
    if ((cut_positions_.col(j).array() >= lo.array()).all() && (cut_positions_.col(j).array() <= hi.array()).all())
      sheet_points_.push_back(j);
  if (sheet_points_.empty()) return;
  // where the material at current position x was: x less the displacement of the points around it (weighted
  // by (1 - r / R)^2 within two supports), or of the nearest one (a corner of the sweep outside the object)
  auto reference = [&](const Vec3& x) -> Vec3 {
    Vec3 sum = Vec3::Zero(), nearest = Vec3::Zero();
    double weight = 0, closest = std::numeric_limits<double>::infinity();
    for (const index_t j : sheet_points_) {
      const double r = (cut_positions_.col(j) - x).norm();
      if (r < closest) closest = r, nearest = state_.u.col(j);
      if (r < radius) {
        const double w = (1 - r / radius) * (1 - r / radius);
        sum += w * state_.u.col(j);
        weight += w;
      }
    }
    return x - (weight > 0 ? Vec3(sum / weight) : nearest);
  };
  // a strip that starts where the last one ended starts on its mapped edge: mapped again at another time (by
  // another displacement) the two would not meet, and the gap or step between them would show
  const bool continues = sheet_edge_.has_value() && (*sheet_edge_)[0] == sweep.a0 && (*sheet_edge_)[1] == sweep.b0;
  const Vec3 a0 = continues ? (*sheet_edge_)[2] : reference(sweep.a0),
             b0 = continues ? (*sheet_edge_)[3] : reference(sweep.b0);
  const Vec3 a1 = reference(sweep.a1), b1 = reference(sweep.b1);
  if (!(a0.allFinite() && b0.allFinite() && a1.allFinite() && b1.allFinite())) return;  // a state that is not finite
  // (a straight run of strips is kept as one quad, to within a hundredth of the spacing)
  cut_sheets_.add_strip(a0, b0, a1, b1, continues, 0.01 * (model_.spacing > 0 ? model_.spacing : 0.5 * model_.h));
  sheet_edge_ = {sweep.a1, sweep.b1, a1, b1};
}

void ModelSimulation::refresh_probe_surface(ProbeAttachment& probe) {
  // the probe's contact from now on: with the split surface (with levels of detail, its part the active set
  // carries, made here: the active set may have changed since the split began)
  auto take = [&](SurfaceSplit done) {
    std::vector<index_t> same(static_cast<std::size_t>(model_.n_points));
    std::iota(same.begin(), same.end(), index_t{0});
    SurfaceContact contact =
        done.contact ? std::move(*done.contact)
                     : probe_surface_contact(*done.surface, probe.contact, probe_shape(probe.tool.contact().params()),
                                             model_, probe.active_set);
    probe.tool.remap(model_, same, std::move(contact));
    probe.split = std::move(done.surface);
    probe.surface_revision = done.revision;
    ++diagnostics_.surface_splits;
    diagnostics_.max_split_seconds = std::max(diagnostics_.max_split_seconds, done.seconds);
  };
  if (probe.split_in_flight.valid()) {
    if (probe.split_in_flight.wait_for(std::chrono::seconds(0)) != std::future_status::ready)
      return;  // the worker is at it
    take(probe.split_in_flight.get());
  }
  if (probe.surface_revision == cut_sheets_.revision) return;
  // on one thread: in real time the other core runs the haptic loop. The surface is the object's, split along
  // its points (with levels of detail the object's model, which outlives this simulation, not the active one)
  auto split = [surface = probe.surface, sheets = cut_sheets_, params = probe.contact,
                shape = probe_shape(probe.tool.contact().params()),
                &object = probe.object_model ? *probe.object_model : model_,
                whole_model = probe.active_set == nullptr]() {
    const StageClock clock;
    tbb::task_arena one_thread(1);
    SurfaceSplit made = one_thread.execute([&] {
      SurfaceSplit m{std::make_shared<const ObjectSurface>(split_surface(*surface, object, sheets.triangles)),
                     std::nullopt, sheets.revision};
      if (whole_model) m.contact.emplace(probe_surface_contact(*m.surface, params, shape, object, nullptr));
      return m;
    });
    made.seconds = clock.seconds();
    return made;
  };
  // in real time on a worker, taken over at a later step; otherwise now (reproducible runs)
  if (probe.asynchronous_lod) probe.split_in_flight = std::async(std::launch::async, std::move(split));
  else take(split());
}

// ---- the step pipeline below the active set: each stage is one function, in the order step() calls them ----

const StepReport& ModelSimulation::step() {
  if (diagnostics_.failed)
    throw Error(
        fmt::format("simulation: no step after a failed one (t = {:.6g} s: {})", state_.time, diagnostics_.failure));
  const StageClock clock;
  // tools read the displacement (attached after steps that left it unwritten: written now)
  if (has_tools() && solver_impl_ && solver_impl_->displacement_unpublished()) publish_state();
  // inputs: the tools take their place for this step
  timed_stage(diagnostics_.tools_seconds, [&] { place_tools(); });
  // the solver: internal, external, contact and tool forces, time integration or equilibrium, held points
  timed_stage(diagnostics_.solve_seconds, [&] { solve(); });
  // checks: a state that is not finite is not a result, whatever the solver said; nor is an inverted one (counted)
  check_finite(report_);
  count_inverted_neighbourhoods();
  update_sleep();
  // diagnostics
  record(report_, clock.seconds());
  return report_;
}

void ModelSimulation::solve() {
  DynamicForces* tools = forces_this_step();
  solver_impl_->set_real_time(
      std::any_of(hands_.begin(), hands_.end(), [](const ProbeAttachment& h) { return h.asynchronous_lod; }));
  report_ = solver_impl_->step(model_, state_, ws_, tools);
  dynamic_forces_ = tools != nullptr;
  if (tools && report_.status != StepStatus::FAILED) tools->after_step(model_, state_, ws_);
  feel_grasper_jaws();
  diagnostics_.contact_seconds += forces_.take_seconds();
}

void ModelSimulation::pose_grasper_jaws() {
  for (PosedBody& jaw : posed_bodies_) {
    if (jaw.hand < 0) continue;
    const ProbeTool& tool = hands_.at(static_cast<std::size_t>(jaw.hand)).tool;
    if (!tool.probe().allFinite()) continue;  // no device point yet: where they were
    const ToolPose pose{tool.probe(), tool.orientation()};
    const double side = 0.5 * tool.jaw_gap() + jaw.contact.shape().radius;
    jaw.contact.set_pose(
        ToolPose{pose.position + jaw.jaw * side * (pose.orientation * Vec3::UnitX()), pose.orientation});
  }
}

void ModelSimulation::feel_grasper_jaws() {
  for (std::size_t k = 0; k < hands_.size(); ++k) {
    ProbeTool& tool = hands_[k].tool;
    if (!tool.grasper()) continue;
    PosedBody* jaws[2] = {nullptr, nullptr};
    for (PosedBody& o : posed_bodies_)
      if (o.hand == static_cast<int>(k)) jaws[o.jaw > 0] = &o;
    if (!jaws[0] || !jaws[1]) continue;
    const ToolLoad a = jaws[0]->contact.load(model_, state_.u), b = jaws[1]->contact.load(model_, state_.u);
    tool.set_grasp_load(grasper_load(a, jaws[0]->contact.pose().position, b, jaws[1]->contact.pose().position,
                                     tool.probe().allFinite() ? tool.probe() : Vec3::Zero()),
                        state_.time);
  }
}

void ModelSimulation::update_sleep() {
  if (!solver_.sleep || solver_.kind != SolverKind::EXPLICIT || model_.n_bodies() < 2 ||
      !model_.material.prony.empty() || report_.status == StepStatus::FAILED)
    return;
  SleepInputs inputs;
  inputs.contact_forces = dynamic_forces_ ? &ws_.acceleration : nullptr;
  inputs.cut = cut_sheets_.revision != sleep_cuts_revision_;
  sleep_cuts_revision_ = cut_sheets_.revision;
  inputs.touched = [this](index_t first, index_t last) {
    return std::any_of(hands_.begin(), hands_.end(), [&](const ProbeAttachment& hand) {
      return std::any_of(hand.tool.touched().begin(), hand.tool.touched().end(),
                         [&](index_t i) { return i >= first && i < last; });
    });
  };
  inputs.dt = solver_.dt;
  update_body_sleep(model_, state_, inputs, sleep_, diagnostics_.sleeping_body_steps, ws_);
}

DynamicForces* ModelSimulation::forces_this_step() {
  // (through the set even for one member: it times the contact stage, which the solvers interleave with the rest)
  if (!has_tools()) return nullptr;
  forces_.clear();
  for (ProbeAttachment& hand : hands_) forces_.add_member(&hand.tool);
  if (held_tool_) forces_.add_member(held_tool_.get());
  for (PosedBody& o : posed_bodies_) forces_.add_member(&o.contact);
  if (body_contact_) forces_.add_member(body_contact_.get());
  return &forces_;
}

void ModelSimulation::place_tools() {
  // keyframed obstacles and tools where they are at the step's end (the time the implicit and static solves are at)
  for (PosedBody& o : posed_bodies_)
    if (!o.path.keyframes().empty() || o.jaw != 0)
      o.contact.set_pose(o.pose_at(state_.time + (solver_.kind == SolverKind::STATIC ? 0.0 : solver_.dt)));
  // the first static solve starts with what presses already stuck (SurfaceContact::begin_static_solve): a body held by
  // tools' friction alone has no equilibrium in a first minimisation without it. Only the first: in a quasi-static
  // drag (a static solve per move of the tool) the vertices that came to press at a step's start stuck there, short
  // of their cone, and the sliding friction fell to 0.2857 of the pressure for mu = 0.3 (6.5% from mu at worst,
  // against 3.7% without; experiment contact --quick); they are anchored where they are at the first update instead
  if (solver_.kind == SolverKind::STATIC && diagnostics_.steps == 0) {
    for (PosedBody& o : posed_bodies_) o.contact.contact().begin_static_solve(state_.u);
    if (held_tool_) held_tool_->contact().begin_static_solve(state_.u);
  }
  bool cutting = false;
  for (std::size_t k = 0; k < hands_.size(); ++k) cutting = place_hand(hands_[k], inputs_[k]) || cutting;
  pose_grasper_jaws();
  // once the cuts stop (no blade cuts, and a step added no sheet: a scripted cut adds a strip every step it runs),
  // the hands push on the surface split along them, and the bodies touch by it: one split per stroke or cut. (A
  // second hand re-split while the other cut took 25 ms a step on 3k points, and a hand re-split at every step of
  // a scripted cut 29 ms.)
  if (cutting) return;
  const bool cuts_stopped = cut_sheets_.revision == cuts_seen_revision_;
  cuts_seen_revision_ = cut_sheets_.revision;
  if (!cuts_stopped) return;
  for (ProbeAttachment& hand : hands_)
    if (hand.surface && (hand.split_in_flight.valid() || hand.surface_revision != cut_sheets_.revision))
      refresh_probe_surface(hand);
  if (body_surface_ && body_surface_revision_ != cut_sheets_.revision) refresh_body_surface();
}

namespace {

// a surface's vertex and face ranges per body (one range for a surface of one body, which has none)
std::vector<index_t> vertex_ranges(const ObjectSurface& s) {
  return s.body_vertex_start.empty() ? std::vector<index_t>{0, static_cast<index_t>(s.mesh.V.cols())}
                                     : s.body_vertex_start;
}
std::vector<index_t> face_ranges(const ObjectSurface& s) {
  return s.body_face_start.empty() ? std::vector<index_t>{0, static_cast<index_t>(s.mesh.F.size())} : s.body_face_start;
}

}  // namespace

void ModelSimulation::set_body_contact(std::shared_ptr<const ObjectSurface> surface, const BodyContactParams& params) {
  body_surface_ = std::move(surface);
  body_contact_params_ = params;
  body_surface_revision_ = cuts_seen_revision_ = cut_sheets_.revision;
  // one body in one piece touches nothing until a cut parts it
  std::vector<index_t> piece_of;
  body_contact_ =
      connected_pieces(model_, piece_of) > 1
          ? std::make_unique<BodyContact>(model_, body_surface_->mesh, body_surface_->map,
                                          vertex_ranges(*body_surface_), face_ranges(*body_surface_), params)
          : nullptr;
}

void ModelSimulation::refresh_body_surface() {
  const StageClock clock;
  body_surface_revision_ = cut_sheets_.revision;
  std::vector<index_t> piece_of;
  if (connected_pieces(model_, piece_of) < 2) {  // a slit: one body, still one piece, touches nothing
    body_contact_ = nullptr;
    return;
  }
  const ObjectSurface split = split_surface(*body_surface_, model_, cut_sheets_.triangles);
  const std::vector<index_t> split_start = vertex_ranges(split);
  auto next = std::make_unique<BodyContact>(model_, split.mesh, split.map, split_start, face_ranges(split),
                                            body_contact_params_);
  // each body's split surface keeps its uncut vertices first, in their order (split_surface()), as the last one did
  if (body_contact_) {
    const std::vector<index_t> whole = vertex_ranges(*body_surface_);
    const std::vector<index_t>& last = body_contact_->vertex_start();
    std::vector<index_t> last_vertex(static_cast<std::size_t>(split.mesh.V.cols()), -1);
    for (std::size_t k = 0; k + 1 < whole.size(); ++k)
      for (index_t v = 0; v < whole[k + 1] - whole[k]; ++v)
        last_vertex[static_cast<std::size_t>(split_start[k] + v)] = last[k] + v;
    next->carry_multipliers(*body_contact_, last_vertex);
  }
  body_contact_ = std::move(next);
  ++diagnostics_.surface_splits;
  diagnostics_.max_split_seconds = std::max(diagnostics_.max_split_seconds, clock.seconds());
}

bool ModelSimulation::place_hand(ProbeAttachment& hand, const StepInputs& inputs) {
  ProbeTool& tool = hand.tool;
  tool.place(model_, state_, inputs.device, inputs.button, inputs.orientation);
  // a blade with its button held cuts the strips its edge swept over its last steps (ProbeTool::blade_trail;
  // nothing on the step a cut starts)
  if (tool.cutting()) {
    tool.blade_sweeps(blade_strips_);
    tool.resist_cut(model_, blade_strips_.empty() ? CutReport{} : cut(blade_strips_), solver_.dt);
    return true;
  }
  return false;
}

void ModelSimulation::check_finite(StepReport& report) const {
  // (a solver that left the state unwritten checked its own coordinates)
  if (report.status == StepStatus::FAILED || solver_impl_->displacement_unpublished() || state_.u.allFinite()) return;
  report.status = StepStatus::FAILED;
  report.failure = fmt::format("the state is not finite at t = {:.6g} s", state_.time);
}

void ModelSimulation::count_inverted_neighbourhoods() {
  StepDiagnostics& d = diagnostics_;
  d.inverted = solver_impl_->count_inverted(model_, state_, ws_);
  d.inverted_steps += d.inverted > 0;
}

void ModelSimulation::record(const StepReport& report, double seconds) {
  StepDiagnostics& d = diagnostics_;
  ++d.steps;
  d.substeps += report.substeps;
  d.iterations += report.iterations;
  d.cg_iterations += report.cg_iterations;
  d.factorisations += report.factorisations;
  d.background_factorisations += report.background_factorisations;
  d.factor_bytes = std::max(d.factor_bytes, report.factor_bytes);
  d.coarse_points = std::max(d.coarse_points, static_cast<long long>(report.coarse_points));
  if (solver_.kind != SolverKind::EXPLICIT) d.residual = report.residual;
  if (report.status == StepStatus::AT_BUDGET) ++d.budget_steps;
  d.status = report.status;
  if (report.status == StepStatus::FAILED) {
    d.failed = true;
    d.failure = report.failure;
  }
  d.step_seconds += seconds;
}

}  // namespace pointhaptics
